#include "validation/compare.hpp"

#include <algorithm>
#include <cmath>

#include <gsl/gsl_statistics_double.h>

#include "common/errors.hpp"

namespace swim::validation {

double interpolate_linear(const std::vector<double>& t, const std::vector<double>& u, double x) {
  if (x <= t.front()) return u.front();
  if (x >= t.back()) return u.back();
  const auto it = std::upper_bound(t.begin(), t.end(), x);
  const std::size_t i = std::size_t(it - t.begin());
  const double w = (x - t[i - 1]) / (t[i] - t[i - 1]);
  return (1 - w) * u[i - 1] + w * u[i];
}

namespace {
void check(const std::vector<double>& t, const std::vector<double>& u, const char* what) {
  if (t.size() < 2 || t.size() != u.size())
    throw InputError(what, std::to_string(t.size()) + " samples", "two or more (t, U) samples");
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(t[i] > t[i - 1])) throw InputError(what, "time " + std::to_string(t[i]), "increasing sample times");
}
}  // namespace

SeriesComparison compare_series(const std::vector<double>& t_a, const std::vector<double>& u_a, double T_a,
                                const std::vector<double>& t_b, const std::vector<double>& u_b, double T_b,
                                bool phase, int n) {
  check(t_a, u_a, "series to compare");
  check(t_b, u_b, "reference series");
  if (!(T_a > 0 && T_b > 0)) throw InputError("cycle time", std::to_string(std::min(T_a, T_b)), "positive");
  std::vector<double> a(static_cast<std::size_t>(n)), b(static_cast<std::size_t>(n));
  const double T = std::min(T_a, T_b);
  for (int k = 0; k < n; ++k) {
    const double s = (k + 0.5) / n;
    a[std::size_t(k)] = interpolate_linear(t_a, u_a, phase ? s * T_a : s * T);
    b[std::size_t(k)] = interpolate_linear(t_b, u_b, phase ? s * T_b : s * T);
  }
  double num = 0, den = 0;
  for (int k = 0; k < n; ++k) {
    const double x = a[std::size_t(k)], y = b[std::size_t(k)];
    num += (x - y) * (x - y);
    den += y * y;
  }
  const bool flat = gsl_stats_sd(a.data(), 1, a.size()) == 0.0 || gsl_stats_sd(b.data(), 1, b.size()) == 0.0;
  SeriesComparison c;
  c.points = n;
  c.l2_relative = den > 0 ? std::sqrt(num / den) : 0.0;
  c.correlation = flat ? 0.0 : gsl_stats_correlation(a.data(), 1, b.data(), 1, a.size());
  return c;
}

}  // namespace swim::validation
