// Force-driven wave: static uniform load, the Section-3 protocol over one cycle, volume
// conservation with and without wall inertia, and robustness at extreme parameters.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "jacobian_check.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/protocol.hpp"
#include "reduced1d/solver.hpp"

using namespace swim::reduced1d;

namespace {
// The paper's balance (reproduction mode) unless a test asks for the force-free model.
Params force_driven(int N = 50, SwimmerModel model = SwimmerModel::Paper) {
  Params p;
  p.swimmer.model = model;
  p.wave = WaveKind::ForceDriven;
  p.numerics.cells = N;
  p.numerics.output_interval = 2e-3;
  return p;
}
bool all_finite(const Result& r) {
  for (const auto& s : r.series)
    for (double v : {s.t, s.X, s.W, s.energy, s.R_min, s.R_max, s.Q_rear, s.Q_front, s.V_rear,
                     s.V_front, s.tube_volume})
      if (!std::isfinite(v)) return false;
  for (double v : r.radius)
    if (!std::isfinite(v)) return false;
  return true;
}
}  // namespace

TEST(Reduced1dForceDriven, UniformStaticLoadRelaxesToTubeLawRadius) {
  for (bool inertia : {false, true}) {
    Params p = force_driven(40);
    p.wall.inertia = inertia;
    const double q = 0.1;  // Pa: R -> R0 - q / C1 = 0.80 R0
    const double t_end = 12 * detail::relaxation_time(p);
    p.numerics.output_interval = t_end / 4;
    const Result r = detail::solve_fixed_actuation(p, std::vector<double>(40, q), t_end);
    ASSERT_FALSE(r.failure) << r.failure->what();
    const double R_eq = p.geometry.R0 - q / p.wall.C1;
    const int N = 40;
    const std::size_t last = r.radius_times.size() - 1;
    for (int i = 0; i < N; ++i) EXPECT_NEAR(r.radius[last * N + i], R_eq, 1e-4 * p.geometry.R0) << i;
    // Calibration relation of source-equations.md §1: C1 = pressure / (R0 - R).
    const double R_mid = r.radius[last * N + N / 2];
    EXPECT_NEAR(q / (p.geometry.R0 - R_mid), p.wall.C1, 1e-3 * p.wall.C1);
    EXPECT_TRUE(all_finite(r));
  }
}

// The Newton matrices are built from an analytic tridiagonal Jacobian plus one rank-1 term per
// held segment (CVODE), or a frozen-segment difference-quotient band plus the same rank-1 terms
// (IDA). Both must equal a central finite-difference Jacobian of the full model (relative 1e-6)
// at random states whose held-segment means sit on the held law's ramps.
TEST(Reduced1dForceDriven, AnalyticJacobianMatchesFiniteDifferences) {
  for (bool inertia : {false, true}) {
    for (int N : {37, 60}) {
      Params p = force_driven(N);
      p.wall.inertia = inertia;
      p.swimmer.drag = ExternalDrag::ResistiveForce;  // exercises the D-X block
      const int n = p.protocol.segments;
      // contraction with segments 3..n-1 held (segment n-1 holds the right end), and recovery
      for (auto [phase, active] : {std::pair{0, 2}, std::pair{0, n - 1}, std::pair{1, 0}}) {
        for (unsigned seed : {1u, 2u, 3u}) {
          const auto c = test::check_jacobian(p, phase, active, seed);
          EXPECT_LT(c.max_rel_error, 1e-6) << "inertia=" << inertia << " N=" << N << " phase=" << phase
                                            << " active=" << active << " seed=" << seed;
          EXPECT_GT(c.entries, 3 * N);
          if (phase == 0) {
            EXPECT_EQ(c.rank, n - 1 - active) << "every held segment sits on a ramp";
          }
        }
      }
    }
  }
}

TEST(Reduced1dForceDriven, ProtocolCompletesOneCycle) {
  const Params p = force_driven(50);
  const Result r = solve(p);
  ASSERT_FALSE(r.failure) << r.failure->what();
  ASSERT_TRUE(all_finite(r));
  const int n = p.protocol.segments;
  // Every segment reached R_f once, right to left: the events in the order reached.
  ASSERT_EQ(int(r.segment_reached.size()), n);
  for (int k = 0; k < n; ++k) EXPECT_GE(r.segment_reached[k], 0.0) << k;
  for (int k = 0; k + 1 < n; ++k) EXPECT_LT(r.segment_reached[k], r.segment_reached[k + 1]);
  // Switch bound: the hold and recovery rules are continuous (regularised) actuation laws, so
  // the only discrete switches are the n "segment reached R_f" events and the cycle end.
  EXPECT_EQ(r.switches, n + 1);
  // Cycle completed with the energy back within tolerance; simulated cycle time O(10-1000) ms.
  ASSERT_EQ(r.cycle_start.size(), 1u);
  ASSERT_EQ(r.cycle_end.size(), 1u);
  EXPECT_GT(r.cycle_end[0], 0.01);
  EXPECT_LT(r.cycle_end[0], 1.0);
  EXPECT_LE(r.series.back().energy, 1.0001 * p.protocol.energy_tol * detail::reference_energy(p));
  EXPECT_EQ(r.series.back().phase, 2);
  EXPECT_DOUBLE_EQ(r.series.back().t, r.cycle_end[0]);
  // The swimmer moves in +z by the end of the contraction (wave travels in -z).
  double X_contraction = 0;
  for (const auto& s : r.series)
    if (s.t <= r.segment_reached.back()) X_contraction = s.X;
  EXPECT_GT(X_contraction, 0.0);
  EXPECT_GT(r.series.back().X, 0.0);
  // Radii stay in a sane range.
  for (const auto& s : r.series) {
    EXPECT_GT(s.R_min, 0.3 * p.geometry.R0);
    EXPECT_LT(s.R_max, 1.5 * p.geometry.R0);
  }
  EXPECT_GT(r.stats.at("steps"), 0);
  EXPECT_EQ(r.stats.at("reinits"), n);  // one restart per switch except the final one
}


// Several cycles: the segment events of every cycle are kept, in the order reached, each cycle's
// n events inside it, so the run record gives the protocol's phases averaged over the cycles
// (n contractions and the recovery, summing to the mean cycle time); before, only the last
// cycle's were kept and a multi-cycle run had no phases.
TEST(Reduced1dForceDriven, EveryCyclesSegmentEventsGiveThePhases) {
  Params p = force_driven(50, SwimmerModel::ForceFree);
  p.protocol.cycles = 2;
  const Result r = solve(p);
  ASSERT_FALSE(r.failure) << r.failure->what();
  const int n = p.protocol.segments;
  ASSERT_EQ(r.cycle_end.size(), 2u);
  ASSERT_EQ(int(r.segment_reached.size()), 2 * n);
  for (int c = 0; c < 2; ++c)
    for (int k = 0; k < n; ++k) {
      const double t = r.segment_reached[std::size_t(c * n + k)];
      EXPECT_GT(t, r.cycle_start[std::size_t(c)]) << c << " " << k;
      EXPECT_LT(t, r.cycle_end[std::size_t(c)]) << c << " " << k;
    }
  const swim::record::CycleFigures cf = swim::record::cycle_figures(record_of(p, r));
  ASSERT_EQ(int(cf.phase_times_s.size()), n + 1);
  double sum = 0;
  for (double t : cf.phase_times_s) {
    EXPECT_GT(t, 0.0);
    sum += t;
  }
  EXPECT_NEAR(sum, cf.cycle_time_s, 1e-12 * cf.cycle_time_s);
  ASSERT_EQ(cf.phase_displacements_m.size(), cf.phase_times_s.size());
  double d = 0;
  for (double x : cf.phase_displacements_m) d += x;
  EXPECT_NEAR(d, cf.displacement_per_cycle_m, 1e-9 * std::abs(cf.displacement_per_cycle_m));
}
TEST(Reduced1dForceDriven, ConservesVolumeWithAndWithoutInertia) {
  for (bool inertia : {false, true}) {
    Params p = force_driven(40);
    p.wall.inertia = inertia;
    p.numerics.rtol = 1e-8;
    p.numerics.atol_scale = 1e-8;
    p.duration = inertia ? 0.03 : 0.0;  // the inertial run resolves wall oscillations: keep it short
    const Result r = solve(p);
    ASSERT_FALSE(r.failure) << r.failure->what();
    const double V0 = r.series.front().tube_volume;
    double worst = 0;
    for (const auto& s : r.series)
      worst = std::max(worst, std::abs((s.tube_volume - V0) - (s.V_rear - s.V_front)));
    EXPECT_LT(worst, 1e-6 * V0) << "inertia=" << inertia;
    double swing = 0;
    for (const auto& s : r.series) swing = std::max(swing, std::abs(s.tube_volume - V0));
    EXPECT_GT(swing, 0.05 * V0);  // the check is not vacuous
  }
}

TEST(Reduced1dForceDriven, InertiaIsASmallCorrectionAtDefaultMass) {
  Params a = force_driven(40);
  a.duration = 0.03;
  Params b = a;
  b.wall.inertia = true;
  const Result ra = solve(a), rb = solve(b);
  ASSERT_FALSE(ra.failure);
  ASSERT_FALSE(rb.failure) << rb.failure->what();
  EXPECT_NEAR(rb.series.back().X, ra.series.back().X, 0.05 * std::abs(ra.series.back().X));
}

// Extreme parameters of the paper's model with the paper's fixed actuation (q = 0.32 Pa):
// each case states its outcome. Unreachable targets and collapsing ends fail at t = 0 with a
// cause and a remedy; the others complete one cycle with finite values everywhere.
TEST(Reduced1dForceDriven, ExtremeParametersGiveTheirStatedOutcome) {
  struct Case {
    const char* name;
    std::function<void(Params&)> set;
    bool completes;
    const char* cause;  // substring of the failure when !completes
  };
  const std::vector<Case> cases = {
      {"R_f/R0 = 0.1", [](Params& p) { p.protocol.R_f = 0.1 * p.geometry.R0; }, false, "cannot contract"},
      {"R_f/R0 = 0.95", [](Params& p) { p.protocol.R_f = 0.95 * p.geometry.R0; }, true, ""},
      {"eps = R0/L = 0.02", [](Params& p) { p.geometry.L = p.geometry.R0 / 0.02; }, true, ""},
      {"eps = R0/L = 1", [](Params& p) { p.geometry.L = p.geometry.R0; }, true, ""},
      {"C1 x 1e-2", [](Params& p) { p.wall.C1 *= 1e-2; }, false, "collapsed"},
      {"C1 x 1e2", [](Params& p) { p.wall.C1 *= 1e2; }, false, "cannot contract"},
      {"mu x 1e-2", [](Params& p) { p.fluid.mu *= 1e-2; }, true, ""},
      {"mu x 1e2", [](Params& p) { p.fluid.mu *= 1e2; }, true, ""},
  };
  for (const auto& c : cases) {
    Params p = force_driven(40);
    c.set(p);
    p.numerics.output_interval = 0.02 * detail::relaxation_time(p);
    p.numerics.max_steps = 200000;
    const Result r = solve(p);
    EXPECT_TRUE(all_finite(r)) << c.name;
    ASSERT_FALSE(r.series.empty()) << c.name;
    if (c.completes) {
      EXPECT_FALSE(r.failure) << c.name << ": " << (r.failure ? r.failure->what() : "");
      EXPECT_EQ(r.cycle_end.size(), 1u) << c.name;
    } else {
      ASSERT_TRUE(r.failure) << c.name;
      EXPECT_NE(std::string(r.failure->what()).find(c.cause), std::string::npos) << c.name << ": " << r.failure->what();
      EXPECT_FALSE(r.failure->remedy().empty()) << c.name;
      EXPECT_EQ(r.failure->time(), 0.0) << c.name;
    }
  }
}

// The recovery's end (model1d.recovery_end). At R_f = 0.82 R0 the tube uniformly at R0 - delta
// stores E_delta = (delta / (R0 - R_f))^2 E_ref = 1.2e-2 E_ref, twelve times the paper's end level
// 1e-3 E_ref. "energy" (the paper's rule) ends at 1e-3 E_ref; "dead_band" at E_delta; "shape"
// when the last cell comes within delta of R0. The two later rules end the recovery earlier; the
// contraction, and with it nearly all of the displacement, is the same under all three.
TEST(Reduced1dForceDriven, RecoveryEndsByTheChosenRule) {
  Params p = force_driven(50, SwimmerModel::ForceFree);
  p.protocol.R_f = 0.82 * p.geometry.R0;
  const double E_ref = detail::reference_energy(p), d = p.protocol.delta, R0 = p.geometry.R0;
  const double E_delta = detail::dead_band_energy(p);
  EXPECT_NEAR(E_delta / E_ref, std::pow(d / (R0 - p.protocol.R_f), 2), 1e-12);
  Result r[3];
  const RecoveryEnd rules[3] = {RecoveryEnd::Energy, RecoveryEnd::DeadBand, RecoveryEnd::Shape};
  for (int k = 0; k < 3; ++k) {
    Params q = p;
    q.protocol.recovery_end = rules[k];
    r[k] = solve(q);
    ASSERT_FALSE(r[k].failure) << r[k].failure->what();
    ASSERT_EQ(r[k].cycle_end.size(), 1u) << k;
    EXPECT_EQ(r[k].switches, p.protocol.segments + 1) << k;
  }
  const Sample& e = r[0].series.back();
  const Sample& b = r[1].series.back();
  const Sample& s = r[2].series.back();
  EXPECT_NEAR(e.energy / (p.protocol.energy_tol * E_ref), 1.0, 1e-3);
  EXPECT_NEAR(b.energy / E_delta, 1.0, 1e-3);
  // every cell within delta of R0, the farthest at delta (a located root); the sample's radii
  // include the end points, which follow the end cells
  const double worst = std::max(R0 - s.R_min, s.R_max - R0);
  EXPECT_NEAR(worst / d, 1.0, 0.05);
  EXPECT_LT(s.energy, E_delta * 1.05);
  EXPECT_LT(r[1].cycle_end[0], 0.85 * r[0].cycle_end[0]);
  EXPECT_LT(r[2].cycle_end[0], 0.85 * r[0].cycle_end[0]);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(r[k].segment_reached, r[0].segment_reached) << k;
    EXPECT_NEAR(r[k].series.back().X / e.X, 1.0, 0.01) << k;
  }
  std::printf("R_f = 0.82 R0: cycle %.4f s (energy), %.4f s (dead_band), %.4f s (shape); X %.4g / %.4g / %.4g m\n",
              r[0].cycle_end[0], r[1].cycle_end[0], r[2].cycle_end[0], e.X, b.X, s.X);
}
