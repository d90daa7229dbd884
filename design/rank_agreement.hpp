// Rank agreement between a screening tier (1D) and a confirming tier (3D) over n designs.
//
//   Kendall tau-b = (C - D) / sqrt((n0 - t_x)(n0 - t_y)),  n0 = n(n-1)/2,
//     C, D: concordant and discordant pairs; t_x, t_y: pairs tied in x, in y.
//   Spearman rho = Pearson correlation of the mid-ranks (equal values share their mean rank).
//   Confidence intervals: Fisher z = atanh(r) with the standard errors of Fieller, Hartley &
//     Pearson (1957, Biometrika 44:470): sqrt(0.437/(n-4)) for tau, sqrt(1.06/(n-3)) for rho;
//     the interval tanh(z -+ 1.96 se) at 95 %. Fewer designs than that (n <= 4 for tau, n <= 3
//     for rho) give the whole range [-1, 1]. At |r| = 1, where z is infinite, the interval runs
//     from the far end of the interval of the nearest value below it that n designs can give
//     (one adjacent pair swapped: tau = 1 - 2/n0, rho = 1 - 12/(n(n^2-1))) to 1.
//   Ties from error bars: a pair whose y values differ by no more than the sum of their error
//     bars (y_err, when given) counts as tied in y, for tau-b and for the misranked pairs.
//   Misranked pair: x orders it one way, y (beyond the error bars) strictly the other way.
//   With every pair tied in x or in y (for instance every 3D difference within its error bars)
//   tau-b is 0/0: undefined (kendall_defined false), not 0.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace swim::design {

struct Interval {
  double lo = -1, hi = 1;
};

struct RankAgreement {
  std::size_t n = 0;
  double kendall_tau = 0;
  Interval kendall_ci;
  /// false when every pair is tied in x or in y (tau-b's 0/0): kendall_tau is then 0 and
  /// kendall_ci the whole [-1, 1], and neither says anything
  bool kendall_defined = true;
  double spearman_rho = 0;
  Interval spearman_ci;
  std::size_t concordant = 0, discordant = 0, tied_x = 0, tied_y = 0;
  std::size_t tied_by_error_bars = 0;  ///< pairs tied in y only because of their error bars
  std::vector<std::pair<std::size_t, std::size_t>> misranked;  ///< index pairs (i < j)
};

/// Mid-ranks of v, 1 = smallest (equal values share the mean of their ranks).
std::vector<double> mid_ranks(const std::vector<double>& v);

/// Agreement of y with x (same length, at least 2). y_err: empty, or one error bar >= 0 per y.
RankAgreement rank_agreement(const std::vector<double>& x, const std::vector<double>& y,
                             const std::vector<double>& y_err = {});

/// The 95 % Fisher-z interval of a correlation r from n pairs with z's variance c/(n - m)
/// (tau: c = 0.437, m = 4; rho: c = 1.06, m = 3).
Interval fisher_interval(double r, std::size_t n, double c, std::size_t m);

/// The designs to confirm among `ranked` (design indices, best first): the ceil(K/2) best, then
/// floor(K/2) spread evenly over the rest of the ranking, its last (the worst) included. K is
/// clamped to ranked.size(). Returned in ranking order.
std::vector<std::size_t> select_for_confirmation(const std::vector<std::size_t>& ranked, std::size_t k);

}  // namespace swim::design
