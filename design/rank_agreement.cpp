#include "design/rank_agreement.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace swim::design {

std::vector<double> mid_ranks(const std::vector<double>& v) {
  std::vector<std::size_t> order(v.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  std::vector<double> r(v.size());
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j + 1 < order.size() && v[order[j + 1]] == v[order[i]]) ++j;
    const double mean = 0.5 * double(i + j) + 1.0;  // ranks i+1 .. j+1
    for (std::size_t k = i; k <= j; ++k) r[order[k]] = mean;
    i = j + 1;
  }
  return r;
}

Interval fisher_interval(double r, std::size_t n, double c, std::size_t m) {
  if (n <= m) return {-1, 1};
  const double z = std::atanh(std::clamp(r, -0.999999, 0.999999));
  const double se = std::sqrt(c / double(n - m));
  return {std::tanh(z - 1.959964 * se), std::tanh(z + 1.959964 * se)};
}

namespace {
double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = double(a.size());
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / n, mb = std::accumulate(b.begin(), b.end(), 0.0) / n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}
int sign(double v) { return (v > 0) - (v < 0); }

// The Fisher interval; at |r| = 1 (where z is infinite) the far end is that of the nearest
// value n designs can give below it (one adjacent pair swapped: |r| = 1 - step), the near end 1.
Interval interval_of(double r, std::size_t n, double c, std::size_t m, double step) {
  if (std::abs(r) < 1.0 - 1e-12) return fisher_interval(r, n, c, m);
  Interval i = fisher_interval(sign(r) * (1.0 - step), n, c, m);
  (r > 0 ? i.hi : i.lo) = sign(r);
  return i;
}
}  // namespace

RankAgreement rank_agreement(const std::vector<double>& x, const std::vector<double>& y,
                             const std::vector<double>& y_err) {
  if (x.size() != y.size() || x.size() < 2 || (!y_err.empty() && y_err.size() != y.size()))
    throw std::invalid_argument("rank_agreement: x, y (and y_err) need the same length, at least 2");
  RankAgreement a;
  a.n = x.size();
  for (std::size_t i = 0; i < a.n; ++i)
    for (std::size_t j = i + 1; j < a.n; ++j) {
      const int sx = sign(x[j] - x[i]);
      int sy = sign(y[j] - y[i]);
      if (sy != 0 && !y_err.empty() && std::abs(y[j] - y[i]) <= y_err[i] + y_err[j]) {
        sy = 0;
        ++a.tied_by_error_bars;
      }
      if (sx == 0) ++a.tied_x;
      if (sy == 0) ++a.tied_y;
      if (sx == 0 || sy == 0) continue;
      if (sx == sy) {
        ++a.concordant;
      } else {
        ++a.discordant;
        a.misranked.emplace_back(i, j);
      }
    }
  const double n0 = 0.5 * double(a.n) * double(a.n - 1);
  const double den = std::sqrt((n0 - double(a.tied_x)) * (n0 - double(a.tied_y)));
  a.kendall_tau = den > 0 ? (double(a.concordant) - double(a.discordant)) / den : 0.0;
  a.spearman_rho = pearson(mid_ranks(x), mid_ranks(y));
  a.kendall_defined = den > 0;
  a.kendall_ci = a.kendall_defined ? interval_of(a.kendall_tau, a.n, 0.437, 4, 2.0 / n0) : Interval{-1, 1};
  a.spearman_ci = interval_of(a.spearman_rho, a.n, 1.06, 3, 12.0 / (double(a.n) * (double(a.n) * double(a.n) - 1.0)));
  return a;
}

std::vector<std::size_t> select_for_confirmation(const std::vector<std::size_t>& ranked, std::size_t k) {
  k = std::min(k, ranked.size());
  const std::size_t top = k - k / 2, spread = k / 2, rest = ranked.size() - top;
  std::vector<std::size_t> out(ranked.begin(), ranked.begin() + long(top));
  // positions floor((i + 1) rest / spread) - 1 in the rest: evenly spaced, ending at the worst
  for (std::size_t i = 0; i < spread; ++i) out.push_back(ranked[top + (i + 1) * rest / spread - 1]);
  return out;
}

}  // namespace swim::design
