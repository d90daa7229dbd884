// The wall's bending along the axis in the 1D tier (model1d.axial_bending): the term
// D d^4R/dz^4 of an axisymmetric thin shell, so that a load of axial wavenumber k meets the
// stiffness C1 + D k^4 instead of C1 alone. Checked here: the static and the dynamic response
// of a sinusoidal load against that stiffness, the residual against the bending energy's
// gradient, the Newton matrix against central differences, the small-D limit, and the scene's
// guards.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "jacobian_check.hpp"
#include "reduced1d/force_model.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/protocol.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"
#include "mode_response.hpp"
#include "scene_refusal.hpp"

using namespace swim::reduced1d;
namespace scene = swim::scene;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kD = 2.1184615504e-24;  // J: the round wall of the validation suite

using test::ModeResponse;

ModeResponse mode_response(int m, double D, double t_over_relaxation) {
  return test::mode_response(m, D, true, t_over_relaxation);
}

}  // namespace

// Static: after 30 relaxation times the response to q0 cos(k z) is q0 / (C1 + D kd^4) for three
// wavelengths around the bending length (D/C1)^(1/4) = 27 nm (lambda = 250, 167 and 125 nm:
// D kd^4 / C1 = 0.26, 1.3 and 4.2), within 0.3 % (the small load's nonlinearity, 2e-3 R0,
// and the ends' boundary layers, which the middle half leaves out). Without the bending the
// same loads give amplitudes 1.26 to 5.2 times larger: the test tells the two apart.
TEST(AxialBending, StaticSinusoidalLoadMeetsC1PlusDk4) {
  for (int m : {40, 60, 80}) {
    const ModeResponse r = mode_response(m, kD, 30.0);
    EXPECT_GT(r.stiffness_ratio, 1.2) << "m = " << m;
    EXPECT_NEAR(r.amplitude * r.stiffness_ratio, 1.0, 3e-3) << "m = " << m;
  }
}

// Dynamic: a sinusoidal load on the tube at rest relaxes at the rate (C1 + D kd^4) / eta, eta the
// lubrication and short-wave drag of that mode, so at t = 1 / lambda the response is (1 - 1/e)
// of its static value (within 2 %, as the traction's own test).
TEST(AxialBending, ShortWaveLoadRelaxesAtTheRateOfC1PlusDk4) {
  for (int m : {40, 80}) {
    const ModeResponse r = mode_response(m, kD, 1.0);
    const double expected = (1.0 - std::exp(-1.0)) / r.stiffness_ratio;
    EXPECT_NEAR(r.amplitude, expected, 0.02 * expected) << "m = " << m;
  }
}

// The wall row's bending term is the gradient of the discrete bending energy
// sum_i (D/2) ((R_{i+1} - 2 R_i + R_{i-1}) / h^2)^2 2 pi R0 h over the interior cells, per
// wall area: the residual (through the curvature unknowns and their rows) against central
// differences of ForceModel::wall_energy, on random radii, to 1e-6 of the largest term.
TEST(AxialBending, WallRowIsTheGradientOfTheBendingEnergy) {
  Params p;
  p.wave = WaveKind::ForceDriven;
  p.swimmer.short_wave_traction = true;
  p.wall.D_axial = kD;
  p.numerics.cells = 30;
  p.geometry.L = 0.4e-6;
  detail::validate(p);
  detail::ForceModel M(p);
  detail::ModelState s = M.make_state();
  detail::ProtocolMachine machine(p);
  machine.set_state(1, 0);  // recovery: no held segment
  std::vector<detail::ProtocolMachine::CellLaw> laws;
  std::vector<const detail::ActuationLaw*> seg;
  machine.laws(laws, seg);
  M.set_actuation(machine, laws, seg);
  const int N = M.N, S = M.stride;
  ASSERT_EQ(S, 3 + M.J + 1);
  const double R0 = p.geometry.R0, h = M.h;
  std::vector<double> R(N);
  for (int i = 0; i < N; ++i) R[i] = R0 * (0.8 + 0.15 * std::sin(1.7 * i) + 0.05 * std::cos(0.3 * i * i));
  std::vector<double> y(M.n, 0.0), yp(M.n, 0.0), F(M.n, 0.0);
  for (int i = 0; i < N; ++i) {
    const int k = 1 + S * i;
    y[k] = (R[i] / R0) * (R[i] / R0);
    if (i > 0 && i + 1 < N) y[k + M.ik] = (R[i + 1] - 2.0 * R[i] + R[i - 1]) / R0;  // the curvature rows hold
  }
  ASSERT_EQ(M.res(y.data(), yp.data(), F.data(), s), 0);
  const double cv = 1.0 / M.P_s;
  double largest = 0, worst = 0;
  std::vector<double> bend(N);
  for (int i = 0; i < N; ++i) {
    const int k = 1 + S * i;
    EXPECT_EQ(F[k + M.ik], 0.0) << i;
    // F_V = cv (C1 (R - R0) + q + T - p + B): V = p = phi = 0; q = the idle law's value
    bend[i] = F[k + 1] / cv - (p.wall.C1 * (R[i] - R0) + s.q[i]);
    largest = std::max(largest, std::abs(bend[i]));
  }
  ASSERT_GT(largest, 0.0);
  for (int i = 0; i < N; ++i) {
    const double inc = 1e-6 * R0;
    std::vector<double> Rp = R, Rm = R;
    Rp[i] += inc;
    Rm[i] -= inc;
    const double elastic = p.wall.C1 * (R[i] - R0);  // the linear law's own gradient, per area
    const double grad = (M.wall_energy(Rp.data()) - M.wall_energy(Rm.data())) / (2.0 * inc) / (2.0 * kPi * R0 * h);
    worst = std::max(worst, std::abs((grad - elastic) - bend[i]));
  }
  EXPECT_LT(worst, 1e-6 * largest);
}

// The Newton matrix with the curvature unknowns (band part and the low-rank segment and closure
// terms) against central differences of the residual, confined and unbounded, with and
// without the short-wave traction (without it the bending alone takes the IDA path), and with
// the calibrated end junction (confined): the end radii follow the cells beside them, and the
// junction's dissipation matrices and rim thrust follow the end radii.
TEST(AxialBending, AnalyticJacobianMatchesFiniteDifferences) {
  for (bool junction : {false, true})
  for (OuterFlow outer : {OuterFlow::Confined, OuterFlow::Unbounded})
    for (bool traction : {true, false}) {
      if (junction && outer != OuterFlow::Confined) continue;  // the junction belongs to the confined closure
      Params p;
      p.wave = WaveKind::ForceDriven;
      p.swimmer.outer = outer;
      p.swimmer.short_wave_traction = traction;
      p.swimmer.end_junction = junction;
      p.wall.D_axial = kD;
      p.numerics.cells = 37;
      const int n = p.protocol.segments;
      const int closure = outer == OuterFlow::Confined ? (junction ? 4 : 2) : 0;
      for (auto [phase, active] : {std::pair{0, 2}, std::pair{1, 0}})
        for (unsigned seed : {1u, 2u}) {
          const auto c = test::check_jacobian(p, phase, active, seed);
          EXPECT_LT(c.max_rel_error, 1e-6) << "junction=" << junction << " traction=" << traction << " phase=" << phase;
          const int held = phase == 0 ? n - 1 - active : 0;
          EXPECT_EQ(c.rank, held + closure);
        }
    }
}

// The paper's short tube (`paper_aspect_L0.2`, its own protocol, load and 1D model): a
// vanishing rigidity gives the local law's cycle within 5e-3 (measured 2.2e-3 in both the
// displacement and the cycle time: a bending wall's open ends follow the wall, straight through
// the last two cells, where the local law's ends take its static radius at once), and
// a rigidity of 5e-25 J (bending length 19 nm, against the protocol's 20 to 60 nm segments)
// lengthens the cycle by more than 10 % (measured +20 %). (With the paper's own wall, 1.0e-24 J,
// the round wall's first 20 nm segment no longer reaches R_f under 0.32 Pa: docs/reduced1d.md.)
TEST(AxialBending, VanishingRigidityGivesTheLocalLawsCycle) {
  const scene::json sc = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json");
  auto run = [&](const char* D) {
    scene::json s = sc;
    if (D) s["model1d"]["axial_bending"] = {{"source", "scene"}, {"rigidity", D}};
    scene::json resolved;
    const Params p = read_scene(s, resolved);
    const Result r = solve(p);
    if (r.failure) ADD_FAILURE() << r.failure->what();
    return metrics(p, r);
  };
  const auto local = run(nullptr), tiny = run("1e-32 J"), wall = run("5e-25 J");
  for (const auto* m : {&local, &tiny, &wall}) ASSERT_EQ(m->cycle_times_s.size(), 1u);
  const double d0 = local.displacement_m, T0 = local.cycle_times_s[0];
  EXPECT_NEAR(tiny.displacement_m / d0, 1.0, 5e-3);
  EXPECT_NEAR(tiny.cycle_times_s[0] / T0, 1.0, 5e-3);
  EXPECT_GT(wall.cycle_times_s[0] / T0, 1.1);
}

// A load beyond what the wall can hold at rest (q > C1 R0: a segment under the whole load has no
// static radius) still runs a bending wall's cycle when its segments reach R_f on the way: the
// protocol holds each segment there. The paper's R_f = 0.35 R0 tube under 0.8 Pa (C1 R0 about
// 0.5 Pa) with the round wall's bending: every segment reaches R_f, from the last to the first, and
// no cell closes (smallest radius measured 23 nm, 0.19 R0). R_f = 0.1 R0, whose segments' middles
// close before their mean reaches R_f, is refused at t = 0 (Extremes, docs/stability-1d.md).
TEST(AxialBending, ALoadTheWallCannotHoldAtRestRunsWhenTheSegmentsReachTheirTarget) {
  scene::json s = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_amplitude_0.35.json");
  s["protocol"].erase("load_factor");
  s["protocol"]["pressure"] = "0.8 Pa";
  s["model1d"]["axial_bending"] = {{"source", "scene"}, {"rigidity", "2.1e-24 J"}};
  scene::json resolved;
  const Params p = read_scene(s, resolved);
  ASSERT_GT(p.protocol.q, 1.4 * p.wall.C1 * p.geometry.R0);
  const Result r = solve(p);
  ASSERT_FALSE(r.failure) << r.failure->what();
  const auto m = metrics(p, r);
  ASSERT_EQ(m.cycle_times_s.size(), 1u);
  ASSERT_EQ(r.segment_reached.size(), std::size_t(p.protocol.segments));
  for (std::size_t k = 1; k < r.segment_reached.size(); ++k) {  // in the order reached
    EXPECT_GT(r.segment_reached[k - 1], 0.0);
    EXPECT_GT(r.segment_reached[k], r.segment_reached[k - 1]) << "event " << k;
  }
  EXPECT_GT(m.min_radius_m, 0.1 * p.geometry.R0);
  EXPECT_GT(m.displacement_per_cycle_m, 0.0);
}

// Scene guards: the term belongs to the force-free force-driven model; the calibration source
// needs a calibration file that holds the measured rigidity; a rigidity must be positive and
// is only read with source = "scene". Each refusal names its key.
TEST(AxialBending, SceneRefusesItWhereItDoesNotApply) {
  auto key_of = [](const scene::json& s) { return test::refusal_of(s).key; };
  const scene::json forced = {{"name", "b"}, {"wave", {{"kind", "force_driven"}}}};
  scene::json s = forced;
  s["model1d"] = {{"model", "paper"}, {"axial_bending", {{"source", "scene"}, {"rigidity", "1e-24 J"}}}};
  EXPECT_EQ(key_of(s), "model1d.axial_bending.source");
  s = {{"name", "b"}, {"wave", {{"kind", "step"}}}};
  s["model1d"] = {{"axial_bending", {{"source", "scene"}, {"rigidity", "1e-24 J"}}}};
  EXPECT_EQ(key_of(s), "model1d.axial_bending.source");
  s = forced;
  s["model1d"] = {{"axial_bending", {{"source", "calibration"}}}};
  EXPECT_EQ(key_of(s), "model1d.axial_bending.source");
  s = forced;
  s["model1d"] = {{"axial_bending", {{"source", "scene"}, {"rigidity", "-1e-24 J"}}}};
  EXPECT_EQ(key_of(s), "model1d.axial_bending.rigidity");
  s = forced;
  s["model1d"] = {{"axial_bending", {{"source", "scene"}}}};
  EXPECT_EQ(key_of(s), "model1d.axial_bending.rigidity");
  s = forced;
  s["model1d"] = {{"axial_bending", {{"source", "none"}, {"rigidity", "1e-24 J"}}}};
  EXPECT_EQ(key_of(s), "model1d.axial_bending.rigidity");
  s = forced;
  s["model1d"] = {{"axial_bending", {{"source", "scene"}, {"rigidity", "1e-24 J"}}}};
  EXPECT_EQ(key_of(s), "(accepted)");
}

// The calibration route: model1d.axial_bending.source = "calibration" reads the rigidity that
// swim calibrate measures on the 3D membrane (axial_bending_rigidity_J) from wall.calibration,
// bit for bit; a calibration file without it is refused naming wall.calibration.
TEST(AxialBending, TheCalibratedRigidityIsReadFromTheCalibrationFile) {
  const std::string dir = ::testing::TempDir();
  const std::string with = dir + "/cal_with_axial.json", without = dir + "/cal_without_axial.json";
  const double D = 2.0946135e-24;
  {
    std::ofstream(with) << scene::json{{"C1_Pa_per_m", 4.07e6}, {"hydraulic_offset_inner_m", 1e-8},
                                       {"hydraulic_offset_outer_m", 1e-8}, {"axial_bending_rigidity_J", D}}.dump();
    std::ofstream(without) << scene::json{{"C1_Pa_per_m", 4.07e6}, {"hydraulic_offset_inner_m", 1e-8},
                                          {"hydraulic_offset_outer_m", 1e-8}}.dump();
  }
  auto scene_for = [](const std::string& file) {
    return scene::json{{"name", "b"},
                       {"wall", {{"calibration", file}}},
                       {"wave", {{"kind", "force_driven"}}},
                       {"protocol", {{"load_factor", 1.5}}},
                       {"model1d", {{"axial_bending", {{"source", "calibration"}}}}}};
  };
  scene::json resolved;
  const Params p = read_scene(scene_for(with), resolved);
  EXPECT_EQ(p.wall.D_axial, D);
  EXPECT_EQ(p.wall.C1, 4.07e6);
  try {
    read_scene(scene_for(without), resolved);
    ADD_FAILURE() << "a calibration file without axial_bending_rigidity_J was accepted";
  } catch (const swim::InputError& e) {
    EXPECT_EQ(e.key(), "wall.calibration");
    EXPECT_NE(std::string(e.what()).find("axial_bending_rigidity_J"), std::string::npos) << e.what();
  }
}
