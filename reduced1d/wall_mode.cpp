#include "reduced1d/wall_mode.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_sf_bessel.h>

#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace swim::reduced1d {

namespace {

// One basis solution of the mode's Stokes equations, psi = f(r) cos(kz), u_r = (k f / r) sin(kz),
// u_z = (f' / r) cos(kz), evaluated at r: the amplitudes of u_r, u_z and sigma_rr = -p + 2 mu
// du_r/dr, each divided by mu-free factors common to the basis (the solve is linear, so any
// per-column scale cancels). The four f: r I1(kr), r^2 I0(kr) (regular on the axis) and r K1(kr),
// r^2 K0(kr) (decaying); the pressures are 0, 2 mu k I0(kr), 0, 2 mu k K0(kr) times sin(kz).
// I-type columns are multiplied by exp(-k r_ref), K-type by exp(k r_ref), r_ref given, so that
// the scaled GSL functions never overflow.
struct Column {
  double ur, uz, srr;
};

Column column(int kind, double k, double r, double r_ref, double mu) {
  const double x = k * r;
  if (kind <= 2) {
    const double s = std::exp(x - k * r_ref);  // I_n(x) exp(-k r_ref) = I_n_scaled(x) exp(x - k r_ref)
    const double i0 = gsl_sf_bessel_I0_scaled(x) * s, i1 = gsl_sf_bessel_I1_scaled(x) * s;
    if (kind == 1) return {k * i1, k * i0, 2 * mu * k * k * (i0 - i1 / x)};
    return {x * i0, 2 * i0 + x * i1, 2 * mu * k * x * i1};  // r^2 I0 divided by 1/k (a column scale)
  }
  const double s = std::exp(k * r_ref - x);  // K_n(x) exp(k r_ref) = K_n_scaled(x) exp(k r_ref - x)
  const double k0 = gsl_sf_bessel_K0_scaled(x) * s, k1 = gsl_sf_bessel_K1_scaled(x) * s;
  if (kind == 3) return {k * k1, -k * k0, -2 * mu * k * k * (k0 + k1 / x)};
  return {x * k0, 2 * k0 - x * k1, -2 * mu * k * x * k1};
}

void check(double k, double R, double Rc, double mu) {
  if (!(k > 0 && std::isfinite(k)) || !(R > 0 && std::isfinite(R)) || !(Rc > R) || !(mu > 0 && std::isfinite(mu)))
    throw std::invalid_argument("wall mode resistance: need k > 0, 0 < R < Rc (Rc may be infinite), mu > 0; got k = " +
                                std::to_string(k) + ", R = " + std::to_string(R) + ", Rc = " + std::to_string(Rc) +
                                ", mu = " + std::to_string(mu));
}

/// sigma_rr at the wall of the combination of two basis columns with u_r = 1, u_z = 0 there.
double two_column_stress(const Column& a, const Column& b) {
  Eigen::Matrix2d M;
  M << a.ur, b.ur, a.uz, b.uz;
  const Eigen::Vector2d c = M.partialPivLu().solve(Eigen::Vector2d(1.0, 0.0));
  return c[0] * a.srr + c[1] * b.srr;
}

}  // namespace

WallModeResistance stokes_wall_mode_resistance(double k, double R, double Rc, double mu) {
  check(k, R, Rc, mu);
  gsl_error_handler_t* old = gsl_set_error_handler_off();
  WallModeResistance z;
  // Lumen: u_r(R) = 1, u_z(R) = 0; sigma_rr on the lumen side (the force on the wall is -sigma_rr).
  z.lumen = two_column_stress(column(1, k, R, R, mu), column(2, k, R, R, mu));
  if (std::isinf(Rc)) {
    // the outer fluid pulls the wall with +sigma_rr
    z.annulus = -two_column_stress(column(3, k, R, R, mu), column(4, k, R, R, mu));
  } else {
    // Annulus: u_r(R) = 1, u_z(R) = 0, u(Rc) = 0. I-type columns scaled at Rc, K-type at R.
    Column col[4], colc[4];
    for (int j = 0; j < 4; ++j) {
      const double ref = j < 2 ? Rc : R;
      col[j] = column(j + 1, k, R, ref, mu);
      colc[j] = column(j + 1, k, Rc, ref, mu);
    }
    Eigen::Matrix4d M;
    for (int j = 0; j < 4; ++j) {
      M(0, j) = col[j].ur;
      M(1, j) = col[j].uz;
      M(2, j) = colc[j].ur;
      M(3, j) = colc[j].uz;
    }
    const Eigen::Vector4d c = M.partialPivLu().solve(Eigen::Vector4d(1.0, 0.0, 0.0, 0.0));
    double s = 0;
    for (int j = 0; j < 4; ++j) s += c[j] * col[j].srr;
    z.annulus = -s;
  }
  gsl_set_error_handler(old);
  if (!std::isfinite(z.lumen) || !std::isfinite(z.annulus))
    throw std::invalid_argument("wall mode resistance: not representable in double precision at kR = " +
                                std::to_string(k * R));
  return z;
}

WallModeResistance lubrication_wall_mode_resistance(double k, double R, double Rc, double mu, bool traction) {
  check(k, R, Rc, mu);
  WallModeResistance z;
  z.lumen = 16 * mu / (k * k * R * R * R);
  if (std::isfinite(Rc)) {
    const double d = Rc * Rc - R * R;
    const double G = Rc * Rc * Rc * Rc - R * R * R * R - d * d / std::log(Rc / R);
    z.annulus = 16 * mu * R / (k * k * G);
  }
  if (traction) {
    z.lumen += 2 * mu * k;
    z.annulus += 2 * mu * k;
  }
  return z;
}

}  // namespace swim::reduced1d
