// The axisymmetric tier end to end: the coupled wall at rest under a uniform load, a
// round-wall cycle of the paper's amplitude scene (lumen volume balance, forward swimming,
// mirror symmetry), and the scenes the tier refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <unistd.h>

#include "axi/grid_axi.hpp"
#include "axi/ib_axi.hpp"
#include "axi/run_axi.hpp"
#include "axi_test_support.hpp"
#include "axi/scene_axi.hpp"
#include "axi/stokes_axi.hpp"
#include "axi/wall_axi.hpp"
#include "common/errors.hpp"
#include "common/scene.hpp"

namespace {

using swim::scene::json;
namespace fs = std::filesystem;

json paper_scene(const std::string& file) { return swim::scene::load_file(std::string(SWIM_SOURCE_DIR) + "/data/scenes/" + file); }

json round_wall(json sc, int cells_across) {
  sc["full3d"]["membrane"]["axisymmetric"] = true;
  sc["axi"]["method"] = "immersed_boundary";
  sc["axi"]["grid"]["cells_across"] = cells_across;
  return sc;
}

std::string input_error_key(const json& sc) {
  json resolved;
  try {
    (void)swim::axi::read_scene_axi(sc, resolved);
  } catch (const swim::InputError& e) {
    return e.key();
  }
  return "(accepted)";
}

using swim::axi::testing::TempDir;

}  // namespace

// A uniform inward load on the coupled wall: the fluid relaxes (the lumen empties through the
// open ends) until the wall is at rest, where only the wall law balances the load. The middle
// ring must come to the static equilibrium of the wall alone (relax_under_pressure) to 1e-3 of
// the contraction (measured: 3.3e-4; node-scale force modes the kernel cannot see keep a
// residual lumen pressure of a few µPa).
TEST(AxiCoupledWall, UniformLoadSettlesAtTheStaticRadiusOfTheWallLaw) {
  using namespace swim::axi;
  const double R0 = 0.125e-6, L = 0.2e-6, Rc = 0.25e-6, h = Rc / 16, mu = 1.2e-3, ks = 5.5e-8, P = 0.05;
  const AxiGrid g{16, 128, h};
  AxiStokes stokes(g, mu);
  const int n = int(std::ceil(L / (0.25 * h))) + 1;
  const AxiWall wall(AxiWallParams{R0, L, ks, 1e-24, n, {}});
  const AxiPressureResponse stat = relax_under_pressure(wall, P);
  Eigen::Matrix3Xd X = wall.reference();
  X.row(0).array() += 0.5 * (g.period() - L);
  Eigen::Matrix3Xd U(3, n), F(3, n);
  std::vector<double> fr, fx, u(g.u_size()), w(g.w_size());
  const double dt = 1e-3;  // below the explicit limit of this grid
  double umax = 0;
  for (int step = 0; step < 3000; ++step) {
    F = wall.forces(X);
    for (int k = 0; k < n; ++k) F(1, k) -= P * wall.node_area()[k];
    spread(g, X, F, fr, fx);
    stokes.solve(fr.data(), fx.data(), u.data(), w.data());
    interpolate(g, X, u.data(), w.data(), U);
    X += dt * U;
    umax = U.cwiseAbs().maxCoeff();
  }
  // at rest: 1e-11 m/s against the 2e-7 m/s of the first step
  EXPECT_LT(umax, 1e-11);
  const double r_mid = n % 2 ? X(1, n / 2) : 0.5 * (X(1, n / 2 - 1) + X(1, n / 2));
  EXPECT_NEAR(r_mid, stat.mid_radius, 1e-3 * (R0 - stat.mid_radius));
}

// The scenes the tier cannot represent are refused, naming the key.
TEST(AxiScene, ScenesTheTierCannotRepresentAreRefusedNamingTheKey) {
  const json base = round_wall(paper_scene("paper_amplitude_0.82.json"), 32);
  EXPECT_EQ(input_error_key(base), "(accepted)");
  json s = base;
  s["full3d"]["membrane"]["axisymmetric"] = false;
  EXPECT_EQ(input_error_key(s), "full3d.membrane.axisymmetric");
  s = base;
  s["container"]["kind"] = "duct";
  EXPECT_EQ(input_error_key(s), "container.kind");
  s = base;
  s["axi"]["grid"]["cells_across"] = 33;
  EXPECT_EQ(input_error_key(s), "axi.grid.cells_across");
  s = base;
  s["full3d"]["navier_stokes"] = true;
  EXPECT_EQ(input_error_key(s), "full3d.navier_stokes");
  s = base;
  s["axi"]["unknown"] = 1;
  EXPECT_EQ(input_error_key(s), "axi.unknown");
  // the round wall has no lobes: neither seed is one it can hold
  s = base;
  s["full3d"]["membrane"]["seed_mode"] = 8;
  s["full3d"]["membrane"]["seed_amplitude"] = 0.01;
  EXPECT_EQ(input_error_key(s), "full3d.membrane.seed_amplitude");
  s = base;
  s["full3d"]["membrane"]["secondary_seed_mode"] = 4;
  s["full3d"]["membrane"]["secondary_seed_amplitude"] = 0.001;
  EXPECT_EQ(input_error_key(s), "full3d.membrane.secondary_seed_amplitude");
  s = base;
  for (double bad : {0.0, 1e-7, 1.0}) {  // [1e-6, 1): smaller would run for days
    s["axi"]["tolerance"] = bad;
    EXPECT_EQ(input_error_key(s), "axi.tolerance") << bad;
  }
  s["axi"]["tolerance"] = 1e-6;
  EXPECT_EQ(input_error_key(s), "(accepted)");
  // the rims' refinement is the fitted method's: the immersed boundary keeps uniform rings
  s = base;
  s["axi"]["rim_refinement"] = 0.25;
  EXPECT_EQ(input_error_key(s), "axi.rim_refinement");
  s["axi"]["method"] = "fitted";
  EXPECT_EQ(input_error_key(s), "(accepted)");
  for (double bad : {0.0, -0.5}) {
    s["axi"]["rim_refinement"] = bad;
    EXPECT_EQ(input_error_key(s), "axi.rim_refinement") << bad;
  }
  // the triangulation is the fitted method's mesh, for the force-driven protocol
  s = base;
  s["axi"]["mesh"] = "triangles";
  EXPECT_EQ(input_error_key(s), "axi.mesh");
  s["axi"]["method"] = "fitted";
  EXPECT_EQ(input_error_key(s), "(accepted)");
  s["axi"]["mesh"] = "hexagons";
  EXPECT_EQ(input_error_key(s), "axi.mesh");
  s["axi"]["mesh"] = "triangles";
  for (const char* bad : {"0 degree", "25 degree", "0.5 m"}) {
    s["axi"]["remesh_angle"] = bad;
    EXPECT_EQ(input_error_key(s), "axi.remesh_angle") << bad;
  }
  s["axi"]["remesh_angle"] = "8 degree";
  EXPECT_EQ(input_error_key(s), "(accepted)");
  s["axi"]["mesh"] = "quadrilaterals";  // the angle is the triangulation's
  EXPECT_EQ(input_error_key(s), "axi.remesh_angle");
  s["axi"].erase("remesh_angle");
  // the scheduled remeshes: an interval in [0, 1 s], 10 ms by default on triangles, the
  // triangulation's only
  s["axi"]["mesh"] = "triangles";
  {
    json resolved;
    EXPECT_DOUBLE_EQ(swim::axi::read_scene_axi(s, resolved).remesh_interval, 0.01);
  }
  for (const char* bad : {"-1 ms", "2 s", "3 m"}) {
    s["axi"]["remesh_interval"] = bad;
    EXPECT_EQ(input_error_key(s), "axi.remesh_interval") << bad;
  }
  for (const char* good : {"0 s", "2 ms"}) {
    s["axi"]["remesh_interval"] = good;
    EXPECT_EQ(input_error_key(s), "(accepted)") << good;
  }
  s["axi"]["mesh"] = "quadrilaterals";
  EXPECT_EQ(input_error_key(s), "axi.remesh_interval");
  s["axi"]["remesh_interval"] = "0 s";
  EXPECT_EQ(input_error_key(s), "(accepted)");
  s["axi"].erase("remesh_interval");
  // the gap's triangle size: in [1, 8] times h, the triangulation's (the structured mesh grades
  // its own gap columns)
  s["axi"]["mesh"] = "triangles";
  for (double bad : {0.5, 9.0}) {
    s["axi"]["gap_size"] = bad;
    EXPECT_EQ(input_error_key(s), "axi.gap_size") << bad;
  }
  s["axi"]["gap_size"] = 1;
  EXPECT_EQ(input_error_key(s), "(accepted)");
  s["axi"]["mesh"] = "quadrilaterals";
  EXPECT_EQ(input_error_key(s), "axi.gap_size");
  s["axi"].erase("gap_size");
  EXPECT_EQ(input_error_key(s), "(accepted)");
  s["axi"]["mesh"] = "triangles";
  s["wave"] = {{"kind", "step"}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}, {"width", "0.05 um"}};
  s.erase("protocol");
  EXPECT_EQ(input_error_key(s), "axi.mesh");
  // the diagnostic wall without the Poisson coupling: a boolean, default true, resolved
  s = base;
  json resolved;
  EXPECT_TRUE(swim::axi::read_scene_axi(s, resolved).poisson_coupling);
  EXPECT_EQ(resolved["axi"]["wall_poisson_coupling"], true);
  s["axi"]["wall_poisson_coupling"] = false;
  EXPECT_FALSE(swim::axi::read_scene_axi(s, resolved).poisson_coupling);
  s["axi"]["wall_poisson_coupling"] = 0;
  EXPECT_EQ(input_error_key(s), "axi.wall_poisson_coupling");
}

namespace {

struct CycleRun {
  swim::axi::RunOutcomeAxi out;
  std::vector<double> t, x, tube, rear, front;
};

CycleRun run_round_wall_cycle(int cells_across) {
  json sc = round_wall(paper_scene("paper_amplitude_0.82.json"), cells_across);
  sc["full3d"]["recovery_end"] = "shape";
  json resolved;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(sc, resolved);
  TempDir dir("swim-axi-cycle-" + std::to_string(cells_across));
  swim::axi::RunControlAxi ctl;
  ctl.progress = 0;
  ctl.keep_rows = true;
  CycleRun r;
  r.out = swim::axi::run_axi(p, resolved, dir.path.string(), ctl);
  const auto& s = r.out.record.series;
  r.t = s.column("t_s");
  r.x = s.column("x_center_m");
  r.tube = s.column("tube_volume_m3");
  r.rear = s.column("volume_rear_m3");
  r.front = s.column("volume_front_m3");
  return r;
}

}  // namespace

// One cycle of the paper's R_f = 0.82 R0 swimmer with a round wall on two grids (h = 15.6 and
// 10.4 nm; 0.2 and 0.5 s of wall time): the cycle completes, the swimmer ends ahead (the paper's
// forward direction, +x), and the lumen conserves volume: the tube's volume change equals the
// net volume that entered through its two end discs, to 0.5 % of the largest change (measured
// 0.29 % and 0.15 %: the kernel-interpolated end fluxes converge with h). On the finer grid the
// displacement per cycle is larger: the immersed boundary's first-order error makes the wall
// hydraulically thicker on the coarse grid (measured 11.1 and 13.1 nm; the series to h = 2 nm
// in docs/axi.md rises towards about 19 nm).
TEST(AxiRun, RoundWallCycleCompletesSwimsForwardAndConservesTheLumenVolume) {
  double per_cycle[2];
  int g = 0;
  for (int cells : {32, 48}) {
    const CycleRun r = run_round_wall_cycle(cells);
    ASSERT_FALSE(r.out.failed) << r.out.message;
    const json& s = r.out.summary;
    ASSERT_EQ(s["cycles_completed"].get<int>(), 1);
    per_cycle[g] = s["displacement_per_cycle_m"].get<double>();
    EXPECT_GT(per_cycle[g], 5e-9);
    EXPECT_LT(per_cycle[g], 0.1 * 0.4e-6);  // a small fraction of the body length
    double dv_max = 0, mismatch = 0;
    for (std::size_t k = 0; k < r.t.size(); ++k) {
      const double dv = r.tube[k] - r.tube[0];
      dv_max = std::max(dv_max, std::abs(dv));
      mismatch = std::max(mismatch, std::abs(dv - (r.rear[k] - r.front[k])));
    }
    EXPECT_GT(dv_max, 1e-21);
    EXPECT_LT(mismatch, 5e-3 * dv_max) << cells << " cells across";
    ++g;
  }
  EXPECT_GT(per_cycle[1], per_cycle[0]);
}
