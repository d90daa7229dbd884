// The round wall's continuum network law (axi/wall_axi.hpp): exact gradients, the reference
// state, invariances, the linearised moduli, the uniform-load equilibrium and the bending
// quadrature's order.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "axi/wall_axi.hpp"

namespace {

using swim::axi::AxiWall;
using swim::axi::AxiWallParams;

constexpr double kR0 = 0.125e-6, kKs = 5.5e-8, kD = 1.2e-24;

Eigen::Matrix3Xd perturbed(const AxiWall& w, double amp, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3Xd X = w.reference();
  for (int k = 0; k < w.nodes(); ++k) {
    X(0, k) += amp * w.ds0() * u(gen);
    X(1, k) += amp * kR0 * u(gen);
  }
  return X;
}

double total(const AxiWall& w, const Eigen::Matrix3Xd& X) {
  const auto e = w.energies(X);
  return e[0] + e[1];
}

}  // namespace

TEST(AxiWall, ForcesAreTheExactNegativeGradientOfTheEnergy) {
  for (double D : {kD, 0.0}) {
    const AxiWall w(AxiWallParams{kR0, 0.4e-6, kKs, D, 20});
    const Eigen::Matrix3Xd X = perturbed(w, 0.05, 7);
    const Eigen::Matrix3Xd F = w.forces(X);
    double worst = 0, scale = F.cwiseAbs().maxCoeff();
    for (int k = 0; k < w.nodes(); ++k)
      for (int c = 0; c < 2; ++c) {
        const double eps = 1e-6 * (c == 0 ? w.ds0() : kR0);
        Eigen::Matrix3Xd Xp = X, Xm = X;
        Xp(c, k) += eps;
        Xm(c, k) -= eps;
        const double fd = -(total(w, Xp) - total(w, Xm)) / (2 * eps);
        worst = std::max(worst, std::abs(fd - F(c, k)));
      }
    EXPECT_LT(worst, 1e-6 * scale) << "D = " << D;
  }
}

TEST(AxiWall, TheReferenceCylinderIsStressFreeAndTranslationChangesNothing) {
  const AxiWall w(AxiWallParams{kR0, 0.4e-6, kKs, kD, 41});
  std::array<double, 2> e{};
  const Eigen::Matrix3Xd F0 = w.forces(w.reference(), &e);
  // round-off of the stretch sqrt(1/4 + 3/4) against the scales k_s R0 L and k_s R0
  EXPECT_LT(e[0] + e[1], 1e-25 * kKs * kR0 * 0.4e-6);
  EXPECT_LT(F0.cwiseAbs().maxCoeff(), 1e-12 * kKs * 2 * M_PI * kR0);
  const Eigen::Matrix3Xd X = perturbed(w, 0.05, 3);
  Eigen::Matrix3Xd Y = X;
  Y.row(0).array() += 0.37e-6;
  const Eigen::Matrix3Xd FX = w.forces(X), FY = w.forces(Y);
  EXPECT_LT((FX - FY).cwiseAbs().maxCoeff(), 1e-9 * FX.cwiseAbs().maxCoeff());
  EXPECT_LT(std::abs(FX.row(0).sum()), 1e-12 * FX.cwiseAbs().maxCoeff());  // no net axial force
}

TEST(AxiWall, MirroringTheShapeMirrorsTheForces) {
  const AxiWall w(AxiWallParams{kR0, 0.4e-6, kKs, kD, 25});
  const Eigen::Matrix3Xd X = perturbed(w, 0.05, 11);
  const int n = w.nodes();
  Eigen::Matrix3Xd M(3, n);
  for (int k = 0; k < n; ++k) M.col(k) << 0.4e-6 - X(0, n - 1 - k), X(1, n - 1 - k), 0.0;
  const Eigen::Matrix3Xd F = w.forces(X), G = w.forces(M);
  double worst = 0;
  for (int k = 0; k < n; ++k)
    worst = std::max({worst, std::abs(G(0, k) + F(0, n - 1 - k)), std::abs(G(1, k) - F(1, n - 1 - k))});
  EXPECT_LT(worst, 1e-10 * F.cwiseAbs().maxCoeff());
}

TEST(AxiWall, LinearisedStretchingIsIsotropicWithTheNetworksModuli) {
  // W ~ Y / (2 (1 - nu^2)) (e_s^2 + e_t^2 + 2 nu e_s e_t) for small strains
  const double e = 1e-5;
  auto W = [&](double es, double et) { return swim::axi::stretching_density(kKs, 1 + es, 1 + et); };
  const double Wss = (W(e, 0) - 2 * W(0, 0) + W(-e, 0)) / (e * e);
  const double Wtt = (W(0, e) - 2 * W(0, 0) + W(0, -e)) / (e * e);
  const double Wst = (W(e, e) - W(e, -e) - W(-e, e) + W(-e, -e)) / (4 * e * e);
  const double Y = swim::axi::young_modulus_2d(kKs), nu = swim::axi::kWallPoisson;
  EXPECT_NEAR(Wss, Y / (1 - nu * nu), 1e-5 * Wss);
  EXPECT_NEAR(Wtt, Y / (1 - nu * nu), 1e-5 * Wss);
  EXPECT_NEAR(Wst, nu * Y / (1 - nu * nu), 1e-5 * Wss);
  EXPECT_NEAR(Y, 2 * kKs / std::sqrt(3.0), 1e-18);
}

TEST(AxiWall, UniformLoadGivesTheClosedFormFreeEndedEquilibriumAtSmallAndLargeLoads) {
  // Free ends: no axial tension, dW/dlambda_t = -P R0, which for this law gives
  // lambda_t = 1 - P R0 / Y exactly: C1 = Y / R0^2 at every load.
  const AxiWall w(AxiWallParams{kR0, 8 * kR0, kKs, kD, 161});
  const double Y = swim::axi::young_modulus_2d(kKs), C1 = Y / (kR0 * kR0);
  for (double lambda : {0.99, 0.55}) {
    const double P = C1 * kR0 * (1 - lambda);
    const auto r = swim::axi::relax_under_pressure(w, P);
    EXPECT_NEAR(r.mid_radius, lambda * kR0, 1e-6 * kR0) << "lambda " << lambda;
    EXPECT_NEAR(r.c1, C1, 1e-4 * C1);
  }
}

TEST(AxiWall, UniformContractionCostsNoBendingAndAnUndulationConvergesAtSecondOrder) {
  {
    const AxiWall w(AxiWallParams{kR0, 0.4e-6, kKs, kD, 33});
    Eigen::Matrix3Xd X = w.reference();
    X.row(1).array() *= 0.6;
    EXPECT_LT(w.energies(X)[1], 1e-40);
  }
  // r = R0 (1 + eps cos(2 pi s0 / lam)), x = s0: continuum bending energy by fine quadrature
  const double L = 0.4e-6, lam = 0.1e-6, eps = 0.01;
  auto bending = [&](int n) {
    const AxiWall w(AxiWallParams{kR0, L, kKs, kD, n});
    Eigen::Matrix3Xd X = w.reference();
    for (int k = 0; k < n; ++k) X(1, k) = kR0 * (1 + eps * std::cos(2 * M_PI * X(0, k) / lam));
    return w.energies(X)[1];
  };
  const double e1 = bending(41), e2 = bending(81), e3 = bending(161), e4 = bending(321);
  const double order = std::log(std::abs(e1 - e2) / std::abs(e2 - e3)) / std::log(2.0);
  const double order2 = std::log(std::abs(e2 - e3) / std::abs(e3 - e4)) / std::log(2.0);
  EXPECT_GT(order, 1.8);
  EXPECT_GT(order2, 1.8);
  EXPECT_GT(e4, 0.0);
}
