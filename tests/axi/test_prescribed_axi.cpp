// The fitted Stokes solver's prescribed wall velocity (FittedStokes::prescribed_wall_velocity)
// and the prescribed-wave swimmer built on it (axi/prescribed_axi.hpp). What each test expects,
// and why, is stated at the test.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "axi/fe_stokes_axi.hpp"
#include "axi/fitted_mesh.hpp"
#include "axi/prescribed_axi.hpp"
#include "tests/support/axi_fixture.hpp"

using swim::axi::FittedMeshParams;
using swim::axi::FittedStokes;

namespace {

using namespace swim::test::fitted_tube;

constexpr double kPi = std::numbers::pi;

FittedMeshParams params(int ci, int co, int gap, double period = kP, double growth = 1.0) {
  return swim::test::fitted_mesh_params(kRc, period, ci, co, gap, growth);
}

// n rings uniform over [x0, x0 + L]; radius a (1 + bump sin(pi s) + asym sin(pi s)^2 sin(2 pi s)),
// s = (x - x0)/L: bump keeps the mirror symmetry about the midplane, asym breaks it.
Eigen::Matrix3Xd tube(int n, double bump, double asym, double L = kL, double x0 = 0.3e-6) {
  Eigen::Matrix3Xd X = Eigen::Matrix3Xd::Zero(3, n);
  for (int k = 0; k < n; ++k) {
    const double s = double(k) / (n - 1), sp = std::sin(kPi * s);
    X(0, k) = x0 + s * L;
    X(1, k) = kA * (1.0 + bump * sp + asym * sp * sp * std::sin(2 * kPi * s));
  }
  return X;
}

Eigen::Matrix3Xd radial(const Eigen::VectorXd& vr) {
  Eigen::Matrix3Xd V = Eigen::Matrix3Xd::Zero(3, vr.size());
  V.row(1) = vr.transpose();
  return V;
}

}  // namespace

// A wall that does not deform (dR/dt = 0) exerts no force when it does not move: the data of
// solve (a) are zero, so F_a = 0 and U = 0 exactly, whatever the shape; the towed tube's drag
// is positive (it pulls the fluid along).
TEST(FittedPrescribed, RigidTubeDoesNotSwim) {
  const int n = 17;
  FittedStokes s(params(4, 4, 24), kMu, n);
  const auto w = s.prescribed_wall_velocity(tube(n, 0.1, 0.3), Eigen::Matrix3Xd::Zero(3, n));
  EXPECT_EQ(w.velocity, 0.0);
  EXPECT_EQ(w.force, 0.0);
  EXPECT_GT(w.drag, 0.0);
}

// A tube symmetric about its midplane contracting uniformly (every ring at the same dR/dt) is
// its own mirror image: the flow is mirror symmetric and the axial force, odd under the mirror,
// vanishes. The mesh is mirror symmetric too (the gap's columns are), so U = 0 to round-off
// (below 1e-10 of |dR/dt|). The same contraction of an asymmetric tube swims (|U| > 1e-3 |dR/dt|):
// the symmetry, not the solver, makes U vanish.
TEST(FittedPrescribed, MirrorSymmetricContractionDoesNotSwim) {
  const int n = 17;
  const double c = 1e-6;  // m/s
  FittedStokes s(params(4, 4, 24, kP, 1.2), kMu, n);
  const Eigen::VectorXd vr = Eigen::VectorXd::Constant(n, -c);
  const auto sym = s.prescribed_wall_velocity(tube(n, 0.2, 0.0), radial(vr));
  std::printf("symmetric: U = %.3e m/s (dR/dt = %.1e m/s), F_a = %.3e N, F_b = %.3e N s/m\n", sym.velocity, -c,
              sym.force, sym.drag);
  EXPECT_LT(std::abs(sym.velocity), 1e-10 * c);
  const auto asym = s.prescribed_wall_velocity(tube(n, 0.2, 0.4), radial(vr));
  std::printf("asymmetric: U = %.3e m/s\n", asym.velocity);
  EXPECT_GT(std::abs(asym.velocity), 1e-3 * c);
}

// Mass conservation at every instant: the lumen (the elements inside the wall line between the
// two end discs) conserves mass element by element, the wall line carries the linear
// interpolation of the ring velocities (exactly the velocity of the piecewise-linear wall), so
// the rate of change of the frustums' volume equals the net inflow through the end discs
// relative to the rings: dV/dt = Q_rear - Q_front to round-off (1e-10 of pi a^2 |dR/dt|).
TEST(FittedPrescribed, LumenVolumeRateEqualsEndDiscFluxes) {
  const int n = 21;
  FittedStokes s(params(4, 4, 24, kP, 1.2), kMu, n);
  const Eigen::Matrix3Xd X = tube(n, 0.1, 0.3);
  Eigen::VectorXd vr(n);
  for (int k = 0; k < n; ++k) vr[k] = 1e-6 * std::cos(0.7 * k + 0.3) * (1.0 + 0.1 * k);
  const auto w = s.prescribed_wall_velocity(X, radial(vr));
  double dV = 0.0;
  for (int k = 0; k + 1 < n; ++k) {
    const double a = X(1, k), b = X(1, k + 1), da = vr[k], db = vr[k + 1];
    dV += kPi / 3.0 * (X(0, k + 1) - X(0, k)) * (2 * a * da + da * b + a * db + 2 * b * db);
  }
  const double qr = s.end_disc_flux(0, w.velocity), qf = s.end_disc_flux(1, w.velocity);
  std::printf("dV/dt = %.6e, Q_rear - Q_front = %.6e m^3/s (U = %.3e m/s)\n", dV, qr - qf, w.velocity);
  EXPECT_LT(std::abs(dV - (qr - qf)), 1e-10 * kPi * kA * kA * 1e-6);
  EXPECT_LT(s.lumen_divergence_residual(), 1e-10);
}

// The drag F_b of the towed tube (a = 0.125 um, L = 0.4 um in Rc = 0.25 um, period 2 um) on three
// nested meshes (rows 2m + 2m, 8m wall segments, 16m uniform gap columns, m = 2, 4, 8: h halves).
// The traction is singular at the tube's free rims (an open edge: t ~ d^-1/2 at distance d), which
// limits the force's convergence below the Q2 rate; measured: F_b = 1.11649e-8 / 1.11300e-8 /
// 1.11126e-8 N s/m, differences 3.1e-3 and 1.6e-3 of F_b, observed order 1.00 (first order, the
// rims' singularity), Richardson value 1.1095e-8 (0.16 % below the finest). Asserted: the order in
// [0.8, 1.5], and the extrapolated value within 1 % of the finest.
TEST(FittedPrescribed, TowedTubeDragConverges) {
  double F[3];
  for (int i = 0; i < 3; ++i) {
    const int m = 2 << i, n = 8 * m + 1;
    FittedStokes s(params(2 * m, 2 * m, 16 * m), kMu, n);
    F[i] = s.prescribed_wall_velocity(tube(n, 0.0, 0.0), Eigen::Matrix3Xd::Zero(3, n)).drag;
  }
  const double order = std::log2((F[1] - F[0]) / (F[2] - F[1]));
  const double extrap = F[2] + (F[2] - F[1]) / (std::pow(2.0, order) - 1.0);
  std::printf("F_b = %.6e / %.6e / %.6e N s/m: differences %.2e, %.2e relative, order %.2f, extrapolated %.6e\n",
              F[0], F[1], F[2], (F[1] - F[0]) / F[2], (F[2] - F[1]) / F[2], order, extrap);
  EXPECT_GT(order, 0.8);
  EXPECT_LT(order, 1.5);
  EXPECT_LT(std::abs(extrap - F[2]) / F[2], 0.01);
}

// A long towed tube against the lubrication (annular Couette) estimate. Far from its ends the
// flow of a tube of radius a towed at U in the cylinder Rc is axial: inside, a plug with the
// pressure gradient G = -dp/dx: u = U + G (a^2 - r^2)/(4 mu); outside, u = G (Rc^2 - r^2)/(4 mu)
// + B ln(r/Rc) with u(a) = U: B = (U - G (Rc^2 - a^2)/(4 mu)) / ln(a/Rc); across the gap (length
// P - L) Poiseuille flow u = G2 (Rc^2 - r^2)/(4 mu). The flux is the same in both sections,
//   Q = pi a^2 U + pi G a^4/(8 mu) + G pi (Rc^2 - a^2)^2/(8 mu) - pi B [(Rc^2 - a^2)/2 + a^2 ln(a/Rc)]
//     = pi G2 Rc^4/(8 mu),
// and the pressure is periodic: G L + G2 (P - L) = 0. The force on the fluid over a period is the
// wall's plus the container's, and the two cancel; the container's, int mu du/dr(Rc) dA, is
// 2 pi mu L B (the pressure-gradient parts of the two sections cancel by periodicity), so
//   F_b = -2 pi mu L B / U.
// The estimate leaves out the flow around the tube's two ends, a correction of O(Rc) in length:
// the relative deviation falls as 1/L. Measured (a = 0.125 um, Rc = 0.25 um, P = 2L, h = Rc/8):
// +1.00 % at L = 2 um and +0.51 % at 4 um (the computed drag higher: the ends add drag), deviation
// times L constant to 2 %. Asserted: below 1 % at L = 4 um, and the deviation times L constant
// within 20 % between the two lengths (an end effect, about 0.02 um of extra tube).
TEST(FittedPrescribed, LongTowedTubeMatchesAnnularCouette) {
  auto estimate = [](double L, double P) {
    const double a = kA, Rc = kRc, mu = kMu, U = 1.0, la = std::log(a / Rc);
    // B(G) = b0 + b1 G; Q_tube(G) = q0 + q1 G; Q_gap(G) = g1 G (G2 = -G L/(P - L))
    const double b0 = U / la, b1 = -(Rc * Rc - a * a) / (4 * mu) / la;
    const double ann = (Rc * Rc - a * a) / 2 + a * a * la;
    const double q0 = kPi * a * a * U - kPi * b0 * ann;
    const double q1 = kPi * std::pow(a, 4) / (8 * mu) + kPi * std::pow(Rc * Rc - a * a, 2) / (8 * mu) - kPi * b1 * ann;
    const double g1 = -kPi * std::pow(Rc, 4) / (8 * mu) * L / (P - L);
    const double G = q0 / (g1 - q1);
    return -2 * kPi * mu * L * (b0 + b1 * G) / U;
  };
  double dev[2];
  const double lengths[2] = {2e-6, 4e-6};
  for (int i = 0; i < 2; ++i) {
    const double L = lengths[i], P = 2 * L;
    const int ci = 4, seg = int(std::lround(L / (kRc / 8)));  // h = Rc/8, ring spacing h
    FittedStokes s(params(ci, ci, 40, P, 1.3), kMu, seg + 1);
    const double F = s.prescribed_wall_velocity(tube(seg + 1, 0.0, 0.0, L, 0.5 * (P - L)),
                                                Eigen::Matrix3Xd::Zero(3, seg + 1)).drag;
    const double E = estimate(L, P);
    dev[i] = (F - E) / E;
    std::printf("L = %.1f um: F_b = %.5e, annular Couette %.5e N s/m, deviation %+.2f %%\n", L * 1e6, F, E,
                100 * dev[i]);
  }
  EXPECT_LT(std::abs(dev[1]), 0.01);
  const double ratio = dev[1] * lengths[1] / (dev[0] * lengths[0]);
  EXPECT_NEAR(ratio, 1.0, 0.2);
}
