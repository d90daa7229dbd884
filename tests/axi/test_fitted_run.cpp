// The axisymmetric tier's fitted (sharp-interface) method end to end: the implicitly coupled
// wall at rest under a uniform load, and a round-wall cycle of the paper's amplitude scene
// (completion, forward swimming, the lumen's volume balance, located protocol events).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>

#include "axi/fe_stokes_axi.hpp"
#include "axi/run_axi.hpp"
#include "axi/scene_axi.hpp"
#include "axi/wall_axi.hpp"
#include "axi_test_support.hpp"
#include "common/scene.hpp"

namespace {

using swim::scene::json;
using swim::axi::testing::TempDir;

json round_wall_fitted(int cells_across) {
  json sc = swim::scene::load_file(std::string(SWIM_SOURCE_DIR) + "/data/scenes/paper_amplitude_0.82.json");
  sc["full3d"]["membrane"]["axisymmetric"] = true;
  sc["full3d"]["membrane"]["bending_rigidity"] = "2.1184615504e-24 J";  // as the series of docs/axi.md
  sc["full3d"]["recovery_end"] = "shape";
  sc["axi"]["method"] = "fitted";
  sc["axi"]["grid"]["cells_across"] = cells_across;
  return sc;
}

/// A small fitted mesh of the paper's container (period 2 µm): 6 element rows inside and outside
/// the wall, 12 columns across the gap.
swim::axi::FittedMeshParams small_mesh(double Rc) {
  swim::axi::FittedMeshParams mp;
  mp.Rc = Rc;
  mp.period = 2e-6;
  mp.cells_inner = 6;
  mp.cells_outer = 6;
  mp.gap_columns = 12;
  return mp;
}

}  // namespace

// A uniform inward load on the wall coupled to the fitted Stokes solver, stepped by implicit
// Euler with the wall's stiffness in the system ((A + dt K) u = F, dt = 0.1 s, far beyond any
// explicit limit): the lumen empties through the open ends until the wall is at rest. At rest
// the fluid carries no force, so the wall must sit at the static equilibrium of the wall law
// alone (relax_under_pressure) to round-off, not to a kernel's smearing: asserted to 1e-6 of the
// contraction at the middle ring and 1e-6 of R0 at every ring.
TEST(FittedCoupledWall, UniformLoadSettlesAtTheStaticEquilibriumOfTheWallLaw) {
  using namespace swim::axi;
  const double R0 = 0.125e-6, L = 0.2e-6, Rc = 0.25e-6, P = 0.05, mu = 1.2e-3, ks = 5.5e-8;
  const int n = 17;
  const AxiWall wall(AxiWallParams{R0, L, ks, 1e-24, n, {}});
  const AxiPressureResponse stat = relax_under_pressure(wall, P);
  const swim::axi::FittedMeshParams mp = small_mesh(Rc);
  FittedStokes fluid(mp, mu, n);
  Eigen::Matrix3Xd X = wall.reference();
  X.row(0).array() += 0.5 * (mp.period - L);
  Eigen::Matrix3Xd U(3, n), F(3, n);
  const double dt = 0.1;
  double u0 = 0, umax = 0;
  for (int step = 0; step < 80; ++step) {
    F = wall.forces(X);
    for (int k = 0; k < n; ++k) F(1, k) -= P * wall.node_area()[k];
    const Eigen::SparseMatrix<double> K = wall.stiffness(X, 1e-6 * R0);
    fluid.factor(X, &K, dt);
    fluid.solve(F, U);
    X += dt * U;
    umax = U.cwiseAbs().maxCoeff();
    if (step == 0) u0 = umax;
  }
  EXPECT_LT(umax, 1e-9 * u0);
  const double r_mid = X(1, n / 2);
  EXPECT_NEAR(r_mid, stat.mid_radius, 1e-6 * (R0 - stat.mid_radius));
  // the whole shape, up to the translation the fluid leaves free
  const double shift = (X(0, 0) - stat.X(0, 0));
  for (int k = 0; k < n; ++k) {
    EXPECT_NEAR(X(1, k), stat.X(1, k), 1e-6 * R0) << k;
    EXPECT_NEAR(X(0, k) - shift, stat.X(0, k), 1e-6 * R0) << k;
  }
}

// One cycle of the paper's R_f = 0.82 R0 swimmer with a round wall on the fitted method's
// coarsest useful grid (16 cells across: h = 31 nm, the rims refined to a quarter of the
// 15 nm ring spacing, the rings aligned with the segments; about a minute): the cycle
// completes; the swimmer ends ahead (+x), within 1.5 % below the extrapolated reference of the
// grid series in docs/axi.md (19.49 nm from 16, 24 and 32 cells; measured 19.26 nm here, the
// coarse mesh's error; uniform rings gave 18.98 nm); and the lumen conserves volume: the
// tube's volume change equals the
// net volume that entered through its two end discs to 1 % of the largest change (the Q2 field
// leaks through a straight wall edge only at higher order).
TEST(FittedRun, RoundWallCycleCompletesSwimsForwardAndConservesTheLumenVolume) {
  json sc = round_wall_fitted(16);
  json resolved;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(sc, resolved);
  ASSERT_EQ(p.method, swim::axi::AxiMethod::Fitted);
  TempDir dir("swim-axi-fitted-cycle");
  swim::axi::RunControlAxi ctl;
  ctl.progress = 0;
  ctl.keep_rows = true;
  const swim::axi::RunOutcomeAxi out = swim::axi::run_axi(p, resolved, dir.path.string(), ctl);
  ASSERT_FALSE(out.failed) << out.message;
  const json& s = out.summary;
  EXPECT_EQ(s["model"], "axisymmetric_fitted_finite_elements");
  ASSERT_EQ(s["cycles_completed"].get<int>(), 1);
  const double d = s["displacement_per_cycle_m"].get<double>();
  EXPECT_GT(d, 0.985 * 19.49e-9);
  EXPECT_LT(d, 19.49e-9);
  const auto& series = out.record.series;
  const std::vector<double> tube = series.column("tube_volume_m3"), rear = series.column("volume_rear_m3"),
                            front = series.column("volume_front_m3");
  double dv_max = 0, mismatch = 0;
  for (std::size_t k = 0; k < tube.size(); ++k) {
    const double dv = tube[k] - tube[0];
    dv_max = std::max(dv_max, std::abs(dv));
    mismatch = std::max(mismatch, std::abs(dv - (rear[k] - front[k])));
  }
  EXPECT_GT(dv_max, 1e-21);
  EXPECT_LT(mismatch, 1e-2 * dv_max);
  EXPECT_EQ(s["segment_reached_s"].size(), 6u);  // each of the six segments reached R_f once
}

namespace {

/// One stroke of a load on the front half of the tube, q(t) = q0 sin^2(pi t / T) per unit
/// reference area (inward), on the fitted fluid with linearly implicit Euler steps
/// (dt = T / steps). Returns {net displacement of the area-weighted centre, largest excursion}.
std::array<double, 2> front_half_stroke(double T, int steps) {
  using namespace swim::axi;
  const double R0 = 0.125e-6, L = 0.2e-6, Rc = 0.25e-6, mu = 1.2e-3, ks = 5.5e-8, q0 = 0.2;
  const int n = 17;
  const AxiWall wall(AxiWallParams{R0, L, ks, 2e-24, n, {}});
  const swim::axi::FittedMeshParams mp = small_mesh(Rc);
  FittedStokes fluid(mp, mu, n);
  Eigen::Matrix3Xd X = wall.reference();
  X.row(0).array() += 0.5 * (mp.period - L);
  const Eigen::VectorXd& A = wall.node_area();
  auto centre = [&](const Eigen::Matrix3Xd& Y) { return Y.row(0).dot(A.transpose()) / A.sum(); };
  const double c0 = centre(X);
  double excursion = 0;
  Eigen::Matrix3Xd U(3, n);
  const double dt = T / steps;
  for (int step = 1; step <= steps; ++step) {
    const double s = std::sin(M_PI * step * dt / T), q = q0 * s * s;
    Eigen::Matrix3Xd F = wall.forces(X);
    for (int k = n / 2; k < n; ++k) F(1, k) -= q * A[k];
    const Eigen::SparseMatrix<double> K = wall.stiffness(X, 1e-6 * R0);
    fluid.factor(X, &K, dt);
    fluid.solve(F, U);
    X += dt * U;
    excursion = std::max(excursion, std::abs(centre(X) - c0));
  }
  // let the wall relax back to its reference shape (the load is off)
  for (int step = 0; step < 40; ++step) {
    const Eigen::Matrix3Xd F = wall.forces(X);
    const Eigen::SparseMatrix<double> K = wall.stiffness(X, 1e-6 * R0);
    fluid.factor(X, &K, 5 * T);
    fluid.solve(F, U);
    X += 5 * T * U;
  }
  return {centre(X) - c0, excursion};
}

}  // namespace

// The scallop theorem: in Stokes flow a force-free swimmer whose shapes retrace their path
// makes no net progress. A load that rises and falls on the tube's front half drives the wall
// through shapes that retrace their path only in the quasi-static limit, where each shape is the
// static equilibrium of the load; a stroke of duration T deviates from it by O(tau / T) (tau the
// wall's relaxation time in the fluid: the lumen drains through its open ends, about a second
// here), and so does the net displacement. Asserted: the net displacement is a fraction of the
// stroke's excursion that falls at least 2.5 times when the stroke is 4 times slower (first
// order in 1/T; measured 0.29 at T = 1 s and 0.096 at T = 4 s), and below 0.15 at T = 4 s. A
// coupling that broke reciprocity (a non-symmetric mobility, a load or velocity transfer that
// were not transposes) would leave an O(1) remainder.
TEST(FittedScallop, AReciprocalStrokeGivesNoNetDisplacementInTheQuasiStaticLimit) {
  const std::array<double, 2> fast = front_half_stroke(1.0, 200), slow = front_half_stroke(4.0, 200);
  ASSERT_GT(fast[1], 1e-10);
  ASSERT_GT(slow[1], 1e-10);
  const double r_fast = std::abs(fast[0]) / fast[1], r_slow = std::abs(slow[0]) / slow[1];
  std::printf("  net / excursion: %.3e (T = 1 s), %.3e (T = 4 s); excursions %.3e, %.3e m\n", r_fast, r_slow,
              fast[1], slow[1]);
  EXPECT_LT(r_slow, 0.15);
  EXPECT_LT(r_slow, r_fast / 2.5);
}
