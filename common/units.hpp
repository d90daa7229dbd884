// Unit strings at the edge of the product: "0.125 um", "1.2e-3 Pa*s", "5.5e-8 N/m".
//
// Parsing and conversion use UDUNITS-2 (Debian libudunits2), so every SI prefix and
// compound unit it knows is accepted. Inside the program every value is SI.
#pragma once

#include <string>
#include <utility>

namespace swim::units {

/// A parsed quantity: its value in the SI unit `si_unit` and the text it came from.
struct Quantity {
  double si = 0.0;
  std::string text;
};

/// Parse "<number> <unit>" and convert it to `si_unit` (for example "m", "Pa*s", "Pa/m").
/// Throws swim::InputError naming `key` when the number or the unit is missing, the unit
/// is unknown, or it is not convertible to `si_unit`.
Quantity parse(const std::string& key, const std::string& text, const std::string& si_unit);

/// True when `unit` is a unit string UDUNITS-2 understands.
bool known_unit(const std::string& unit);

/// Format an SI value with its unit, e.g. format(1.25e-7, "m") -> "1.25e-07 m".
std::string format(double value_si, const std::string& si_unit);

}  // namespace swim::units

namespace swim::units {

/// Split "<number> <unit>" (key for messages). Throws InputError when either part is missing
/// or the unit is unknown.
std::pair<double, std::string> split(const std::string& key, const std::string& text);

/// Value of "<number> <unit>" in SI base units, with the base unit written by UDUNITS-2
/// (e.g. "0.2 um" -> {2e-7, "m"}).
std::pair<double, std::string> to_base(const std::string& key, const std::string& text);

}  // namespace swim::units
