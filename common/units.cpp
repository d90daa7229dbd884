#include "common/units.hpp"

#include <udunits2.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>

#include "common/errors.hpp"

namespace swim::units {
namespace {

struct UnitFree {
  void operator()(ut_unit* u) const { ut_free(u); }
};
struct ConverterFree {
  void operator()(cv_converter* c) const { cv_free(c); }
};
using UnitPtr = std::unique_ptr<ut_unit, UnitFree>;
using ConverterPtr = std::unique_ptr<cv_converter, ConverterFree>;

// The unit database is read once and never modified afterwards; UDUNITS-2 parsing is not
// documented as thread safe, so every use goes through one mutex.
struct System {
  ut_system* sys = nullptr;
  std::mutex mutex;
  System() {
    ut_set_error_message_handler(ut_ignore);
    sys = ut_read_xml(nullptr);
    if (!sys) throw std::runtime_error("cannot read the UDUNITS-2 unit database");
  }
  ~System() { ut_free_system(sys); }
};

System& system() {
  static System s;
  return s;
}

UnitPtr parse_unit(const std::string& u) {
  return UnitPtr(ut_parse(system().sys, u.c_str(), UT_ASCII));
}

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

}  // namespace

Quantity parse(const std::string& key, const std::string& text, const std::string& si_unit) {
  const std::string quoted = "\"" + text + "\"";
  const std::string allowed = "a number followed by a unit convertible to " + si_unit + " (e.g. \"1 " +
                              si_unit + "\")";
  const std::string t = trim(text);
  char* end = nullptr;
  const double number = std::strtod(t.c_str(), &end);
  if (end == t.c_str()) throw InputError(key, quoted, "no number; expected " + allowed);
  if (!std::isfinite(number)) throw InputError(key, quoted, "number is not finite; expected " + allowed);
  const std::string unit = trim(std::string(end));
  if (unit.empty()) throw InputError(key, quoted, "missing unit; expected " + allowed);

  std::lock_guard lock(system().mutex);
  UnitPtr from = parse_unit(unit);
  if (!from) throw InputError(key, quoted, "unknown unit '" + unit + "'; expected " + allowed);
  UnitPtr to = parse_unit(si_unit);
  if (!to) throw std::logic_error("internal: bad SI unit string " + si_unit);
  if (!ut_are_convertible(from.get(), to.get()))
    throw InputError(key, quoted, "unit '" + unit + "' is not convertible to " + si_unit);
  ConverterPtr conv(ut_get_converter(from.get(), to.get()));
  if (!conv) throw InputError(key, quoted, "unit '" + unit + "' cannot be converted to " + si_unit);
  // Offset units (degC) are meaningless for the quantities of this product: reject them.
  if (cv_convert_double(conv.get(), 0.0) != 0.0)
    throw InputError(key, quoted, "unit '" + unit + "' has an offset; expected " + allowed);
  return Quantity{cv_convert_double(conv.get(), number), t};
}

bool known_unit(const std::string& unit) {
  std::lock_guard lock(system().mutex);
  return static_cast<bool>(parse_unit(unit));
}

std::string format(double value_si, const std::string& si_unit) {
  char b[64];
  std::snprintf(b, sizeof b, "%.10g %s", value_si, si_unit.c_str());
  return b;
}

}  // namespace swim::units

namespace swim::units {

std::pair<double, std::string> split(const std::string& key, const std::string& text) {
  const std::string t = trim(text);
  char* end = nullptr;
  const double number = std::strtod(t.c_str(), &end);
  if (end == t.c_str() || !std::isfinite(number))
    throw InputError(key, "\"" + text + "\"", "expected \"<number> <unit>\"");
  const std::string unit = trim(std::string(end));
  if (unit.empty()) throw InputError(key, "\"" + text + "\"", "missing unit; expected \"<number> <unit>\"");
  if (!known_unit(unit)) throw InputError(key, "\"" + text + "\"", "unknown unit '" + unit + "'");
  return {number, unit};
}

std::pair<double, std::string> to_base(const std::string& key, const std::string& text) {
  const auto [number, unit] = split(key, text);
  std::lock_guard lock(system().mutex);
  UnitPtr u = parse_unit(unit);
  char buf[256];
  const int n = ut_format(u.get(), buf, sizeof buf, UT_ASCII | UT_DEFINITION);
  if (n < 0 || n >= static_cast<int>(sizeof buf)) throw InputError(key, "\"" + text + "\"", "unit cannot be expressed in SI");
  // UT_DEFINITION writes "<factor> <base units>" or just "<base units>"
  std::string def(buf);
  char* end = nullptr;
  double factor = std::strtod(def.c_str(), &end);
  std::string base = trim(std::string(end));
  if (end == def.c_str()) {
    factor = 1.0;
    base = trim(def);
  }
  return {number * factor, base};
}

}  // namespace swim::units
