#include "common/si_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace swim {

std::string significant(double value, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, value);
  return buf;
}

std::string si(double value, const std::string& unit, int digits) {
  if (!std::isfinite(value)) return "n/a";
  char buf[64];
  if (unit.rfind("m^3", 0) == 0) {
    // volumes: always µm³, the scale of the swimmers, so that two runs print comparable
    // figures ("0.00382 µm³", "0.000962 µm³"); plain decimals down to 10⁻⁶ µm³
    const std::string u = "\u00b5m\u00b3" + unit.substr(3);
    const double x = value == 0.0 ? 0.0 : value * 1e18;  // (no "-0" for a negative zero)
    const double a = std::abs(x);
    if (a == 0.0 || a < 1e-6 || a >= 1e15) {
      std::snprintf(buf, sizeof buf, "%.*g %s", digits, x, u.c_str());
      return buf;
    }
    const int decimals = std::max(0, digits - 1 - int(std::floor(std::log10(a))));
    std::snprintf(buf, sizeof buf, "%.*f", decimals, x);
    std::string t = buf;
    if (t.find('.') != std::string::npos) {
      while (t.back() == '0') t.pop_back();
      if (t.back() == '.') t.pop_back();
    }
    return t + " " + u;
  }
  if (value == 0.0) {
    std::snprintf(buf, sizeof buf, "0 %s", unit.c_str());
    return buf;
  }
  static const char* names[] = {"f", "p", "n", "\u00b5", "m", "", "k", "M", "G"};
  int e3 = int(std::floor(std::log10(std::abs(value)) / 3.0));
  e3 = std::max(-5, std::min(3, e3));
  const double scaled = value / std::pow(10.0, 3.0 * e3);
  const std::string u = names[e3 + 5] + unit;
  std::snprintf(buf, sizeof buf, "%.*g %s", digits, scaled, u.c_str());
  return buf;
}

}  // namespace swim
