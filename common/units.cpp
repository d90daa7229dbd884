#include "common/units.hpp"

#include <udunits2.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cerrno>
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

// Strict "<number> <unit>": a decimal number ([sign] digits [. digits] [e [sign] digits];
// no hex, inf, nan), then one unit expression. Returns the number and the unit text, or
// throws InputError naming `key`. The unit must not carry a numeric factor of its own
// ("0.1 0.2 um", "um*1000", "um/2"): UDUNITS-2 would multiply it in silently.
std::pair<double, std::string> split_strict(const std::string& key, const std::string& text, const std::string& allowed) {
  const std::string quoted = "\"" + text + "\"";
  const std::string t = trim(text);
  size_t i = 0;
  const auto digits = [&] {
    const size_t a = i;
    while (i < t.size() && std::isdigit(static_cast<unsigned char>(t[i]))) ++i;
    return i - a;
  };
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  size_t mantissa = digits();
  if (i < t.size() && t[i] == '.') {
    ++i;
    mantissa += digits();
  }
  if (mantissa == 0) throw InputError(key, quoted, "no number; expected " + allowed);
  if (i < t.size() && (t[i] == 'x' || t[i] == 'X') && i == std::size_t(1 + (t[0] == '+' || t[0] == '-')))
    throw InputError(key, quoted, "hexadecimal numbers are not accepted; expected " + allowed);
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    size_t j = i + 1;
    if (j < t.size() && (t[j] == '+' || t[j] == '-')) ++j;
    size_t k = j;
    while (k < t.size() && std::isdigit(static_cast<unsigned char>(t[k]))) ++k;
    if (k > j) i = k;  // else the 'e' starts the unit? No unit starts with a bare e: rejected below
  }
  const std::string number_text = t.substr(0, i);
  errno = 0;
  const double number = std::strtod(number_text.c_str(), nullptr);
  if (!std::isfinite(number)) throw InputError(key, quoted, "number does not fit a double; expected " + allowed);
  if (number == 0.0 && number_text.find_first_of("123456789") < number_text.find_first_of("eE"))
    throw InputError(key, quoted, "number underflows to zero in a double; expected " + allowed);
  const std::string unit = trim(t.substr(i));
  if (unit.empty()) throw InputError(key, quoted, "missing unit; expected " + allowed);
  // The unit starts with a letter or "(" and no factor in it is a bare number: split at
  // the operators of a unit expression and look at each factor's first character.
  if (!(std::isalpha(static_cast<unsigned char>(unit[0])) || unit[0] == '(' ||
        static_cast<unsigned char>(unit[0]) >= 0x80))
    throw InputError(key, quoted, "expected exactly one number followed by one unit (got '" + unit +
                                      "' after the number); expected " + allowed);
  size_t a = 0;
  while (a < unit.size()) {
    size_t b = unit.find_first_of(" \t*/().@", a);
    if (b == std::string::npos) b = unit.size();
    if (unit[b < unit.size() ? b : 0] == '@' && b < unit.size())
      throw InputError(key, quoted, "unit '" + unit + "' has an origin shift; expected " + allowed);
    if (b > a) {
      const char c = unit[a];
      if (std::isdigit(static_cast<unsigned char>(c)) || c == '+' || c == '-')
        throw InputError(key, quoted, "expected exactly one number followed by one unit; the unit '" + unit +
                                          "' holds a numeric factor '" + unit.substr(a, b - a) + "'");
      if (unit.compare(a, b - a, "since") == 0 || unit.compare(a, b - a, "from") == 0 ||
          unit.compare(a, b - a, "after") == 0 || unit.compare(a, b - a, "ref") == 0)
        throw InputError(key, quoted, "unit '" + unit + "' is a time-stamp or offset unit; expected " + allowed);
    }
    // "." between two numbers would be a decimal point; between factors UDUNITS reads it as *
    a = b + 1;
  }
  return {number, unit};
}

}  // namespace

Quantity parse(const std::string& key, const std::string& text, const std::string& si_unit) {
  const std::string quoted = "\"" + text + "\"";
  const std::string allowed = "a number followed by a unit convertible to " + si_unit + " (e.g. \"1 " +
                              si_unit + "\")";
  const auto [number, unit] = split_strict(key, text, allowed);

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
  return Quantity{cv_convert_double(conv.get(), number), trim(text)};
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
  const auto [number, unit] = split_strict(key, text, "\"<number> <unit>\"");
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
