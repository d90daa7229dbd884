#include "common/si_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace swim {

std::string si(double value, const std::string& unit, int digits) {
  if (!std::isfinite(value)) return "n/a";
  char buf[64];
  if (value == 0.0) {
    std::snprintf(buf, sizeof buf, "0 %s", unit.c_str());
    return buf;
  }
  static const char* names[] = {"f", "p", "n", "\u00b5", "m", "", "k", "M", "G"};
  const bool cubic = unit.rfind("m^3", 0) == 0;
  const int power = cubic ? 3 : 1;  // a prefix on m^3 scales by 1000^3
  // mantissa in [1, 1000) for a plain unit; for volumes in [1e-3, 1e6) (prefix steps of 1e9)
  int e3 = cubic ? int(std::floor((std::log10(std::abs(value)) + 3.0) / 9.0))
                 : int(std::floor(std::log10(std::abs(value)) / 3.0));
  e3 = std::max(-5, std::min(3, e3));
  const double scaled = value / std::pow(10.0, 3.0 * power * e3);
  std::string u = names[e3 + 5];
  if (cubic)
    u += "m^3" + unit.substr(3);
  else
    u += unit;
  std::snprintf(buf, sizeof buf, "%.*g %s", digits, scaled, u.c_str());
  return buf;
}

}  // namespace swim
