#include "axi/ib_axi.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "full3d/kernel.hpp"

namespace swim::axi {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

inline int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

// Four stencil points i0 .. i0+3 and their weights phi(.) for a coordinate c (in cells)
// against grid points at (i + offset) h.
struct Stencil {
  int i0;
  double w[4];
};

inline Stencil stencil(double c, double offset) {
  Stencil s;
  const double r = c - offset;
  const double fl = std::floor(r);
  full3d::peskin_4pt_weights(r - fl, s.w);
  s.i0 = int(fl) - 1;
  return s;
}

// Axial stencil (periodic): indices wrapped into [0, nx).
struct AxialStencil {
  int j[4];
  double w[4];
};

inline AxialStencil axial_stencil(const AxiGrid& g, double x, double offset) {
  const double P = g.period();
  const double xw = x - P * std::floor(x / P);  // in [0, P] (P itself possible by round-off)
  const Stencil s = stencil(xw / g.h, offset);
  AxialStencil a;
  int j = wrap(s.i0, g.nx);
  for (int m = 0; m < 4; ++m) {
    a.j[m] = j;
    a.w[m] = s.w[m];
    if (++j == g.nx) j = 0;
  }
  return a;
}

void check_ring(const AxiGrid& g, double x, double r) {
  if (!std::isfinite(x) || !std::isfinite(r))
    throw NumericalError("a wall ring has a non-finite position (x = " + significant(x) + " m, r = " + significant(r) + " m)",
                         "reduce the time step tolerance (axi.time) or check the wall parameters");
  if (!(r >= (2.0 + 1e-9) * g.h))
    throw NumericalError("a wall ring came within 2 cells of the axis (r = " + significant(r) + " m, h = " + significant(g.h) +
                             " m)",
                         "refine axi.grid.cells_across or raise wave.contracted_ratio");
}

// The ring's stencils: radial for the u points (offset 0, rows 1..nr-1 kept) and the w points
// (offset 1/2, rows 0..nr-1 kept); axial for the u points (x_cell, offset 1/2) and the w
// points (x_face, offset 0). Dropped points get weight 0 (row index clamped to 0).
struct RingStencil {
  int iu[4], iw[4];
  double wu[4], ww[4];
  AxialStencil xu, xw;
};

inline RingStencil ring_stencil(const AxiGrid& g, double x, double r) {
  check_ring(g, x, r);
  RingStencil s;
  const Stencil su = stencil(r / g.h, 0.0), sw = stencil(r / g.h, 0.5);
  for (int m = 0; m < 4; ++m) {
    const int a = su.i0 + m, b = sw.i0 + m;
    const bool ua = a >= 1 && a <= g.nr - 1, wb = b >= 0 && b <= g.nr - 1;
    s.iu[m] = ua ? a : 0;
    s.wu[m] = ua ? su.w[m] : 0.0;
    s.iw[m] = wb ? b : 0;
    s.ww[m] = wb ? sw.w[m] : 0.0;
  }
  s.xu = axial_stencil(g, x, 0.5);
  s.xw = axial_stencil(g, x, 0.0);
  return s;
}

void check_columns(const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F) {
  if (X.cols() != F.cols())
    throw std::invalid_argument("axi::spread: X and F must have one column per ring (" +
                                std::to_string(X.cols()) + " vs " + std::to_string(F.cols()) + ")");
}

}  // namespace

void spread(const AxiGrid& g, const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, std::vector<double>& fr,
            std::vector<double>& fx) {
  check_columns(X, F);
  fr.assign(g.u_size(), 0.0);
  fx.assign(g.w_size(), 0.0);
  const double ih2 = 1.0 / (g.h * g.h);
  for (Eigen::Index k = 0; k < X.cols(); ++k) {
    const RingStencil s = ring_stencil(g, X(0, k), X(1, k));
    const double Fx = F(0, k) * ih2 / kTwoPi, Fr = F(1, k) * ih2 / kTwoPi;
    for (int m = 0; m < 4; ++m) {
      if (s.ww[m] != 0.0) {
        const double c = Fx * s.ww[m] / g.r_cell(s.iw[m]);
        double* row = fx.data() + g.at(s.iw[m], 0);
        for (int n = 0; n < 4; ++n) row[s.xw.j[n]] += c * s.xw.w[n];
      }
      if (s.wu[m] != 0.0) {
        const double c = Fr * s.wu[m] / g.r_face(s.iu[m]);
        double* row = fr.data() + g.at(s.iu[m], 0);
        for (int n = 0; n < 4; ++n) row[s.xu.j[n]] += c * s.xu.w[n];
      }
    }
  }
}

void interpolate(const AxiGrid& g, const Eigen::Matrix3Xd& X, const double* u, const double* w,
                 Eigen::Matrix3Xd& U) {
  U.resize(3, X.cols());
  for (Eigen::Index k = 0; k < X.cols(); ++k) {
    const RingStencil s = ring_stencil(g, X(0, k), X(1, k));
    double ax = 0.0, ra = 0.0;
    for (int m = 0; m < 4; ++m) {
      const double* roww = w + g.at(s.iw[m], 0);
      const double* rowu = u + g.at(s.iu[m], 0);
      double sx = 0.0, sr = 0.0;
      for (int n = 0; n < 4; ++n) {
        sx += roww[s.xw.j[n]] * s.xw.w[n];
        sr += rowu[s.xu.j[n]] * s.xu.w[n];
      }
      ax += s.ww[m] * sx;
      ra += s.wu[m] * sr;
    }
    U(0, k) = ax;
    U(1, k) = ra;
    U(2, k) = 0.0;
  }
}

namespace {

void check_point(const AxiGrid& g, double x, double r, const char* who) {
  if (!std::isfinite(x) || !(r >= 0.0) || !(r <= g.radius()))
    throw std::invalid_argument(std::string(who) + ": the point (x = " + significant(x) + " m, r = " + significant(r) +
                                " m) must have a finite x and 0 <= r <= Rc = " + significant(g.radius()) + " m");
}

// Kernel sample at (x, r) of a field whose radial rows sit at (i + offset) h (offset 0: u,
// rows 0..nr; offset 1/2: w, rows 0..nr-1), whose axial points sit at (j + x_offset) h, with
// the images across the axis (sign axis_sign) and the wall (odd). Rows outside [lo, hi] after
// the mapping are zero (u on the axis and the wall).
double sample(const AxiGrid& g, const double* a, double x, double r, double offset, double axis_sign, int lo, int hi,
              double x_offset) {
  const Stencil sr = stencil(r / g.h, offset);
  const AxialStencil sx = axial_stencil(g, x, x_offset);
  const int nr = g.nr;
  double sum = 0.0;
  for (int m = 0; m < 4; ++m) {
    int i = sr.i0 + m;
    double sign = 1.0;
    // images: about the axis, row i <-> row -i (u, offset 0) or -1-i (w, offset 1/2); about
    // the wall, row i <-> 2 nr - i (u) or 2 nr - 1 - i (w), odd.
    const int ax = offset == 0.0 ? 0 : -1, wl = offset == 0.0 ? 2 * nr : 2 * nr - 1;
    while (i < 0 || i > (offset == 0.0 ? nr : nr - 1)) {
      if (i < 0) {
        i = ax - i;
        sign *= axis_sign;
      } else {
        i = wl - i;
        sign = -sign;
      }
    }
    if (i < lo || i > hi) continue;  // u on the axis or the wall: zero
    const double* row = a + g.at(i, 0);
    double s = 0.0;
    for (int n = 0; n < 4; ++n) s += row[sx.j[n]] * sx.w[n];
    sum += sign * sr.w[m] * s;
  }
  return sum;
}

}  // namespace

double sample_w(const AxiGrid& g, const double* w, double x, double r) {
  check_point(g, x, r, "axi::sample_w");
  return sample(g, w, x, r, 0.5, 1.0, 0, g.nr - 1, 0.0);
}

double sample_u(const AxiGrid& g, const double* u, double x, double r) {
  check_point(g, x, r, "axi::sample_u");
  return sample(g, u, x, r, 0.0, -1.0, 1, g.nr - 1, 0.5);
}

double disc_flux(const AxiGrid& g, const double* w, double x, double radius, double frame_velocity,
                 int n_radial) {
  if (n_radial < 1) throw std::invalid_argument("axi::disc_flux: n_radial must be >= 1");
  if (!(radius >= 0.0) || !(radius <= g.radius()))
    throw std::invalid_argument("axi::disc_flux: the radius " + significant(radius) + " m must lie in [0, Rc = " +
                                significant(g.radius()) + " m]");
  if (!std::isfinite(x)) throw std::invalid_argument("axi::disc_flux: non-finite axial position");
  const double dr = radius / n_radial;
  double q = 0.0;
  for (int m = 0; m < n_radial; ++m) {
    const double r = (m + 0.5) * dr;
    q += r * (sample(g, w, x, r, 0.5, 1.0, 0, g.nr - 1, 0.0) - frame_velocity);
  }
  return kTwoPi * q * dr;
}

}  // namespace swim::axi
