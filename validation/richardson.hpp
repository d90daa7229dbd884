// Extrapolation of a grid-dependent figure f(h) to h -> 0 (Richardson, observed order).
//
// With three grids h1 > h2 > h3 and f(h) = f0 + C h^p + o(h^p), the observed order p solves
//   (f1 - f2) / (f2 - f3) = (h1^p - h2^p) / (h2^p - h3^p)
// (Brent on p in [kOrderSearchMin, kOrderSearchMax]; for a constant refinement ratio r it is
// ln(ratio)/ln(r)), and
//   f0 = f3 + (f3 - f2) / ((h2 / h3)^p - 1),   error estimate |f0 - f3|.
// The sequence is not in its asymptotic range when the two differences have opposite signs,
// when p lies outside the range of orders the discretisation can show (OrderRange: an
// immersed-boundary method is first order at best), or when the correction would exceed half
// the finest value: the finest value is then returned with the spread of the three as its
// error, and `asymptotic` is false. With two grids the order must be given (`assumed_order`,
// inside the range); the error is then the larger of the correction and the difference of
// the two values.
#pragma once

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace swim::validation {

/// Largest accepted correction of an extrapolation, as a fraction of the finest value.
constexpr double kMaxCorrection = 0.5;

/// Observed orders are searched on this bracket; outside it the note says "below"/"above".
constexpr double kOrderSearchMin = 0.01;
constexpr double kOrderSearchMax = 20.0;

/// The observed orders a discretisation can show. An observed order outside it says the grids
/// are not in the asymptotic range (or that something else than h changes between them).
struct OrderRange {
  double lo = 0.5;
  double hi = 1.5;
  /// "[0.5, 1.5]"
  std::string text() const;
};

/// Immersed-boundary methods (the 3D tier, the axisymmetric IB tier): first order at best, so in
/// the asymptotic range the grids show an order near 1: down to 0.5 (a free rim's square-root
/// singularity), up to 1.5. An order near 2 on three grids of a first-order method says the h^2
/// term still carries the grids' differences, which is the error expansion's domain
/// (expansion_fit), not Richardson's: on the round R_f = 0.82 R0 wall the 3D tier's three finest
/// grids show 1.98 and extrapolate 19 % below the axisymmetric reference, the expansion over its
/// five grids within 0.2 % of it (docs/validation.md).
constexpr OrderRange kImmersedBoundaryOrders{0.5, 1.5};
/// The highest order a first-order method's range may admit: a range that ends at or below it
/// is a first-order scheme's (expansion_fit, the smeared lumen's fit of the cycle time).
constexpr double kFirstOrderHighest = 2.0;
/// A sharp-interface method of second order.
constexpr OrderRange kSharpInterfaceOrders{1.0, 3.5};

struct Extrapolation {
  double value = 0;      ///< extrapolated f0 (or the finest value when not asymptotic)
  double error = 0;      ///< estimated error of `value`
  double order = 0;      ///< observed (or assumed) order p used; 0 when not asymptotic
  /// order the three grids show, also when it is rejected; NaN when there is none (two grids,
  /// differences of opposite sign, or an order beyond the search bracket)
  double observed_order = std::numeric_limits<double>::quiet_NaN();
  bool asymptotic = false;
  /// the grid differences lie within the time integration's error, so no order is observed, and
  /// the error is bounded at the scheme's lowest order instead (bound_within_time_error)
  bool within_time_error = false;
  /// "richardson" (or two grids with the assumed order), "expansion_fit", "lumen_fit",
  /// "time_error_bound", "finest_grid"
  std::string method = "finest_grid";
  std::string note;      ///< how the value was obtained
  /// method "expansion_fit": the fitted a (per m of h) and b (per m^2) of f0 + a h + b h^2;
  /// NaN otherwise
  double expansion_a = std::numeric_limits<double>::quiet_NaN();
  double expansion_b = std::numeric_limits<double>::quiet_NaN();
  /// method "lumen_fit": the fitted a (per m of h) of T0 (1 - a h)^-4; NaN otherwise
  double lumen_a = std::numeric_limits<double>::quiet_NaN();
};

/// Root of f in [lo, hi], where f(lo) and f(hi) differ in sign (GSL Brent, to 1e-14 relative).
/// Throws NumericalError when the solver fails.
double bracketed_root(const std::function<double(double)>& f, double lo, double hi);

/// h: grid spacings (any order), f: the figure on each; `range`: the orders the scheme can
/// show (default: immersed boundary, [0.5, 1.5]). Throws InputError for fewer than two grids,
/// repeated spacings, mismatched sizes, an empty or non-positive range, or an assumed order
/// outside the range.
Extrapolation richardson(std::vector<double> h, std::vector<double> f, double assumed_order = 1.0,
                         OrderRange range = kImmersedBoundaryOrders);

/// The error expansion of a first-order method before its asymptotic range,
///   f(h) = f0 + a h + b h^2,
/// fitted by least squares to four or more grids (an immersed boundary whose first-order
/// smearing of the wall is large enough for the second-order term to matter on every affordable
/// grid: the three-grid Richardson then shows no order). The error of f0 is the larger of
///   - the largest change of f0 when one grid is left out of the fit (each refit has three
///     grids or more), which the fit's own residual cannot hide, and
///   - its distance to the finest pair's Richardson value at order 1 and at the lowest order
///     the scheme can show (range.lo): before the asymptotic range an immersed boundary shows
///     orders below 1 (the free rims' square-root singularities), which integer powers miss. The fit is refused (the finest value with the spread of the
/// finest three as its error, `asymptotic` false, `order` 0) when it has fewer than four grids,
/// when the scheme is not first order at best (its order range must hold 1 and end at 2 or
/// below: a second-order method's expansion has no h term), or when f0 moves the finest value by more than
/// half of it (kMaxCorrection). A fitted value is not asymptotic either: `asymptotic` stays
/// false, `order` is 1 (the leading term) and the note says how it was obtained.
Extrapolation expansion_fit(std::vector<double> h, std::vector<double> f, OrderRange range = kImmersedBoundaryOrders);

/// The cycle time of an immersed-boundary series before its asymptotic range, by the way the
/// boundary's smearing slows it: the kernel narrows the lumen the flow sees by a fixed multiple
/// of h (the calibrated hydraulic offsets, docs/validation.md), and the cycle is set by the
/// lumen's Poiseuille resistance, R^-4, so that
///   T(h) = T0 (1 - a h)^-4,   i.e.   T^-1/4 = T0^-1/4 (1 - a h),
/// a straight line in h, fitted by least squares to three or more grids. The error of T0 is the
/// largest of the change of T0 when one grid is left out (four grids or more), its distance to
/// the line through the two finest grids alone, and kLumenModelShare of its correction (the
/// model's own error, measured against the axisymmetric references). Refused (the finest value with the
/// spread of the finest three as its error, method "finest_grid") with fewer than three grids, a
/// non-positive time, a line that does not fall towards the coarse grids (a <= 0) or reaches
/// zero within them (a h >= 1), and a T0 more than half away from the finest value
/// (kMaxCorrection). The value is not asymptotic (`asymptotic` false, `order` 1: the smearing is
/// first order) and its note says so. `lumen_a` is a (per m of h).
Extrapolation lumen_fit(std::vector<double> h, std::vector<double> T);

/// The least error of lumen_fit, as a share of its correction |T0 - T_finest|: on the converged
/// suite's round walls the fit missed the axisymmetric reference by 6 % and 17 % of its
/// correction on the two monotone five-grid series (L = 0.2 and 0.4 um), so a quarter.
constexpr double kLumenModelShare = 0.25;

/// richardson() over the grids; where the finest three are not in the asymptotic range and the
/// series has four or more grids of a first-order method, expansion_fit() instead (when it is
/// not refused; its note then also gives Richardson's).
Extrapolation extrapolate_series(const std::vector<double>& h, const std::vector<double>& f, double assumed_order,
                                 OrderRange range);

/// A figure that is the sum of parts that converge differently (the cycle time as the sum of
/// the protocol's phases), each part extrapolated on its own with richardson(). Where the
/// parts' errors have opposite signs and different orders, the sum's own series can show no
/// order although each part has one.
struct SumExtrapolation {
  double value = 0;          ///< sum of the parts' values
  double error = 0;          ///< sum of the parts' |errors|
  double relative_error = 0; ///< error / |value|
  bool asymptotic = false;   ///< every part asymptotic
  /// relative_error <= target, and every part either asymptotic with an observed order or
  /// carrying an error of at most a tenth of the target (relative to the sum): a part too
  /// short for its grid differences to show an order cannot spoil the sum
  bool converged = false;
  std::vector<Extrapolation> parts;
};

/// A series whose grid-to-grid differences are within the noise of its time integration. Each
/// value carries up to `time_error` from the integrator's step tolerance, so when every
/// difference between neighbouring grids among the finest three is at most 2 time_error, the
/// differences say nothing about the order. The finest value's grid error is then bounded with
/// the scheme's lowest order instead: with f(h) = f0 + C h^p and p >= range.lo, the finest
/// value's error is d / ((h_a / h_b)^p - 1) for a pair of grids h_a > h_b whose true difference
/// is d, at most (|f_a - f_b| + 2 time_error) / ((h_a / h_b)^range.lo - 1); the larger of the two
/// pairs' bounds is kept. The result: the finest value, error = that bound + time_error,
/// method "time_error_bound", `within_time_error` true, `asymptotic` false and `order` 0 (no
/// order is observed). Nothing (std::nullopt) with fewer than three grids, a time_error that is
/// not positive and finite, or a difference beyond 2 time_error. Throws InputError as
/// richardson() for repeated spacings and mismatched sizes.
std::optional<Extrapolation> bound_within_time_error(std::vector<double> h, std::vector<double> f, double time_error,
                                                     OrderRange range);

/// h: grid spacings; parts[g]: the parts on grid g (the same number on every grid, two or
/// more), target: the relative error the sum must reach. Throws InputError as richardson(),
/// and for parts that differ in number or are fewer than two.
SumExtrapolation richardson_sum(const std::vector<double>& h, const std::vector<std::vector<double>>& parts,
                                double assumed_order, OrderRange range, double target);

}  // namespace swim::validation
