// Short-wave wall traction of the force-free force-driven model (model1d.short_wave_traction):
// the |k| quadrature, the relaxation rate of a short-wave load against the linear
// Stokes-lubrication prediction, and the scene's guards. (The Newton matrix of the IDA path
// that carries it is checked with the other force-free Jacobians, test_force_free.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "common/errors.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"
#include "mode_response.hpp"

using namespace swim::reduced1d;

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

// |k| ~= sum_j c_j k^2 / (k^2 + s_j^2) for the discrete wavenumber k_d = (2/h) sin(k h / 2)
// of every cosine mode k = m pi / L of the grid (the eigenvalues of the mirror-end second
// difference), within 1 % from the tube's lowest mode to the cell scale, on coarse and fine
// grids, with positive weights (a dissipative operator); the number of nodes grows only
// logarithmically with N.
TEST(WallTraction, QuadratureOfAbsKIsWithinOnePercentOnEveryGridMode) {
  const double L = 0.4e-6;
  for (int N : {4, 7, 20, 200, 3200, 100000}) {
    const double h = L / N;
    const auto q = detail::abs_k_quadrature(L, h);
    ASSERT_EQ(q.s.size(), q.c.size());
    EXPECT_GE(q.s.size(), 3u);
    EXPECT_LE(q.s.size(), 10u);
    for (double c : q.c) EXPECT_GT(c, 0.0);
    double worst = 0;
    for (int m = 1; m < N; ++m) {
      const double k = m * kPi / L, kd = 2.0 / h * std::sin(0.5 * k * h);
      double a = 0;
      for (std::size_t j = 0; j < q.s.size(); ++j) a += q.c[j] * kd * kd / (kd * kd + q.s[j] * q.s[j]);
      worst = std::max(worst, std::abs(a / kd - 1.0));
    }
    EXPECT_LT(worst, 0.01) << "N = " << N;
  }
}

// A small load q_i = q0 cos(k z_i) on a long tube (unbounded outer flow: p_out = 0, local
// lumen lubrication) relaxes, far from the ends, as R - R0 = -(q0/C1) cos(k z) (1 - e^{-lambda t})
// with lambda = C1 / (eta_lub + eta_tr): eta_lub = 16 mu / (R0^3 k_d^2) from the lumen's
// lubrication flow and eta_tr = 4 mu k_d from the traction of the two fluids (discrete
// wavenumber k_d). At k R0 = 4 the traction is 16 times the lubrication resistance: the
// relaxation is 17 times slower with it, and each model meets its own rate to 2 %.
TEST(WallTraction, ShortWaveLoadRelaxesAtTheLinearStokesRate) {
  for (bool traction : {true, false}) {
    const test::ModeResponse r = test::mode_response(51, 0.0, traction, 1.0);  // k R0 = 4.006
    EXPECT_NEAR(r.amplitude, 1.0 - std::exp(-1.0), 0.02 * (1.0 - std::exp(-1.0))) << "traction " << traction;
  }
}

// The traction belongs to the force-free force-driven model: a scene that asks for it with the
// paper's model or with a prescribed wave is refused, naming the key.
TEST(WallTraction, SceneRefusesItOutsideTheForceFreeForceDrivenModel) {
  using swim::scene::json;
  json resolved;
  const Params p = read_scene(json{{"model1d", {{"short_wave_traction", true}}}}, resolved);
  EXPECT_TRUE(p.swimmer.short_wave_traction);
  EXPECT_EQ(resolved["model1d"]["short_wave_traction"], true);
  for (const json& bad : {json{{"model1d", {{"short_wave_traction", true}, {"model", "paper"}}}},
                          json{{"model1d", {{"short_wave_traction", true}}}, {"wave", {{"kind", "step"}}}}}) {
    try {
      read_scene(bad, resolved);
      ADD_FAILURE() << "accepted " << bad.dump();
    } catch (const swim::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("model1d.short_wave_traction"), std::string::npos) << e.what();
    }
  }
}

// The traction damps the cell-scale wall motion that lubrication leaves undamped, so the
// force-driven cycle converges on coarse grids: the default swimmer's displacement per cycle
// on 50 cells is within 1 % of that on 200, its cycle time within 2 % (measured 0.3 % and
// 1.6 %; docs/outer-flow-1d.md, 3b; the lubrication-only wall's displacement is 2-12 % off at
// N = 50 on the paper's scenes).
TEST(WallTraction, FiftyCellsMatchTwoHundred) {
  auto run = [](int N) {
    Params p;
    p.wave = WaveKind::ForceDriven;
    p.swimmer.short_wave_traction = true;
    p.numerics.cells = N;
    p.numerics.output_interval = 2e-3;
    const Result r = solve(p);
    EXPECT_FALSE(r.failure) << (r.failure ? r.failure->what() : "");
    return metrics(p, r);
  };
  const auto coarse = run(50), fine = run(200);
  ASSERT_EQ(coarse.cycles_completed, 1);
  ASSERT_EQ(fine.cycles_completed, 1);
  EXPECT_GT(fine.displacement_per_cycle_m, 0.0);
  EXPECT_NEAR(coarse.displacement_per_cycle_m, fine.displacement_per_cycle_m, 0.01 * fine.displacement_per_cycle_m);
  EXPECT_NEAR(coarse.mean_cycle_time_s, fine.mean_cycle_time_s, 0.02 * fine.mean_cycle_time_s);
}

// The run with the traction is an index-1 DAE; its local error test covers the differential
// unknowns only. At the default tolerance the cycle then matches a run at 1e-10 to well below
// the grid's own error (N = 50 against 200: 3e-3 in displacement) and takes under 1 000
// steps; with the algebraic unknowns (V, p and the traction fields, which jump with the
// actuation at every relay ramp) in the test it took 2 418.
TEST(WallTraction, ErrorTestOnTheDifferentialUnknownsKeepsTheCycleAtFewerSteps) {
  auto run = [](double rtol, long& steps, std::vector<Sample>& series) {
    Params p;
    p.wave = WaveKind::ForceDriven;
    p.swimmer.short_wave_traction = true;
    p.numerics.cells = 50;
    p.numerics.rtol = rtol;
    p.numerics.output_interval = 2e-3;
    Result r = solve(p);
    EXPECT_FALSE(r.failure) << (r.failure ? r.failure->what() : "");
    steps = r.stats.at("steps");
    series = std::move(r.series);
    return metrics(p, r);
  };
  long steps = 0, steps_ref = 0;
  std::vector<Sample> s, s_ref;
  const auto m = run(1e-6, steps, s), ref = run(1e-10, steps_ref, s_ref);
  ASSERT_EQ(m.cycles_completed, 1);
  ASSERT_EQ(ref.cycles_completed, 1);
  EXPECT_LT(steps, 1000);
  EXPECT_NEAR(m.displacement_per_cycle_m, ref.displacement_per_cycle_m, 2e-5 * ref.displacement_per_cycle_m);
  EXPECT_NEAR(m.mean_cycle_time_s, ref.mean_cycle_time_s, 1e-4 * ref.mean_cycle_time_s);

  // U(t) between the steps comes from IDA's interpolation of the algebraic unknowns, which
  // are outside the error test: over the cycle its samples stay within 1e-3 (rms) and 1e-2
  // (largest, a sample just after a protocol event) of max |U| of the reference run
  // (measured 2.0e-4 and 1.6e-3), compared on the output grid (the two runs' event samples
  // fall at slightly different times).
  double u_max = 0.0, sq = 0.0, err_max = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0, j = 0; i < s.size() && j < s_ref.size();) {
    if (std::abs(s[i].t - s_ref[j].t) <= 1e-12) {
      u_max = std::max(u_max, std::abs(s_ref[j].W));
      const double e = s[i].W - s_ref[j].W;
      sq += e * e;
      err_max = std::max(err_max, std::abs(e));
      ++n, ++i, ++j;
    } else if (s[i].t < s_ref[j].t) {
      ++i;
    } else {
      ++j;
    }
  }
  ASSERT_GT(n, 200u);  // a cycle of about 0.52 s sampled every 2 ms
  const double rms = std::sqrt(sq / double(n));
  ASSERT_GT(u_max, 0.0);
  EXPECT_LT(rms, 1e-3 * u_max);
  EXPECT_LT(err_max, 1e-2 * u_max);
  std::printf("U(t) samples against rtol 1e-10: rms %.3g, largest %.3g of max |U|\n", rms / u_max, err_max / u_max);
}
