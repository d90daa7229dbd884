// Threaded spreading (eq. 19), interpolation (eq. 20) and membrane forces (eqs. 7-9):
// results with threads = 2, 3 must equal threads = 1 (to 1e-14 relative), keep the
// adjointness and the force balance of the serial operators.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "full3d/ib.hpp"
#include "full3d/kernel.hpp"
#include "full3d/membrane.hpp"
#include "full3d/operators.hpp"
#include "tests/full3d/test_support.hpp"

using namespace swim::full3d;
using namespace swim::full3d::testing;

namespace {

// Random cloud: x anywhere in [-L/2, 3L/2) (straddles the periodic seam and its images);
// y, z over the whole cross-section, including the 2h layers at the duct walls (and, in the
// periodic box, across its seams too).
Eigen::Matrix3Xd random_cloud(const MacGrid& g, int n, std::mt19937& rng) {
  Eigen::Matrix3Xd X(3, n);
  std::uniform_real_distribution<double> Ux(-0.5 * g.length(0), 1.5 * g.length(0));
  for (int k = 0; k < n; ++k) X(0, k) = Ux(rng);
  for (int d = 1; d < 3; ++d) {
    const double lo = g.periodic(d) ? -0.3 * g.length(d) : 0.0;
    const double hi = g.periodic(d) ? 1.3 * g.length(d) : g.length(d);
    std::uniform_real_distribution<double> U(lo, hi);
    for (int k = 0; k < n; ++k) X(d, k) = U(rng);
  }
  // a few nodes exactly on grid lines, on the seam and on the walls
  if (n >= 4) {
    X.col(0) << 0.0, 0.0, 0.0;
    X.col(1) << g.length(0), 2.0 * g.h(), g.length(2);
    X.col(2) << 3.0 * g.h(), 0.5 * g.h(), g.h();
    X.col(3) << g.length(0) - 0.25 * g.h(), g.length(1) - 1.5 * g.h(), 0.5 * g.length(2);
  }
  return X;
}


double max_abs(const VectorField& f) {
  double m = 0.0;
  for (const auto& a : f.c)
    for (double x : a) m = std::max(m, std::abs(x));
  return m;
}

double max_diff(const VectorField& a, const VectorField& b) {
  double m = 0.0;
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(a.c[c].size(), b.c[c].size());
    for (std::size_t i = 0; i < a.c[c].size(); ++i) m = std::max(m, std::abs(a.c[c][i] - b.c[c][i]));
  }
  return m;
}

}  // namespace

TEST(ImmersedBoundaryParallel, KernelWeightsMatchEquation18) {
  for (int i = 0; i <= 1000; ++i) {
    const double t = i < 1000 ? i / 1000.0 : std::nextafter(1.0, 0.0);
    double w[4];
    peskin_4pt_weights(t, w);
    EXPECT_NEAR(w[0], peskin_4pt(1.0 + t), 1e-15) << t;
    EXPECT_NEAR(w[1], peskin_4pt(t), 1e-15) << t;
    EXPECT_NEAR(w[2], peskin_4pt(1.0 - t), 1e-15) << t;
    EXPECT_NEAR(w[3], peskin_4pt(2.0 - t), 1e-15) << t;
    EXPECT_NEAR(w[0] + w[1] + w[2] + w[3], 1.0, 1e-15);
    EXPECT_NEAR(w[0] + w[2], 0.5, 1e-15);
  }
}

TEST(ImmersedBoundaryParallel, SpreadAndInterpolateIndependentOfThreads) {
  std::mt19937 rng(11);
  for (auto kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
    MacGrid g(24, 10, 9, 0.05, kind);
    const Eigen::Matrix3Xd X = random_cloud(g, 400, rng);
    const Eigen::Matrix3Xd F = random_forces(400, rng);
    VectorField u(g);
    std::uniform_real_distribution<double> U(-1, 1);
    for (auto& a : u.c)
      for (double& x : a) x = U(rng);
    zero_wall_faces(g, u);

    VectorField f1(g);
    spread(g, X, F, f1, 1);
    Eigen::Matrix3Xd U1;
    interpolate(g, u, X, U1, 1);
    const double fs = max_abs(f1), us = U1.cwiseAbs().maxCoeff();
    ASSERT_GT(fs, 0.0);
    for (int thr : {2, 3, 5}) {
      VectorField f(g);
      f.fill(7.0);  // spread overwrites
      spread(g, X, F, f, thr);
      EXPECT_LE(max_diff(f, f1), 1e-14 * fs) << to_string(kind) << " threads " << thr;
      Eigen::Matrix3Xd Ut;
      interpolate(g, u, X, Ut, thr);
      EXPECT_LE((Ut - U1).cwiseAbs().maxCoeff(), 1e-14 * us) << to_string(kind) << " threads " << thr;
      // spread_add accumulates on top of the existing field
      VectorField f2 = f1;
      spread_add(g, X, F, f2, thr);
      f.axpy(1.0, f1);
      EXPECT_LE(max_diff(f2, f), 1e-14 * fs) << to_string(kind) << " threads " << thr;
    }
  }
}

TEST(ImmersedBoundaryParallel, ClusteredNodesAndMoreThreadsThanPlanes) {
  std::mt19937 rng(12);
  // all nodes within one x cell next to the seam and one z cell next to a wall (duct) or
  // the seam (box): most threads own no node
  for (auto kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
  MacGrid g(16, 8, 12, 0.1, kind);
  Eigen::Matrix3Xd X = random_cloud(g, 60, rng);
  for (int k = 0; k < X.cols(); ++k) {
    X(0, k) = g.length(0) - 0.9 * g.h() * (k % 7) / 7.0;
    X(2, k) = g.length(2) - 0.9 * g.h() * (k % 5) / 5.0;
  }
  const Eigen::Matrix3Xd F = random_forces(60, rng);
  VectorField f1(g);
  spread(g, X, F, f1, 1);
  for (int thr : {2, 4, 7}) {
    VectorField f(g);
    spread(g, X, F, f, thr);
    EXPECT_LE(max_diff(f, f1), 1e-14 * max_abs(f1)) << to_string(kind) << " threads " << thr;
  }
  }
  // n < stencil width, more threads than z planes, fewer nodes than threads
  MacGrid s(3, 4, 3, 0.2, GridBoundary::PeriodicBox);
  const Eigen::Matrix3Xd Y = random_cloud(s, 2, rng), G = random_forces(2, rng);
  VectorField s1(s);
  spread(s, Y, G, s1, 1);
  for (int thr : {2, 3, 4}) {
    VectorField st(s);
    spread(s, Y, G, st, thr);
    EXPECT_LE(max_diff(st, s1), 1e-14 * max_abs(s1)) << thr;
  }
}

TEST(ImmersedBoundaryParallel, AdjointAndConservativeWithThreads) {
  std::mt19937 rng(13);
  for (auto kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
    MacGrid g(20, 8, 12, 0.05, kind);
    const Eigen::Matrix3Xd X = random_cloud(g, 300, rng);
    const Eigen::Matrix3Xd F = random_forces(300, rng);
    VectorField u(g);
    std::uniform_real_distribution<double> U(-1, 1);
    for (auto& a : u.c)
      for (double& x : a) x = U(rng);
    zero_wall_faces(g, u);
    for (int thr : {2, 3}) {
      VectorField f(g);
      spread(g, X, F, f, thr);
      Eigen::Matrix3Xd Ui;
      interpolate(g, u, X, Ui, thr);
      double lhs = 0;
      for (int c = 0; c < 3; ++c)
        for (std::size_t m = 0; m < u.c[c].size(); ++m) lhs += f.c[c][m] * u.c[c][m];
      lhs *= g.h() * g.h() * g.h();
      const double rhs = (F.array() * Ui.array()).sum();
      EXPECT_NEAR(lhs, rhs, 1e-12 * std::abs(rhs)) << to_string(kind) << " threads " << thr;
      if (kind == GridBoundary::PeriodicBox) {  // no wall truncation: total force is conserved
        Eigen::Vector3d tot = Eigen::Vector3d::Zero();
        for (int c = 0; c < 3; ++c)
          for (double x : f.c[c]) tot[c] += x;
        tot *= g.h() * g.h() * g.h();
        EXPECT_LT((tot - F.rowwise().sum()).norm(), 1e-13 * F.cwiseAbs().sum()) << "threads " << thr;
      }
    }
  }
  // duct, nodes kept 2h from the walls: total force conserved too
  MacGrid g(20, 10, 10, 0.05, GridBoundary::SquareDuct);
  Eigen::Matrix3Xd X = random_cloud(g, 200, rng);
  for (int k = 0; k < X.cols(); ++k)
    for (int d = 1; d < 3; ++d) X(d, k) = 2.01 * g.h() + std::fmod(std::abs(X(d, k)), g.length(d) - 4.02 * g.h());
  const Eigen::Matrix3Xd F = random_forces(200, rng);
  VectorField f(g);
  spread(g, X, F, f, 2);
  Eigen::Vector3d tot = Eigen::Vector3d::Zero();
  for (int c = 0; c < 3; ++c)
    for (double x : f.c[c]) tot[c] += x;
  tot *= g.h() * g.h() * g.h();
  EXPECT_LT((tot - F.rowwise().sum()).norm(), 1e-13 * F.cwiseAbs().sum());
}

TEST(MembraneForcesParallel, IndependentOfThreads) {
  const CylinderMesh m = make_cylinder(1.0, 3.0, 24, Eigen::Vector3d::Zero());
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> U(-0.03, 0.03);
  Eigen::Matrix3Xd X = m.X0;
  for (int k = 0; k < X.cols(); ++k)
    for (int d = 0; d < 3; ++d) X(d, k) += U(rng);
  for (auto form : {BendingForm::ReferenceAngle, BendingForm::Printed}) {
    MembraneParams p;
    p.ks = 2.0;
    p.kb = 0.3;
    p.bending = form;
    const Eigen::Matrix3Xd F1 = elastic_forces(m, X, p, 1);
    // threads = 1 is the sum of the public serial pieces
    Eigen::Matrix3Xd Fs = Eigen::Matrix3Xd::Zero(3, X.cols());
    add_stretching_forces(m, X, p.ks, Fs);
    add_bending_forces(m, X, p.kb, form, Fs);
    EXPECT_EQ((F1 - Fs).cwiseAbs().maxCoeff(), 0.0);
    const double scale = F1.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0.0);
    for (int thr : {2, 3, 4}) {
      const Eigen::Matrix3Xd Ft = elastic_forces(m, X, p, thr);
      EXPECT_LE((Ft - F1).cwiseAbs().maxCoeff(), 1e-14 * scale) << "threads " << thr;
      // internal forces: total force vanishes
      EXPECT_LT(Ft.rowwise().sum().norm(), 1e-13 * Ft.cwiseAbs().sum()) << "threads " << thr;
    }
  }
}
