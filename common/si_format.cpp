#include "common/si_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace swim {

std::string si(double value, const std::string& unit, int digits) {
  if (!std::isfinite(value)) return "n/a";
  char buf[64];
  if (value == 0.0) {
    const std::string u = unit.rfind("m^3", 0) == 0 ? "m\u00b3" + unit.substr(3) : unit;
    std::snprintf(buf, sizeof buf, "0 %s", u.c_str());
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
    u += "m\u00b3" + unit.substr(3);
  else
    u += unit;
  if (cubic && std::abs(scaled) >= 1000.0) {
    // a volume's mantissa reaches 999 999: written out, rounded to `digits` significant
    // digits and grouped in thousands ("718 000 nm³"), never in e-notation
    const double step = std::pow(10.0, std::floor(std::log10(std::abs(scaled))) + 1 - digits);
    const long long n = std::llround(std::abs(scaled) / std::max(step, 1.0)) * static_cast<long long>(std::max(step, 1.0));
    const std::string digits_of_n = std::to_string(n);
    std::string d;
    for (std::size_t k = 0; k < digits_of_n.size(); ++k) {
      if (k > 0 && (digits_of_n.size() - k) % 3 == 0) d += ' ';
      d += digits_of_n[k];
    }
    std::snprintf(buf, sizeof buf, "%s%s %s", scaled < 0 ? "-" : "", d.c_str(), u.c_str());
    return buf;
  }
  std::snprintf(buf, sizeof buf, "%.*g %s", digits, scaled, u.c_str());
  return buf;
}

}  // namespace swim
