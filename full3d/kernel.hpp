// Peskin's four-point regularised delta function (paper eq. 18).
//
//   delta_h(z) = phi(z/h) / h,   D_h(x) = delta_h(x1) delta_h(x2) delta_h(x3)   (eq. 17)
//
//   phi(r) = (3 - 2|r| + sqrt(1 + 4|r| - 4 r^2)) / 8,   |r| <= 1
//          = (5 - 2|r| - sqrt(-7 + 12|r| - 4 r^2)) / 8, 1 <= |r| <= 2
//          = 0,                                          otherwise
//
// The argument r is the distance in units of the grid spacing h; callers apply
// the 1/h factors. phi satisfies, for every offset a:
//   sum_j phi(a - j) = 1, sum_{j even} = sum_{j odd} = 1/2,
//   sum_j (a - j) phi(a - j) = 0, sum_j phi(a - j)^2 = 3/8.
#pragma once

#include <cmath>

namespace swim::full3d {

inline double peskin_4pt(double r) {
  const double a = std::abs(r);
  if (a <= 1.0) return 0.125 * (3.0 - 2.0 * a + std::sqrt(1.0 + 4.0 * a - 4.0 * a * a));
  if (a < 2.0) {
    const double disc = -7.0 + 12.0 * a - 4.0 * a * a;  // >= 0 on [1,2]; clamp round-off
    return 0.125 * (5.0 - 2.0 * a - std::sqrt(disc > 0.0 ? disc : 0.0));
  }
  return 0.0;
}

/// The four non-zero weights of one node along one direction, all from one square root.
/// With r the node position in grid units (relative to the first grid point), i0 =
/// floor(r) - 1 and t = r - floor(r) in [0, 1), the stencil points i0 .. i0+3 lie at
/// distances 1+t, t, 1-t, 2-t from the node. On every branch of eq. (18) the radicand
/// reduces to the same q^2 = 1 + 4t - 4t^2 (>= 1 on [0, 1), so no clamping is needed):
///   w[0] = phi(1+t) = (3 - 2t - q)/8,   w[1] = phi(t)   = (3 - 2t + q)/8,
///   w[2] = phi(1-t) = (1 + 2t + q)/8,   w[3] = phi(2-t) = (1 + 2t - q)/8.
/// This is eq. (18) evaluated exactly (identical to peskin_4pt up to round-off).
inline void peskin_4pt_weights(double t, double w[4]) {
  const double q = std::sqrt(1.0 + 4.0 * t - 4.0 * t * t);
  const double a = 3.0 - 2.0 * t, b = 1.0 + 2.0 * t;
  w[0] = 0.125 * (a - q);
  w[1] = 0.125 * (a + q);
  w[2] = 0.125 * (b + q);
  w[3] = 0.125 * (b - q);
}

/// Half-width of the support of peskin_4pt in grid cells.
inline constexpr int kPeskin4ptHalfWidth = 2;

}  // namespace swim::full3d
