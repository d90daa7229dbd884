// Composite 10-point Gauss-Legendre quadrature for the tests' reference integrals.
#pragma once

namespace swim::test {

/// The integral of f over [t0, t1], 10-point Gauss-Legendre on each of `pieces` equal
/// sub-intervals.
template <class F>
double gauss_legendre10(F&& f, double t0, double t1, int pieces) {
  static constexpr double xg[5] = {0.1488743389816312, 0.4333953941292472, 0.6794095682990244, 0.8650633666889845,
                                   0.9739065285171717};
  static constexpr double wg[5] = {0.2955242247147529, 0.2692667193099963, 0.2190863625159820, 0.1494513318108240,
                                   0.0666713443086881};
  double sum = 0;
  for (int p = 0; p < pieces; ++p) {
    const double a0 = t0 + (t1 - t0) * p / pieces, a1 = t0 + (t1 - t0) * (p + 1) / pieces;
    const double c = 0.5 * (a0 + a1), r = 0.5 * (a1 - a0);
    for (int k = 0; k < 5; ++k) sum += wg[k] * r * (f(c - r * xg[k]) + f(c + r * xg[k]));
  }
  return sum;
}

}  // namespace swim::test
