// The axisymmetric tier's Stokes solver (axi/stokes_axi.hpp) and ring transfer (axi/ib_axi.hpp):
//  * Poiseuille flow and a manufactured smooth flow converge at second order (velocity), the
//    manufactured pressure at >= 1.5;
//  * every solve is discretely divergence-free; the solution operator is self-adjoint in the
//    r-weighted inner product (reciprocity); an x-independent force gives u = 0 exactly;
//  * spreading conserves force, is adjoint to interpolation, reproduces constant and linear
//    fields on the staggered points; the axis guard; point sampling with axis/wall images;
//    disc fluxes against closed forms;
//  * a uniformly sheared thin cylinder (rings at r = a) moves at the closed-form annular
//    Couette velocity w_a = tau a ln(Rc/a) / mu, converging at (at least) first order.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "axi/grid_axi.hpp"
#include "axi/ib_axi.hpp"
#include "axi/stokes_axi.hpp"
#include "common/errors.hpp"
#include "tests/support/axi_fixture.hpp"

using swim::axi::AxiGrid;
using swim::axi::AxiStokes;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kMu = 1.0e-3;  // Pa s
constexpr double kRc = 1.0e-3;  // m

AxiGrid grid(int nr, int nx, double Rc = kRc) { return AxiGrid{nr, nx, Rc / nr}; }

double max_abs(const std::vector<double>& a) {
  double m = 0.0;
  for (double v : a) m = std::max(m, std::abs(v));
  return m;
}

double order(double coarse, double fine) { return std::log2(coarse / fine); }

// Discrete divergence at every cell, max |.|.
double max_divergence(const AxiGrid& g, const std::vector<double>& u, const std::vector<double>& w) {
  double m = 0.0;
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) {
      const int jp = (j + 1) % g.nx;
      const double d = (g.r_face(i + 1) * u[g.at(i + 1, j)] - g.r_face(i) * u[g.at(i, j)]) / (g.r_cell(i) * g.h) +
                       (w[g.at(i, jp)] - w[g.at(i, j)]) / g.h;
      m = std::max(m, std::abs(d));
    }
  return m;
}

// <f, v> = sum 2 pi r h^2 (fr u + fx w), r_face on the u points (rows 1..nr-1), r_cell on w.
double weighted_dot(const AxiGrid& g, const std::vector<double>& fr, const std::vector<double>& fx,
                    const std::vector<double>& u, const std::vector<double>& w) {
  double s = 0.0;
  for (int i = 1; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) s += 2 * kPi * g.r_face(i) * g.h * g.h * fr[g.at(i, j)] * u[g.at(i, j)];
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) s += 2 * kPi * g.r_cell(i) * g.h * g.h * fx[g.at(i, j)] * w[g.at(i, j)];
  return s;
}

void random_forces(const AxiGrid& g, std::mt19937& rng, std::vector<double>& fr, std::vector<double>& fx) {
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  fr.assign(g.u_size(), 0.0);
  fx.assign(g.w_size(), 0.0);
  for (int i = 1; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) fr[g.at(i, j)] = d(rng);
  for (auto& v : fx) v = d(rng);
}

// Poiseuille: f_x = G, w = G (Rc^2 - r^2) / (4 mu). Max error of w relative to max w, and max |u|.
struct PoiseuilleResult {
  double err_w, max_u, wmax;
  std::vector<double> w;
};
PoiseuilleResult poiseuille(const AxiGrid& g, double G) {
  AxiStokes s(g, kMu);
  std::vector<double> fr(g.u_size(), 0.0), fx(g.w_size(), G), u, w;
  s.solve(fr, fx, u, w);
  const double Rc = g.radius(), wmax = G * Rc * Rc / (4 * kMu);
  double e = 0.0;
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) {
      const double r = g.r_cell(i);
      e = std::max(e, std::abs(w[g.at(i, j)] - G * (Rc * Rc - r * r) / (4 * kMu)));
    }
  return {e / wmax, max_abs(u), wmax, w};
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Stokes solver

TEST(AxiStokes, PoiseuilleFlowConvergesAtSecondOrder) {
  double e[3];
  for (int l = 0; l < 3; ++l) {
    const auto res = poiseuille(grid(8 << l, 8), 2.0);
    e[l] = res.err_w;
    EXPECT_LE(res.max_u, 1e-14 * res.wmax);
  }
  std::printf("  Poiseuille rel. max error of w: %.3e %.3e %.3e, orders %.3f %.3f\n", e[0], e[1], e[2],
              order(e[0], e[1]), order(e[1], e[2]));
  EXPECT_GE(order(e[0], e[1]), 1.8);
  EXPECT_GE(order(e[1], e[2]), 1.8);
  EXPECT_LT(e[2], 1e-2);
}

namespace {

// The manufactured flow (tests/support/axi_fixture.hpp): u = u_r, w = u_x.
using Manufactured = swim::test::ManufacturedAxiFlow;

struct MmsErrors {
  double u, w, p;
};

MmsErrors manufactured_errors(int nr) {
  const double P = 2 * kRc;
  const AxiGrid g = grid(nr, 2 * nr);
  const Manufactured m(kRc, P, kMu);
  std::vector<double> fr(g.u_size(), 0.0), fx(g.w_size(), 0.0), u, w, p;
  for (int i = 1; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) fr[g.at(i, j)] = m.f_r(g.r_face(i), g.x_cell(j));
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) fx[g.at(i, j)] = m.f_x(g.r_cell(i), g.x_face(j));
  AxiStokes s(g, kMu);
  s.solve(fr, fx, u, w, &p);
  double eu = 0, ew = 0, ep = 0, umax = 0, wmax = 0, pmax = 0, pmean = 0;
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) pmean += m.p(g.r_cell(i), g.x_cell(j));
  pmean /= double(g.p_size());  // the solver's gauge: zero plain mean over the cells
  for (int i = 0; i <= g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) {
      const double ue = m.u_r(g.r_face(i), g.x_cell(j));
      eu = std::max(eu, std::abs(u[g.at(i, j)] - ue));
      umax = std::max(umax, std::abs(ue));
    }
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) {
      const double we = m.u_x(g.r_cell(i), g.x_face(j));
      ew = std::max(ew, std::abs(w[g.at(i, j)] - we));
      wmax = std::max(wmax, std::abs(we));
      const double pe = m.p(g.r_cell(i), g.x_cell(j)) - pmean;
      ep = std::max(ep, std::abs(p[g.at(i, j)] - pe));
      pmax = std::max(pmax, std::abs(pe));
    }
  return {eu / umax, ew / wmax, ep / pmax};
}

}  // namespace

TEST(AxiStokes, ManufacturedSmoothFlowConvergesAtSecondOrderAndPressureAtLeastThreeHalves) {
  MmsErrors e[3];
  for (int l = 0; l < 3; ++l) e[l] = manufactured_errors(32 << l);
  std::printf("  manufactured rel. max errors  u: %.3e %.3e %.3e (orders %.3f %.3f)\n", e[0].u, e[1].u, e[2].u,
              order(e[0].u, e[1].u), order(e[1].u, e[2].u));
  std::printf("                                w: %.3e %.3e %.3e (orders %.3f %.3f)\n", e[0].w, e[1].w, e[2].w,
              order(e[0].w, e[1].w), order(e[1].w, e[2].w));
  std::printf("                                p: %.3e %.3e %.3e (orders %.3f %.3f)\n", e[0].p, e[1].p, e[2].p,
              order(e[0].p, e[1].p), order(e[1].p, e[2].p));
  for (int l = 0; l < 2; ++l) {
    EXPECT_GE(order(e[l].u, e[l + 1].u), 1.8);
    EXPECT_GE(order(e[l].w, e[l + 1].w), 1.8);
    EXPECT_GE(order(e[l].p, e[l + 1].p), 1.5);
  }
  EXPECT_LT(e[2].u, 1e-2);
  EXPECT_LT(e[2].w, 1e-2);
}

TEST(AxiStokes, EverySolveIsDiscretelyDivergenceFreeToRoundOff) {
  std::mt19937 rng(11);
  for (auto [nr, nx] : {std::pair{2, 4}, std::pair{7, 10}, std::pair{24, 64}}) {
    const AxiGrid g = grid(nr, nx);
    AxiStokes s(g, kMu);
    std::vector<double> fr, fx, u, w;
    for (int rep = 0; rep < 2; ++rep) {
      random_forces(g, rng, fr, fx);
      s.solve(fr, fx, u, w);
      const double scale = max_abs(w) / g.h;
      ASSERT_GT(scale, 0.0);
      EXPECT_LE(max_divergence(g, u, w), 1e-13 * scale) << "nr = " << nr << ", nx = " << nx;
      for (int j = 0; j < g.nx; ++j) {
        EXPECT_EQ(u[g.at(0, j)], 0.0);
        EXPECT_EQ(u[g.at(g.nr, j)], 0.0);
      }
    }
  }
}

TEST(AxiStokes, SolutionOperatorIsSelfAdjointInTheRWeightedInnerProduct) {
  std::mt19937 rng(5);
  const AxiGrid g = grid(20, 48);
  AxiStokes s(g, kMu);
  std::vector<double> fr1, fx1, fr2, fx2, u1, w1, u2, w2;
  random_forces(g, rng, fr1, fx1);
  random_forces(g, rng, fr2, fx2);
  s.solve(fr1, fx1, u1, w1);
  s.solve(fr2, fx2, u2, w2);
  const double a = weighted_dot(g, fr1, fx1, u2, w2), b = weighted_dot(g, fr2, fx2, u1, w1);
  // Cauchy-Schwarz in the dissipation (energy) inner product bounds |a| by this scale.
  const double e1 = weighted_dot(g, fr1, fx1, u1, w1), e2 = weighted_dot(g, fr2, fx2, u2, w2);
  ASSERT_GT(e1, 0.0);  // positive: the dissipation of a non-zero flow
  ASSERT_GT(e2, 0.0);
  const double scale = std::sqrt(e1 * e2);
  std::printf("  reciprocity: <f1,u2> = %.6e, <f2,u1> = %.6e, rel. diff %.2e\n", a, b, std::abs(a - b) / scale);
  EXPECT_LE(std::abs(a - b), 1e-10 * scale);
  EXPECT_LE(std::abs(a), scale * (1 + 1e-12));
}

TEST(AxiStokes, AnAxiallyUniformForceGivesZeroRadialVelocityAndAHydrostaticRadialPressure) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  const AxiGrid g = grid(16, 32);
  std::vector<double> prof_r(g.nr + 1, 0.0), prof_x(g.nr);
  for (int i = 1; i < g.nr; ++i) prof_r[i] = d(rng);
  for (auto& v : prof_x) v = d(rng);
  std::vector<double> fr(g.u_size(), 0.0), fx(g.w_size()), u, w, p;
  for (int i = 0; i <= g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) fr[g.at(i, j)] = prof_r[i];
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) fx[g.at(i, j)] = prof_x[i];
  AxiStokes s(g, kMu);
  s.solve(fr, fx, u, w, &p);
  const double wmax = max_abs(w);
  ASSERT_GT(wmax, 0.0);
  EXPECT_LE(max_abs(u), 1e-14 * wmax);
  // w independent of x; radial balance -(p_i - p_{i-1})/h + f_r = 0 at every face
  double dw = 0.0, dp = 0.0;
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) dw = std::max(dw, std::abs(w[g.at(i, j)] - w[g.at(i, 0)]));
  for (int i = 1; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j)
      dp = std::max(dp, std::abs((p[g.at(i, j)] - p[g.at(i - 1, j)]) / g.h - fr[g.at(i, j)]));
  EXPECT_LE(dw, 1e-13 * wmax);
  EXPECT_LE(dp, 1e-12 * max_abs(fr));
  double pm = 0.0;
  for (double v : p) pm += v;
  EXPECT_LE(std::abs(pm / double(p.size())), 1e-13 * max_abs(p));  // the zero-mean gauge
}

TEST(AxiStokes, BadGridsAndViscositiesAreRejected) {
  EXPECT_THROW(AxiStokes(AxiGrid{1, 8, 1e-4}, kMu), std::invalid_argument);
  EXPECT_THROW(AxiStokes(AxiGrid{4, 2, 1e-4}, kMu), std::invalid_argument);
  EXPECT_THROW(AxiStokes(AxiGrid{4, 9, 1e-4}, kMu), std::invalid_argument);
  EXPECT_THROW(AxiStokes(AxiGrid{4, 8, 0.0}, kMu), std::invalid_argument);
  EXPECT_THROW(AxiStokes(AxiGrid{4, 8, 1e-4}, 0.0), std::invalid_argument);
  AxiStokes s(AxiGrid{4, 8, 1e-4}, kMu);
  std::vector<double> fr(3), fx(32), u, w;
  EXPECT_THROW(s.solve(fr, fx, u, w), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Immersed-boundary transfer

namespace {

Eigen::Matrix3Xd random_rings(const AxiGrid& g, std::mt19937& rng, int n, double rmin, double rmax) {
  std::uniform_real_distribution<double> ux(-1.5 * g.period(), 2.5 * g.period()), ur(rmin, rmax);
  Eigen::Matrix3Xd X(3, n);
  for (int k = 0; k < n; ++k) X.col(k) << ux(rng), ur(rng), 0.0;
  // a few rings on and next to the periodic seam
  if (n >= 4) {
    X(0, 0) = 0.0;
    X(0, 1) = g.period() - 0.3 * g.h;
    X(0, 2) = 0.2 * g.h;
    X(0, 3) = -0.7 * g.h;
  }
  return X;
}

}  // namespace

TEST(AxiIb, SpreadingConservesTheTotalForceOfRingsAwayFromTheWall) {
  std::mt19937 rng(1);
  const AxiGrid g = grid(24, 40);
  const Eigen::Matrix3Xd X = random_rings(g, rng, 50, 2.01 * g.h, g.radius() - 2.5 * g.h);
  Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Random(3, 50);
  F.row(2).setZero();
  std::vector<double> fr, fx;
  swim::axi::spread(g, X, F, fr, fx);
  ASSERT_EQ(fr.size(), g.u_size());
  ASSERT_EQ(fx.size(), g.w_size());
  double sr = 0.0, sx = 0.0;
  for (int i = 0; i <= g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) sr += 2 * kPi * g.r_face(i) * g.h * g.h * fr[g.at(i, j)];
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) sx += 2 * kPi * g.r_cell(i) * g.h * g.h * fx[g.at(i, j)];
  double tx = 0.0, tr = 0.0, scale = 0.0;
  for (int k = 0; k < 50; ++k) {
    tx += F(0, k);
    tr += F(1, k);
    scale += std::abs(F(0, k)) + std::abs(F(1, k));
  }
  EXPECT_NEAR(sx, tx, 1e-13 * scale);
  EXPECT_NEAR(sr, tr, 1e-13 * scale);
  for (int j = 0; j < g.nx; ++j) {
    EXPECT_EQ(fr[g.at(0, j)], 0.0);
    EXPECT_EQ(fr[g.at(g.nr, j)], 0.0);
  }
}

TEST(AxiIb, SpreadingIsAdjointToInterpolationInTheRWeightedInnerProduct) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  const AxiGrid g = grid(16, 24);
  // radii up to beyond the wall: the truncated stencils must stay adjoint
  const Eigen::Matrix3Xd X = random_rings(g, rng, 40, 2.001 * g.h, g.radius() + 1.0 * g.h);
  Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Random(3, 40);
  std::vector<double> u(g.u_size()), w(g.w_size()), fr, fx;
  for (auto& v : u) v = d(rng);
  for (auto& v : w) v = d(rng);
  swim::axi::spread(g, X, F, fr, fx);
  Eigen::Matrix3Xd U;
  swim::axi::interpolate(g, X, u.data(), w.data(), U);
  ASSERT_EQ(U.cols(), 40);
  const double lhs = weighted_dot(g, fr, fx, u, w);
  double rhs = 0.0, scale = 0.0;
  for (int k = 0; k < 40; ++k)
    for (int c = 0; c < 2; ++c) {
      rhs += F(c, k) * U(c, k);
      scale += std::abs(F(c, k) * U(c, k));
    }
  EXPECT_NEAR(lhs, rhs, 1e-12 * scale);
  for (int k = 0; k < 40; ++k) EXPECT_EQ(U(2, k), 0.0);
}

TEST(AxiIb, InterpolationReproducesConstantFieldsAwayFromTheWall) {
  std::mt19937 rng(4);
  const AxiGrid g = grid(20, 32);
  const Eigen::Matrix3Xd X = random_rings(g, rng, 30, 2.0001 * g.h, g.radius() - 2.001 * g.h);
  const double cw = 0.37, cu = -1.9;
  std::vector<double> u(g.u_size(), cu), w(g.w_size(), cw);
  Eigen::Matrix3Xd U;
  swim::axi::interpolate(g, X, u.data(), w.data(), U);
  for (int k = 0; k < 30; ++k) {
    EXPECT_NEAR(U(0, k), cw, 1e-13 * std::abs(cw));
    EXPECT_NEAR(U(1, k), cu, 1e-13 * std::abs(cu));
  }
}

// The kernel's first moments vanish, so a field linear in r and x is interpolated exactly: this
// pins each component's staggered positions (u at (r_face, x_cell), w at (r_cell, x_face)).
TEST(AxiIb, InterpolationReproducesLinearFieldsOnTheirStaggeredPointsAwayFromTheWallAndTheSeam) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> ux(0.0, 1.0);
  const AxiGrid g = grid(20, 32);
  auto fu = [&](double r, double x) { return 0.3 + 2.0 * r / g.radius() - 1.5 * x / g.period(); };
  auto fw = [&](double r, double x) { return -0.2 - 1.0 * r / g.radius() + 0.7 * x / g.period(); };
  std::vector<double> u(g.u_size()), w(g.w_size());
  for (int i = 0; i <= g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) u[g.at(i, j)] = fu(g.r_face(i), g.x_cell(j));
  for (int i = 0; i < g.nr; ++i)
    for (int j = 0; j < g.nx; ++j) w[g.at(i, j)] = fw(g.r_cell(i), g.x_face(j));
  Eigen::Matrix3Xd X(3, 30), U;
  for (int k = 0; k < 30; ++k)
    X.col(k) << 3 * g.h + ux(rng) * (g.period() - 6 * g.h), 2.0001 * g.h + ux(rng) * (g.radius() - 4.01 * g.h), 0.0;
  swim::axi::interpolate(g, X, u.data(), w.data(), U);
  for (int k = 0; k < 30; ++k) {
    EXPECT_NEAR(U(0, k), fw(X(1, k), X(0, k)), 1e-13);
    EXPECT_NEAR(U(1, k), fu(X(1, k), X(0, k)), 1e-13);
  }
}

TEST(AxiIb, ARingWithinTwoCellsOfTheAxisIsANumericalError) {
  const AxiGrid g = grid(16, 32);
  Eigen::Matrix3Xd X(3, 2), F = Eigen::Matrix3Xd::Ones(3, 2), U;
  X << 1e-4, 3e-4, 2.05 * g.h, 1.5 * g.h, 0, 0;
  std::vector<double> fr, fx, u(g.u_size(), 0.0), w(g.w_size(), 0.0);
  try {
    swim::axi::spread(g, X, F, fr, fx);
    FAIL() << "no exception";
  } catch (const swim::NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("within 2 cells of the axis"), std::string::npos) << e.what();
    EXPECT_NE(e.remedy().find("axi.grid.cells_across"), std::string::npos);
  }
  EXPECT_THROW(swim::axi::interpolate(g, X, u.data(), w.data(), U), swim::NumericalError);
  X(1, 1) = 2.05 * g.h;
  EXPECT_NO_THROW(swim::axi::spread(g, X, F, fr, fx));
  X(0, 1) = std::nan("");
  EXPECT_THROW(swim::axi::interpolate(g, X, u.data(), w.data(), U), swim::NumericalError);
}

TEST(AxiIb, PointSamplingWithAxisAndWallImagesIsSecondOrderAccurateUpToAxisAndWall) {
  // u = sin(pi r / Rc) cos(2 pi x / P) is odd about the axis and the wall, w = cos(pi r / (2 Rc))
  // sin(2 pi x / P) even about the axis and odd about the wall: the images are exact.
  double eu[3], ew[3];
  for (int l = 0; l < 3; ++l) {
    const AxiGrid g = grid(8 << l, 16 << l);
    const double P = g.period(), Rc = g.radius();
    std::vector<double> u(g.u_size()), w(g.w_size());
    for (int i = 0; i <= g.nr; ++i)
      for (int j = 0; j < g.nx; ++j)
        u[g.at(i, j)] = (i == 0 || i == g.nr) ? 0.0 : std::sin(kPi * g.r_face(i) / Rc) * std::cos(2 * kPi * g.x_cell(j) / P);
    for (int i = 0; i < g.nr; ++i)
      for (int j = 0; j < g.nx; ++j)
        w[g.at(i, j)] = std::cos(0.5 * kPi * g.r_cell(i) / Rc) * std::sin(2 * kPi * g.x_face(j) / P);
    eu[l] = ew[l] = 0.0;
    for (int a = 0; a <= 40; ++a)
      for (double x : {0.0, 0.123 * P, -0.61 * P, 0.999 * P}) {
        const double r = Rc * a / 40.0;
        eu[l] = std::max(eu[l], std::abs(swim::axi::sample_u(g, u.data(), x, r) -
                                         std::sin(kPi * r / Rc) * std::cos(2 * kPi * x / P)));
        ew[l] = std::max(ew[l], std::abs(swim::axi::sample_w(g, w.data(), x, r) -
                                         std::cos(0.5 * kPi * r / Rc) * std::sin(2 * kPi * x / P)));
      }
  }
  std::printf("  sampling max errors u: %.3e %.3e %.3e, w: %.3e %.3e %.3e\n", eu[0], eu[1], eu[2], ew[0], ew[1], ew[2]);
  for (int l = 0; l < 2; ++l) {
    EXPECT_GE(order(eu[l], eu[l + 1]), 1.8);
    EXPECT_GE(order(ew[l], ew[l + 1]), 1.8);
  }
  const AxiGrid g = grid(8, 16);
  std::vector<double> w(g.w_size(), 0.0);
  EXPECT_THROW(swim::axi::sample_w(g, w.data(), 0.0, -1e-9), std::invalid_argument);
  EXPECT_THROW(swim::axi::sample_w(g, w.data(), 0.0, 1.01 * g.radius()), std::invalid_argument);
}

// With the images, the sampled fields of ANY grid data have the parities of the continuum:
// w even about the axis (zero slope at r = 0), u odd (zero on the axis), both odd about the
// wall (zero at r = Rc).
TEST(AxiIb, SampledFieldsOfRandomDataAreEvenOrOddAcrossTheAxisAndVanishOnTheWall) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  const AxiGrid g = grid(10, 16);
  std::vector<double> u(g.u_size()), w(g.w_size());
  for (auto& v : u) v = d(rng);
  for (auto& v : w) v = d(rng);
  const double eps = 1e-4 * g.h;
  for (double x : {0.0, 0.31 * g.period(), 0.77 * g.period()}) {
    const double w0 = swim::axi::sample_w(g, w.data(), x, 0.0);
    EXPECT_LE(std::abs(swim::axi::sample_w(g, w.data(), x, eps) - w0), 1e-6) << "x = " << x;
    EXPECT_NEAR(swim::axi::sample_u(g, u.data(), x, 0.0), 0.0, 1e-15);
    EXPECT_NEAR(swim::axi::sample_u(g, u.data(), x, g.radius()), 0.0, 1e-15);
    EXPECT_NEAR(swim::axi::sample_w(g, w.data(), x, g.radius()), 0.0, 1e-15);
    // u near the axis: odd, so u(eps) = O(eps) while a random u has O(1) values
    EXPECT_LE(std::abs(swim::axi::sample_u(g, u.data(), x, eps)), 1e-3);
  }
}

TEST(AxiIb, DiscFluxOfAConstantFieldIsExactAndOfPoiseuilleFlowConvergesAtSecondOrder) {
  {
    const AxiGrid g = grid(12, 16);
    const double c = 0.25, V = 0.1;
    std::vector<double> w(g.w_size(), c);
    for (double a : {0.7 * g.h, 3.3 * g.h, g.radius() - 2 * g.h}) {
      const double q = swim::axi::disc_flux(g, w.data(), 0.37 * g.period(), a, V, 17);
      EXPECT_NEAR(q, (c - V) * kPi * a * a, 1e-12 * c * kPi * a * a) << "a = " << a;
    }
    EXPECT_EQ(swim::axi::disc_flux(g, w.data(), 0.0, 0.0, V, 3), 0.0);
    EXPECT_THROW(swim::axi::disc_flux(g, w.data(), 0.0, 1.1 * g.radius(), 0.0, 4), std::invalid_argument);
    EXPECT_THROW(swim::axi::disc_flux(g, w.data(), 0.0, g.radius(), 0.0, 0), std::invalid_argument);
  }
  // Poiseuille: Q(a) = pi G / (2 mu) (Rc^2 a^2 / 2 - a^4 / 4); the full radius through the wall
  // image, and a = Rc/2 inside.
  const double G = 2.0;
  double ef[3], eh[3];
  for (int l = 0; l < 3; ++l) {
    const AxiGrid g = grid(8 << l, 8);
    const auto res = poiseuille(g, G);
    const double Rc = g.radius();
    auto exact = [&](double a) { return kPi * G / (2 * kMu) * (Rc * Rc * a * a / 2 - a * a * a * a / 4); };
    ef[l] = std::abs(swim::axi::disc_flux(g, res.w.data(), 0.3 * g.h, Rc, 0.0, 4 * g.nr) - exact(Rc)) / exact(Rc);
    eh[l] = std::abs(swim::axi::disc_flux(g, res.w.data(), 0.3 * g.h, Rc / 2, 0.0, 4 * g.nr) - exact(Rc / 2)) /
            exact(Rc / 2);
  }
  std::printf("  Poiseuille disc flux rel. errors, a = Rc: %.3e %.3e %.3e; a = Rc/2: %.3e %.3e %.3e\n", ef[0], ef[1],
              ef[2], eh[0], eh[1], eh[2]);
  for (int l = 0; l < 2; ++l) {
    EXPECT_GE(order(ef[l], ef[l + 1]), 1.8);
    EXPECT_GE(order(eh[l], eh[l + 1]), 1.8);
  }
  EXPECT_LT(ef[2], 1e-2);
  EXPECT_LT(eh[2], 1e-2);
}

// A thin tube: rings of radius a spaced s = h/2 over the whole period, each pushed axially with
// F_x = tau 2 pi a s (a uniform axial traction tau on the cylinder r = a). With no mean pressure
// gradient in the periodic container, the continuum flow is w = w_a for r < a (no force inside,
// regular on the axis: plug), w = w_a ln(Rc/r) / ln(Rc/a) for a < r < Rc (annular Couette), and
// the traction jump mu (w'(a+) - w'(a-)) = -tau gives w_a = tau a ln(Rc/a) / mu (the wall shear
// 2 pi Rc mu w_a / (Rc ln(Rc/a)) balances the force 2 pi a tau per length).
TEST(AxiIb, AUniformlyShearedThinTubeMovesAtTheAnnularCouetteVelocityAtFirstOrder) {
  const double tau = 0.5, a = kRc / 2, wa = tau * a * std::log(kRc / a) / kMu;
  double e[3];
  for (int l = 0; l < 3; ++l) {
    const AxiGrid g = grid(16 << l, 8);
    const int n = 2 * g.nx;
    const double s = g.period() / n;
    Eigen::Matrix3Xd X(3, n), F(3, n), U;
    for (int k = 0; k < n; ++k) {
      X.col(k) << (k + 0.3) * s, a, 0.0;
      F.col(k) << tau * 2 * kPi * a * s, 0.0, 0.0;
    }
    std::vector<double> fr, fx, u, w;
    swim::axi::spread(g, X, F, fr, fx);
    AxiStokes st(g, kMu);
    st.solve(fr, fx, u, w);
    swim::axi::interpolate(g, X, u.data(), w.data(), U);
    double mean = 0.0;
    for (int k = 0; k < n; ++k) mean += U(0, k) / n;
    e[l] = std::abs(mean - wa) / wa;
    for (int k = 0; k < n; ++k) {
      EXPECT_LE(std::abs(U(1, k)), 1e-12 * wa);
      EXPECT_LE(std::abs(U(0, k) - mean), 1e-12 * wa);
    }
  }
  std::printf("  thin tube: w_a = %.6e m/s, rel. errors %.3e %.3e %.3e, ratios %.3f %.3f\n", wa, e[0], e[1], e[2],
              e[0] / e[1], e[1] / e[2]);
  EXPECT_GE(e[0] / e[1], 1.6);
  EXPECT_GE(e[1] / e[2], 1.6);
  EXPECT_LT(e[2], 0.05);
}
