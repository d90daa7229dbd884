// Spreading (eq. 19) and interpolation (eq. 20) on the MAC grid.
#include <gtest/gtest.h>

#include <random>

#include "full3d/ib.hpp"
#include "full3d/operators.hpp"
#include "tests/full3d/test_support.hpp"

using namespace swim::full3d;
using namespace swim::full3d::testing;

namespace {
Eigen::Matrix3Xd random_points(const MacGrid& g, int n, double margin, std::mt19937& rng) {
  Eigen::Matrix3Xd X(3, n);
  for (int d = 0; d < 3; ++d) {
    std::uniform_real_distribution<double> U(margin, g.length(d) - margin);
    for (int k = 0; k < n; ++k) X(d, k) = U(rng);
  }
  return X;
}
Eigen::Vector3d field_total(const MacGrid& g, const VectorField& f) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (int c = 0; c < 3; ++c)
    for (double x : f.c[c]) s[c] += x;
  return s * g.h() * g.h() * g.h();
}
}  // namespace

TEST(ImmersedBoundary, SpreadConservesTotalForcePeriodicBox) {
  std::mt19937 rng(1);
  MacGrid g(12, 10, 9, 0.1, GridBoundary::PeriodicBox);
  // points anywhere, including outside [0, L) (periodic images)
  Eigen::Matrix3Xd X = random_points(g, 50, -0.3, rng);
  const Eigen::Matrix3Xd F = random_forces(50, rng);
  VectorField f(g);
  spread(g, X, F, f);
  const Eigen::Vector3d tot = field_total(g, f), ref = F.rowwise().sum();
  EXPECT_LT((tot - ref).norm(), 1e-13 * F.cwiseAbs().sum());
}

TEST(ImmersedBoundary, SpreadConservesTotalForceAwayFromDuctWalls) {
  std::mt19937 rng(2);
  MacGrid g(12, 10, 9, 0.1, GridBoundary::SquareDuct);
  const Eigen::Matrix3Xd X = random_points(g, 50, 2.01 * g.h(), rng);
  const Eigen::Matrix3Xd F = random_forces(50, rng);
  VectorField f(g);
  spread(g, X, F, f);
  EXPECT_LT((field_total(g, f) - F.rowwise().sum()).norm(), 1e-13 * F.cwiseAbs().sum());
}

TEST(ImmersedBoundary, SpreadAndInterpolateAreAdjoint) {
  std::mt19937 rng(3);
  for (auto kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
    MacGrid g(10, 8, 12, 0.05, kind);
    const Eigen::Matrix3Xd X = random_points(g, 40, 0.0, rng);  // includes nodes near walls
    const Eigen::Matrix3Xd F = random_forces(40, rng);
    VectorField u(g), f(g);
    std::uniform_real_distribution<double> U(-1, 1);
    for (auto& a : u.c)
      for (double& x : a) x = U(rng);
    zero_wall_faces(g, u);
    spread(g, X, F, f);
    Eigen::Matrix3Xd Ui;
    interpolate(g, u, X, Ui);
    double lhs = 0;
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < u.c[c].size(); ++m) lhs += f.c[c][m] * u.c[c][m];
    lhs *= g.h() * g.h() * g.h();
    const double rhs = (F.array() * Ui.array()).sum();
    EXPECT_NEAR(lhs, rhs, 1e-12 * std::abs(rhs)) << to_string(kind);
  }
}

// A spread given the support of the field's last spread zeroes only that part, and gives the
// field a fresh spread gives, bit for bit: clusters of nodes that move (across the periodic x
// seam, next to a duct wall, across a periodic y/z seam), on one and two threads.
TEST(ImmersedBoundary, SpreadWithTheLastSupportEqualsAFreshSpread) {
  std::mt19937 rng(5);
  for (auto kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
    const MacGrid g(24, 14, 16, 0.05, kind);
    // a cluster of nodes about a centre (a tube's few per cent of the grid)
    auto cluster = [&](const Eigen::Vector3d& c) {
      std::uniform_real_distribution<double> U(-0.12, 0.12);
      Eigen::Matrix3Xd X(3, 30);
      for (int k = 0; k < 30; ++k) X.col(k) = c + Eigen::Vector3d(U(rng), U(rng), U(rng));
      return X;
    };
    const double lo = 2.2 * g.h() + 0.12;  // keeps the duct's clusters off the walls' stencils
    const std::vector<Eigen::Vector3d> centres = {
        {0.6, 0.35, 0.4},                          // inside
        {0.02, 0.35, 0.4},                         // across the periodic x seam
        {1.18, 0.35, 0.4},                         // across it from the other side
        {0.6, lo, g.length(2) - lo},               // next to walls (duct), near the y/z seams (box)
        {0.6, 0.01, 0.79},                         // across the y and z seams (box only)
        {0.3, 0.5, 0.2}};
    for (int threads : {1, 2}) {
      VectorField kept(g);
      SpreadSupport support;
      int spreads = 0;
      for (const Eigen::Vector3d& c : centres) {
        if (kind == GridBoundary::SquareDuct && (c[1] < lo || c[2] > g.length(2) - lo)) continue;
        const Eigen::Matrix3Xd X = cluster(c);
        const Eigen::Matrix3Xd F = random_forces(30, rng);
        spread(g, X, F, kept, threads, &support);
        ++spreads;
        VectorField fresh(g);
        spread(g, X, F, fresh, threads);
        for (int comp = 0; comp < 3; ++comp)
          ASSERT_EQ(kept.c[comp], fresh.c[comp]) << to_string(kind) << ", centre " << c.transpose() << ", component "
                                                 << comp << ", " << threads << " threads";
        EXPECT_TRUE(support.valid);
      }
      EXPECT_GE(spreads, 5);
      // the support of a cluster away from every seam is a small part of the grid
      support = SpreadSupport{};
      spread(g, cluster(centres[0]), random_forces(30, rng), kept, threads, &support);
      EXPECT_FALSE(support.whole[0] || support.whole[1] || support.whole[2]) << to_string(kind);
      EXPECT_LT(support.hi[0] - support.lo[0] + 1, g.nx());
    }
  }
}

TEST(ImmersedBoundary, InterpolationReproducesConstantsAndLinearFields) {
  std::mt19937 rng(4);
  for (auto kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
    MacGrid g(16, 14, 12, 0.1, kind);
    const double a[3] = {0.3, -1.2, 2.0};
    const double b[3][3] = {{1.0, -2.0, 0.5}, {0.7, 0.1, -0.4}, {-1.5, 0.9, 2.2}};
    VectorField cst(g), lin(g);
    for_each_face(g, [&](const Face& q) {
      cst.c[q.c][q.id] = a[q.c];
      lin.c[q.c][q.id] = a[q.c] + b[q.c][0] * q.x[0] + b[q.c][1] * q.x[1] + b[q.c][2] * q.x[2];
    });
    // the linear field is not periodic: keep the stencils off the seams and walls
    const Eigen::Matrix3Xd X = random_points(g, 30, 2.01 * g.h(), rng);
    Eigen::Matrix3Xd Uc, Ul;
    interpolate(g, cst, X, Uc);
    interpolate(g, lin, X, Ul);
    for (int k = 0; k < X.cols(); ++k)
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(Uc(c, k), a[c], 1e-14);
        EXPECT_NEAR(Ul(c, k), a[c] + b[c][0] * X(0, k) + b[c][1] * X(1, k) + b[c][2] * X(2, k), 1e-13);
      }
    if (kind == GridBoundary::PeriodicBox) {  // constants everywhere, across the seams
      const Eigen::Matrix3Xd Y = random_points(g, 30, -0.5, rng);
      interpolate(g, cst, Y, Uc);
      for (int k = 0; k < Y.cols(); ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(Uc(c, k), a[c], 1e-14);
    }
  }
}
