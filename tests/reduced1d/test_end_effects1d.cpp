// The open ends' flow of the confined force-free model on the 1D tier (`model1d.end_effects`,
// docs/outer-flow-1d.md §2b, §2c): the correction's limit on long tubes, the junction on a
// force-driven cycle and the scene key's refusals.
// (The closed form of the towed tube, mirror symmetry and the scallop theorem with the ends on:
// test_outer_flow.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "common/scene.hpp"
#include "reduced1d/outer_flow.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"
#include "scene_refusal.hpp"

using namespace swim::reduced1d::outer;
using swim::scene::json;

namespace {

/// Displacement over one transit of a prescribed wave on the 1D tier (confined force-free model).
double transit_displacement(const std::string& kind, double L_um, double lambda_um, const std::string& ends) {
  auto um = [](double v) { return std::to_string(v) + " um"; };
  json sc = {{"name", "ends"},
             {"swimmer", {{"radius", "0.125 um"}, {"length", um(L_um)}}},
             {"container", {{"kind", "cylinder"}, {"radius", "0.25 um"}, {"period", um(5 * L_um)}}},
             {"wave", {{"kind", kind}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}}},
             {"model1d", {{"end_effects", ends}}},
             {"numerics1d", {{"cells", 400}}}};
  if (kind == "step") sc["wave"]["width"] = um(lambda_um);
  if (kind == "sine") sc["wave"]["wavelength"] = um(lambda_um);
  json resolved;
  const auto r = swim::reduced1d::solve(swim::reduced1d::read_scene(sc, resolved));
  EXPECT_FALSE(r.failure.has_value());
  return r.series.back().X;
}

}  // namespace

/// The relative change of the displacement per transit that the end model `ends` makes at a
/// fixed wave shape (a sine of wavelength 0.4 um, a whole number of wavelengths on the tube), for
/// L = 0.8, 1.6, 3.2 and 6.4 um.
static std::vector<double> relative_changes(const std::string& ends) {
  std::vector<double> rel;
  for (double L : {0.8, 1.6, 3.2, 6.4}) {
    const double off = transit_displacement("sine", L, 0.4, "none");
    const double on = transit_displacement("sine", L, 0.4, ends);
    rel.push_back(on / off - 1.0);
    std::printf("%s, L = %.1f um (L/Rc = %.1f): displacement %.4e -> %.4e m, relative change %+.4f, times L/Rc %.3f\n",
                ends.c_str(), L, L / 0.25, off, on, rel.back(), rel.back() * L / 0.25);
  }
  return rel;
}

// The correction is an end effect: at a fixed wave shape its relative change of the
// displacement per transit falls as 1/L, halving with each doubling of the tube, and vanishes as
// L/Rc grows.
TEST(EndEffects, CorrectionVanishesAsOneOverTheTubeLength) {
  const std::vector<double> rel = relative_changes("open_ends");
  for (std::size_t k = 0; k < rel.size(); ++k) {
    EXPECT_GT(std::abs(rel[k]), 0.0);
    if (k > 0) {
      EXPECT_GT(rel[k] / rel[k - 1], 0.4) << "L doubling " << k;
      EXPECT_LT(rel[k] / rel[k - 1], 0.6) << "L doubling " << k;
    }
  }
  EXPECT_LT(std::abs(rel.back()), 0.02);
}

// The calibrated junction (§2c) is an end effect too, and it adds thrust: its relative change is
// positive and halves with each doubling of the tube from L = 1.6 um on.
TEST(EndEffects, JunctionCorrectionVanishesAsOneOverTheTubeLength) {
  const std::vector<double> rel = relative_changes("junction");
  for (std::size_t k = 0; k < rel.size(); ++k) {
    EXPECT_GT(rel[k], 0.0) << "the junction adds the thrust lubrication misses at the ends";
    if (k >= 2) {
      EXPECT_GT(rel[k] / rel[k - 1], 0.4) << "L doubling " << k;
      EXPECT_LT(rel[k] / rel[k - 1], 0.6) << "L doubling " << k;
    }
  }
  EXPECT_LT(rel.back(), 0.05);
}

// The scene key: a value outside the choice names the key and the allowed values; the ends
// are refused with the unbounded outer flow and the paper's model, and a force-driven wave takes
// the calibrated junction only.
TEST(EndEffects, SceneKeyRefusesBadValuesAndOtherModels) {
  auto scene = [](json model1d, std::string wave) {
    json sc = {{"name", "ends"},
               {"swimmer", {{"radius", "0.125 um"}, {"length", "0.4 um"}}},
               {"container", {{"kind", "cylinder"}, {"radius", "0.25 um"}, {"period", "2 um"}}},
               {"model1d", model1d}};
    if (wave != "force_driven")
      sc["wave"] = {{"kind", wave}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}, {"width", "0.05 um"}};
    return sc;
  };
  auto message = [](const json& sc) { return swim::reduced1d::test::refusal_of(sc).message; };
  const std::string bad = message(scene({{"end_effects", "sampson"}}, "step"));
  EXPECT_NE(bad.find("model1d.end_effects"), std::string::npos) << bad;
  EXPECT_NE(bad.find("sampson"), std::string::npos) << bad;
  EXPECT_NE(bad.find("open_ends"), std::string::npos) << bad;
  const std::string forced = message(scene({{"end_effects", "open_ends"}}, "force_driven"));
  EXPECT_NE(forced.find("model1d.end_effects"), std::string::npos) << forced;
  const std::string unbounded = message(scene({{"end_effects", "open_ends"}, {"outer_flow", "unbounded"}}, "step"));
  EXPECT_NE(unbounded.find("model1d.end_effects"), std::string::npos) << unbounded;
  EXPECT_EQ(message(scene({{"end_effects", "open_ends"}}, "step")), "");
  json resolved;
  const auto p = swim::reduced1d::read_scene(scene({{"end_effects", "open_ends"}}, "step"), resolved);
  EXPECT_EQ(p.swimmer.end_lumen, kOpenEnds.lumen);
  EXPECT_EQ(p.swimmer.end_annulus, kOpenEnds.annulus);
  EXPECT_EQ(resolved["model1d"]["end_effects"], "open_ends");
  EXPECT_FALSE(p.swimmer.end_junction);
  // the calibrated junction: the confined force-free model, prescribed or force-driven, and the
  // choice is echoed
  EXPECT_NE(forced.find("junction"), std::string::npos) << "names the force-driven wave's choice: " << forced;
  EXPECT_EQ(message(scene({{"end_effects", "junction"}}, "force_driven")), "");
  for (const json& other : {json{{"end_effects", "junction"}, {"outer_flow", "unbounded"}},
                            json{{"end_effects", "junction"}, {"model", "paper"}}}) {
    const std::string msg = message(scene(other, "force_driven"));
    EXPECT_NE(msg.find("model1d.end_effects"), std::string::npos) << other.dump() << ": " << msg;
  }
  EXPECT_NE(bad.find("junction"), std::string::npos) << bad;
  json resolved_j;
  const auto pj = swim::reduced1d::read_scene(scene({{"end_effects", "junction"}}, "step"), resolved_j);
  EXPECT_TRUE(pj.swimmer.end_junction);
  EXPECT_EQ(pj.swimmer.end_lumen, 0.0);
  EXPECT_EQ(resolved_j["model1d"]["end_effects"], "junction");
}

// The calibrated junction on a force-driven cycle (the demo scene, short-wave traction on, and
// without it): the cycle completes and the displacement per cycle
// differs from the plain junction's (measured at 50 cells: 45.0 nm plain, 69.8 nm with the junction).
TEST(EndEffects, JunctionRunsTheForceDrivenCycle) {
  for (bool traction : {true, false}) {
    double X[2];
    for (int k = 0; k < 2; ++k) {
      json sc = swim::scene::load_file(std::string(SWIM_SOURCE_DIR) + "/data/scenes/demo.json");
      sc["model1d"]["end_effects"] = k == 0 ? "none" : "junction";
      sc["model1d"]["short_wave_traction"] = traction;
      json resolved;
      const auto p = swim::reduced1d::read_scene(sc, resolved);
      EXPECT_EQ(p.swimmer.end_junction, k == 1);
      const auto r = swim::reduced1d::solve(p);
      ASSERT_FALSE(r.failure.has_value()) << "traction " << traction << " ends " << k;
      const auto m = swim::reduced1d::metrics(p, r);
      ASSERT_EQ(m.cycle_times_s.size(), 1u) << "traction " << traction << " ends " << k;
      X[k] = m.displacement_m;
      std::printf("traction %d, %s: %.3f nm per cycle, cycle %.4f s\n", int(traction), k ? "junction" : "plain",
                  X[k] * 1e9, m.cycle_times_s[0]);
    }
    EXPECT_GT(X[0], 0.0);
    EXPECT_GT(std::abs(X[1] / X[0] - 1.0), 0.05) << "the junction changes the displacement per cycle";
  }
}

// A force-driven wave pinches a held end to 0.09 R0 (paper_amplitude_0.35: Rc/R = 22, outside
// the junction's fit): the force-driven closure holds the junction's radius to the fitted range,
// and the cycle stays a Stokes swimmer's (measured: 124.7 nm per cycle against 81.9 nm with the
// plain junction; at the pinched radius itself 1.46 um, more than the tube's length).
TEST(EndEffects, JunctionHoldsAPinchedForceDrivenEndToTheFittedRange) {
  json sc = swim::scene::load_file(std::string(SWIM_SOURCE_DIR) + "/data/scenes/paper_amplitude_0.35.json");
  sc["model1d"]["end_effects"] = "junction";
  json resolved;
  const auto p = swim::reduced1d::read_scene(sc, resolved);
  const auto r = swim::reduced1d::solve(p);
  ASSERT_FALSE(r.failure.has_value());
  const auto m = swim::reduced1d::metrics(p, r);
  ASSERT_EQ(m.cycle_times_s.size(), 1u);
  std::printf("paper_amplitude_0.35 with the junction: %.2f nm per cycle, cycle %.4f s\n", m.displacement_m * 1e9,
              m.cycle_times_s[0]);
  EXPECT_GT(m.displacement_m, 0.0);
  EXPECT_LT(m.displacement_m, 0.5 * p.geometry.L);
}
