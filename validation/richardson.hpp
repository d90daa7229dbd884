// Extrapolation of a grid-dependent figure f(h) to h -> 0 (Richardson, observed order).
//
// With three grids h1 > h2 > h3 and f(h) = f0 + C h^p + o(h^p), the observed order p solves
//   (f1 - f2) / (f2 - f3) = (h1^p - h2^p) / (h2^p - h3^p)
// (bisection on p in [0.25, 8]; for a constant refinement ratio r it is ln(ratio)/ln(r)), and
//   f0 = f3 + (f3 - f2) / ((h2 / h3)^p - 1),   error estimate |f0 - f3|.
// When the two differences have opposite signs, or p leaves [0.25, 8], the sequence is not in
// its asymptotic range: the finest value is returned with the spread of the three as its
// error, and `asymptotic` is false. With two grids the order must be given (`assumed_order`).
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace swim::validation {

/// Largest accepted correction of an extrapolation, as a fraction of the finest value.
constexpr double kMaxCorrection = 0.5;

struct Extrapolation {
  double value = 0;      ///< extrapolated f0 (or the finest value when not asymptotic)
  double error = 0;      ///< estimated error of `value`
  double order = 0;      ///< observed (or assumed) order p; 0 when not asymptotic
  bool asymptotic = false;
  std::string note;      ///< how the value was obtained
};

/// Root of f in [lo, hi], where f(lo) and f(hi) differ in sign (GSL Brent, to 1e-14 relative).
/// Throws NumericalError when the solver fails.
double bracketed_root(const std::function<double(double)>& f, double lo, double hi);

/// h: grid spacings (any order), f: the figure on each. Throws InputError for fewer than two
/// grids, repeated spacings, or mismatched sizes.
Extrapolation richardson(std::vector<double> h, std::vector<double> f, double assumed_order = 1.0);

}  // namespace swim::validation
