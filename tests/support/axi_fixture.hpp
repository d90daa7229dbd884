// The axisymmetric tier's test fixture: the tube the fitted-mesh tests place in its periodic
// container, their mesh parameters, and the manufactured smooth Stokes flow both of the tier's
// fluid solvers are checked against.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "axi/fitted_mesh.hpp"

namespace swim::test {

/// The fitted-mesh tests' tube and container, SI.
namespace fitted_tube {
constexpr double kMu = 1.0e-3;   ///< viscosity, Pa s
constexpr double kRc = 0.25e-6;  ///< container radius, m
constexpr double kP = 2.0e-6;    ///< period, m
constexpr double kA = 0.125e-6;  ///< tube radius, m
constexpr double kL = 0.4e-6;    ///< tube length, m
}  // namespace fitted_tube

/// The fitted mesh in the container of radius Rc and `period`: ci element rows inside the wall,
/// co outside, gap columns across the gap growing by `growth`.
inline axi::FittedMeshParams fitted_mesh_params(double Rc, double period, int ci, int co, int gap, double growth) {
  axi::FittedMeshParams p;
  p.Rc = Rc;
  p.period = period;
  p.cells_inner = ci;
  p.cells_outer = co;
  p.gap_columns = gap;
  p.gap_growth = growth;
  return p;
}

/// A polynomial in r, coefficients from the constant term up.
struct Poly {
  std::vector<double> c;
  double operator()(double r) const {
    double s = 0.0;
    for (std::size_t n = c.size(); n-- > 0;) s = s * r + c[n];
    return s;
  }
  Poly d() const {
    Poly q;
    for (std::size_t n = 1; n < c.size(); ++n) q.c.push_back(double(n) * c[n]);
    if (q.c.empty()) q.c.push_back(0.0);
    return q;
  }
};

/// A smooth Stokes flow in the periodic cylinder of radius Rc, from the stream function
/// psi = A r^2 (Rc^2 - r^2)^2 sin(kx x) (u_r = -(1/r) dpsi/dx, u_x = (1/r) dpsi/dr:
/// divergence-free, u_r = 0 on the axis, u = 0 at Rc, periodic):
///   u_r = U(r) cos(kx x), U = -A kx r (Rc^2 - r^2)^2;  u_x = W(r) sin(kx x), W = 2 A (Rc^2 - r^2)(Rc^2 - 3 r^2);
///   p = Q(r) cos(kx x), Q = P0 (1 + r^2/Rc^2)  (zero mean over x, so zero volume mean);
/// max u_x = 0.01 m/s, P0 = mu 0.01 / Rc. The forces from the strong equations:
///   f_r = [Q' - mu (U'' + U'/r - U/r^2 - kx^2 U)] cos,  f_x = [-kx Q - mu (W'' + W'/r - kx^2 W)] sin.
struct ManufacturedAxiFlow {
  double mu, kx, A, P0;
  Poly U, W, Q;
  ManufacturedAxiFlow(double Rc, double period, double mu_) : mu(mu_), kx(2 * std::numbers::pi / period) {
    A = 0.01 / (2 * Rc * Rc * Rc * Rc);
    P0 = mu * 0.01 / Rc;
    const double R2 = Rc * Rc;
    U.c = {0.0, -A * kx * R2 * R2, 0.0, 2 * A * kx * R2, 0.0, -A * kx};
    W.c = {2 * A * R2 * R2, 0.0, -8 * A * R2, 0.0, 6 * A};
    Q.c = {P0, 0.0, P0 / R2};
  }
  // U'/r - U/r^2 for odd U: term c_n r^n -> (n - 1) c_n r^(n-2); W'/r for even W: n c_n r^(n-2).
  double u_extra(double r) const {
    double s = 0.0;
    for (std::size_t n = 3; n < U.c.size(); ++n) s += double(n - 1) * U.c[n] * std::pow(r, double(n) - 2);
    return s;
  }
  double w_extra(double r) const {
    double s = 0.0;
    for (std::size_t n = 2; n < W.c.size(); ++n) s += double(n) * W.c[n] * std::pow(r, double(n) - 2);
    return s;
  }
  double f_r(double r, double x) const {
    return (Q.d()(r) - mu * (U.d().d()(r) + u_extra(r) - kx * kx * U(r))) * std::cos(kx * x);
  }
  double f_x(double r, double x) const {
    return (-kx * Q(r) - mu * (W.d().d()(r) + w_extra(r) - kx * kx * W(r))) * std::sin(kx * x);
  }
  double u_r(double r, double x) const { return U(r) * std::cos(kx * x); }
  double u_x(double r, double x) const { return W(r) * std::sin(kx * x); }
  double p(double r, double x) const { return Q(r) * std::cos(kx * x); }
};

}  // namespace swim::test
