// The 3D error bars of a confirmation: read from the error_estimate a 3D run writes into its
// summary.json (validation/error_estimate.hpp, the structure swim run --error-estimate writes),
// and a pair of designs whose 3D values lie within their error bars counted tied, not misranked,
// by the confirmation report itself (design::confirm_candidates with the runs given). And the
// confirming tier (confirm.tier): the section, and the axisymmetric runs' reuse and resumption.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "axi/run_axi.hpp"
#include "axi/scene_axi.hpp"
#include "common/errors.hpp"
#include "design/confirm.hpp"
#include "validation/error_estimate.hpp"

using namespace swim::design;
using swim::scene::json;

namespace {

constexpr double kHFine = 1e-8, kHCoarse = 4.0 / 3.0 * 1e-8;  // r = 4/3

// A finished 3D run's summary with the figures the estimate reads, velocity v [m/s].
json run_summary(double v) {
  return {{"status", "ok"},
          {"mean_velocity_m_per_s", v},
          {"displacement_per_cycle_m", v * 0.5},
          {"cycle_time_s", 0.5},
          {"cycle_times_s", {0.5}},
          {"mean_velocity_per_cycle_m_per_s", v},
          {"wall_time_s", 1.0}};
}

// The fine run's summary with the error_estimate of its run and a coarse run of velocity vc,
// the sweep metric mean_velocity_m_per_s estimated too (as a confirmation run writes it).
json estimated(double v, double vc) {
  json s = run_summary(v);
  s["error_estimate"] =
      swim::validation::error_estimate_json(s, run_summary(vc), 9, kHFine, kHCoarse, {"mean_velocity_m_per_s"});
  return s;
}

// The largest distance from v to its extrapolations E_p, p in [0.5, 2]: |v - vc| / (r^0.5 - 1).
double expected_bar(double v, double vc) { return std::abs(v - vc) / (std::sqrt(4.0 / 3.0) - 1.0); }

Candidate candidate(std::size_t design, double v1d) {
  Candidate c;
  c.design = design;
  c.values = "design " + std::to_string(design);
  c.selected_as = "best";
  c.rank_in_sweep = long(design) + 1;
  c.scene = json::object();
  c.metrics.mean_velocity_m_per_s = v1d;
  return c;
}

// Three designs: 1D ranks them 0 > 1 > 2; 3D has 1 slightly above 0 (10.5 against 10 nm/s), 2 far below.
json report(const std::vector<json>& summaries, bool error_estimate) {
  const std::vector<Candidate> cands = {candidate(0, 3e-9), candidate(1, 2e-9), candidate(2, 1e-9)};
  ConfirmOptions o;
  o.metric = "mean_velocity_m_per_s";
  o.maximize = true;
  o.section = read_confirm_section(json{{"error_estimate", error_estimate}}, "confirm");
  o.runs_dir = testing::TempDir() + "/swim_confirm_error_bars/confirm-runs";
  o.run = [&](std::size_t i, const json&, const std::string&) {
    Confirmed c;
    c.summary = summaries[i];
    c.folder = o.runs_dir + "/design-" + std::to_string(i);
    c.reused = true;
    c.ok = true;
    c.cell_size_m = kHFine;
    return c;
  };
  return confirm_candidates(cands, o);
}

}  // namespace

TEST(ConfirmErrorBars, TheErrorBarIsTheDistanceToTheRunsOwnExtrapolationInterval) {
  const json s = estimated(10e-9, 9.9e-9);
  ASSERT_EQ(s["error_estimate"]["status"], "ok");
  const json bar = error_bar_of(s, "mean_velocity_m_per_s");
  ASSERT_TRUE(bar.is_number());
  EXPECT_NEAR(bar.get<double>(), expected_bar(10e-9, 9.9e-9), 1e-20);
  // the sweep metric mean_cycle_time_s is the estimate's cycle_time_s (both grids 0.5 s: no error)
  EXPECT_EQ(error_bar_of(s, "mean_cycle_time_s"), json(0.0));
  // no estimate, a failed estimate, a figure not estimated: no error bar
  EXPECT_TRUE(error_bar_of(run_summary(10e-9), "mean_velocity_m_per_s").is_null());
  json failed = run_summary(10e-9);
  failed["error_estimate"] = {{"status", "failed: the coarse run (9 cells across): no cycle completed"}};
  EXPECT_TRUE(error_bar_of(failed, "mean_velocity_m_per_s").is_null());
  EXPECT_TRUE(error_bar_of(s, "pumped_volume_m3").is_null());
}

TEST(ConfirmErrorBars, DesignsWithinTheirThreeDErrorBarsAreTiedNotMisranked) {
  // 3D: design 1 above design 0 by 0.5 nm/s; their error bars 0.65 and 0.32 nm/s reach across
  const std::vector<json> runs = {estimated(10e-9, 9.9e-9), estimated(10.5e-9, 10.45e-9), estimated(1e-9, 1e-9)};
  ASSERT_LT(0.5e-9, expected_bar(10e-9, 9.9e-9) + expected_bar(10.5e-9, 10.45e-9));
  const json r = report(runs, true);
  EXPECT_EQ(r["error_estimate_3d"], true);
  EXPECT_EQ(r["designs_with_error_bar_3d"], 3);
  EXPECT_NEAR(r["designs"][0]["error_bar_3d"].get<double>(), expected_bar(10e-9, 9.9e-9), 1e-20);
  EXPECT_EQ(r["designs"][0]["error_estimate_3d"]["figure"], "mean_velocity_m_per_s");
  const json& a = r["agreement"];
  EXPECT_EQ(a["pairs_tied_by_3d_error_bars"], 1);
  EXPECT_EQ(a["pairs_tied_in_3d"], 1);
  EXPECT_TRUE(a["misranked_pairs"].empty());
  EXPECT_TRUE(r["misranked_designs"].empty());
  // tau-b = (2 - 0) / sqrt(3 * 2): two concordant pairs, the third tied in 3D
  EXPECT_NEAR(a["kendall_tau"].get<double>(), 2.0 / std::sqrt(6.0), 1e-12);

  // the same runs with confirm.error_estimate false: no error bars, the pair is misranked
  const json off = report(runs, false);
  EXPECT_TRUE(off["designs"][0]["error_bar_3d"].is_null());
  EXPECT_EQ(off["designs"][0]["error_bar_3d_absent_because"], "confirm.error_estimate is false");
  EXPECT_EQ(off["agreement"]["pairs_tied_by_3d_error_bars"], 0);
  ASSERT_EQ(off["agreement"]["misranked_pairs"].size(), 1u);
  EXPECT_EQ(off["agreement"]["misranked_pairs"][0], json({"design 0", "design 1"}));
  EXPECT_NEAR(off["agreement"]["kendall_tau"].get<double>(), 1.0 / 3.0, 1e-12);

  // bars that reach across every pair: no order in 3D, so no Kendall tau (null, and why)
  const json all = report({estimated(10e-9, 9e-9), estimated(10.5e-9, 9.5e-9), estimated(1e-9, 0.5e-9)}, true);
  EXPECT_EQ(all["agreement"]["pairs_tied_by_3d_error_bars"], 3);
  EXPECT_TRUE(all["agreement"]["kendall_tau"].is_null());
  EXPECT_TRUE(all["agreement"]["kendall_tau_ci_95"].is_null());
  EXPECT_TRUE(all["agreement"]["kendall_tau_absent_because"].is_string());
  EXPECT_NE(confirm_markdown(all, "t").find("tau-b is 0/0"), std::string::npos);

  // bars that do not reach (a coarse grid close to the run's) leave the pair misranked
  const json tight = report({estimated(10e-9, 9.99e-9), estimated(10.5e-9, 10.49e-9), estimated(1e-9, 1e-9)}, true);
  EXPECT_EQ(tight["agreement"]["pairs_tied_by_3d_error_bars"], 0);
  EXPECT_EQ(tight["agreement"]["misranked_pairs"].size(), 1u);
}

TEST(ConfirmErrorBars, AFailedRunsPartialFiguresAreNotTheDesigns) {
  // a 3D run that failed part way writes the mean velocity up to its failure: the report
  // shows no 3D figure and no 1D/3D difference for it, and leaves it out of the ranks
  json failed = run_summary(37e-9);
  failed["status"] = "failed: numerical failure: the tube collapsed";
  const json f = figures_confirming(failed, "mean_velocity_m_per_s");
  for (const char* k : {"mean_velocity_m_per_s", "displacement_per_cycle_m", "cycle_time_s"})
    EXPECT_TRUE(f[k].is_null()) << k;
  EXPECT_EQ(figures_confirming(run_summary(37e-9), "mean_velocity_m_per_s")["mean_velocity_m_per_s"], 37e-9);
  const json r = report({run_summary(10e-9), failed, run_summary(1e-9)}, false);
  EXPECT_TRUE(r["designs"][1]["figures_3d"]["mean_velocity_m_per_s"].is_null());
  EXPECT_TRUE(r["designs"][1]["relative_difference_3d_vs_1d"]["mean_velocity_m_per_s"].is_null());
  EXPECT_EQ(r["agreement"]["designs"], 2);
}

TEST(ConfirmErrorBars, TheSectionTakesOnlyABooleanErrorEstimate) {
  EXPECT_EQ(wants_error_estimate(read_confirm_section(nullptr, "confirm")), kErrorEstimateDefault);
  EXPECT_FALSE(wants_error_estimate(read_confirm_section(json{{"error_estimate", false}}, "confirm")));
  try {
    read_confirm_section(json{{"error_estimate", "yes"}}, "confirm");
    FAIL() << "a string was accepted";
  } catch (const std::exception& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("confirm.error_estimate"), std::string::npos) << m;
    EXPECT_NE(m.find("\"yes\""), std::string::npos) << m;
    EXPECT_NE(m.find("true or false"), std::string::npos) << m;
  }
}

// confirm.tier: "3d" (the default) or "axi", the axisymmetric reference of a round wall, whose
// runs estimate their error on a coarser grid as the 3D ones do (the default); its prepared
// scene carries the grid and at most two threads in the axi section, a scene the axisymmetric
// tier cannot run is refused with its key, and so is a grid with no coarser one (8 cells).
TEST(ConfirmTier, TheSectionNamesTheTierAndTheAxisymmetricOneEstimatesItsErrorToo) {
  EXPECT_EQ(confirm_tier(read_confirm_section(nullptr, "confirm")), "3d");
  const json axi = read_confirm_section(json{{"tier", "axi"}, {"grid", {{"cells_across", 8}}}}, "confirm");
  EXPECT_EQ(confirm_tier(axi), "axi");
  EXPECT_EQ(tier_label("axi"), "axisymmetric");
  EXPECT_EQ(wants_error_estimate(axi), kErrorEstimateDefault);
  EXPECT_FALSE(wants_error_estimate(read_confirm_section(json{{"tier", "axi"}, {"error_estimate", false}}, "confirm")));
  EXPECT_TRUE(wants_error_estimate(read_confirm_section(json{{"tier", "axi"}, {"error_estimate", true}}, "confirm")));
  // the coarse grid: the even count nearest 3/4 of the run's, at least 8 and below it
  EXPECT_EQ(swim::validation::coarse_cells_across_axi(8), 0);
  EXPECT_EQ(swim::validation::coarse_cells_across_axi(10), 8);
  EXPECT_EQ(swim::validation::coarse_cells_across_axi(12), 8);
  EXPECT_EQ(swim::validation::coarse_cells_across_axi(16), 12);
  EXPECT_EQ(swim::validation::coarse_cells_across_axi(32), 24);
  EXPECT_EQ(swim::validation::coarse_cells_across_axi(40), 30);
  auto refused = [](const json& section, const std::string& key, const std::string& what) {
    try {
      read_confirm_section(section, "confirm");
      ADD_FAILURE() << section.dump() << " was accepted";
    } catch (const swim::InputError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused(json{{"tier", "2d"}}, "confirm.tier", "\"axi\"");

  json sc = swim::scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_amplitude_0.82.json");
  const json prepared = confirm_scene(sc, axi, 8);
  EXPECT_EQ(prepared["axi"]["grid"]["cells_across"], 8);
  EXPECT_EQ(prepared["axi"]["threads"], 2);
  EXPECT_FALSE(prepared.contains("full3d") && prepared["full3d"].contains("threads"));
  // the paper's wall may buckle: the axisymmetric tier refuses it, naming the key
  try {
    check_confirm_scene(prepared, axi);
    FAIL() << "a wall free to buckle was accepted on the axisymmetric tier";
  } catch (const swim::InputError& e) {
    EXPECT_EQ(e.key(), "full3d.membrane.axisymmetric") << e.what();
  }
  sc["full3d"]["membrane"]["axisymmetric"] = true;
  EXPECT_NO_THROW(check_confirm_scene(confirm_scene(sc, axi, 1), axi));
  // 8 cells across (the tier's least) has no coarser grid for the estimate: refused with its key
  try {
    check_error_estimate(confirm_scene(sc, axi, 1), axi, "confirm");
    FAIL() << "an estimate on 8 cells across was accepted";
  } catch (const swim::InputError& e) {
    EXPECT_EQ(e.key(), "confirm.error_estimate") << e.what();
    EXPECT_NE(std::string(e.what()).find("axi.grid.cells_across = 8"), std::string::npos) << e.what();
  }
  const json axi12 = read_confirm_section(json{{"tier", "axi"}, {"grid", {{"cells_across", 12}}}}, "confirm");
  EXPECT_NO_THROW(check_error_estimate(confirm_scene(sc, axi12, 1), axi12, "confirm"));
  const json off = read_confirm_section(json{{"tier", "axi"}, {"grid", {{"cells_across", 8}}}, {"error_estimate", false}}, "confirm");
  EXPECT_NO_THROW(check_error_estimate(confirm_scene(sc, off, 1), off, "confirm"));
}

// An axisymmetric confirmation run interrupted between two checkpoints (its folder holds a
// "running" summary and checkpoint.bin) is continued by the next confirmation, not run again, and
// gives the uninterrupted run's figures to the bit; a finished one is reused as it is.
TEST(ConfirmTier, AnInterruptedAxisymmetricRunIsContinuedFromItsCheckpoint) {
  json sc = swim::scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_amplitude_0.82.json");
  sc["full3d"]["membrane"]["axisymmetric"] = true;
  sc["full3d"]["recovery_end"] = "shape";
  sc["axi"]["checkpoint_interval"] = "10 ms";
  sc["time"]["duration"] = "60 ms";
  const json section = read_confirm_section(json{{"tier", "axi"}, {"grid", {{"cells_across", 8}}}}, "confirm");
  const json prepared = confirm_scene(sc, section, 1);
  const auto root = std::filesystem::temp_directory_path() / ("swim_confirm_axi_resume_" + std::to_string(::getpid()));
  std::filesystem::remove_all(root);
  const Confirmed whole = run_confirmed(prepared, (root / "a").string(), "design-0", 0, false, "", "axi");
  ASSERT_TRUE(whole.ok) << whole.summary.dump();
  EXPECT_FALSE(whole.reused);
  // the same run in the other runs folder, stopped half way by the tier's own control
  const std::filesystem::path dir = root / "b" / std::filesystem::path(whole.folder).filename();
  std::filesystem::create_directories(dir);
  json resolved;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(prepared, resolved);
  swim::axi::RunControlAxi stop;
  stop.progress = 0;
  stop.stop_after_steps = whole.summary["steps"].get<long>() / 2;
  ASSERT_TRUE(swim::axi::run_axi(p, resolved, dir.string(), stop).interrupted);
  ASSERT_TRUE(std::filesystem::exists(dir / "checkpoint.bin"));
  // a file of the interrupted folder's: a run made afresh clears the folder, a continued one does not
  std::ofstream(dir / "left_by_the_interrupted_run") << "x";
  const Confirmed resumed = run_confirmed(prepared, (root / "b").string(), "design-0", 0, false, "", "axi");
  EXPECT_EQ(resumed.folder, dir.string());
  EXPECT_FALSE(resumed.reused);
  EXPECT_TRUE(std::filesystem::exists(dir / "left_by_the_interrupted_run")) << "run again instead of continued";
  ASSERT_TRUE(resumed.ok) << resumed.summary.dump();
  EXPECT_EQ(resumed.summary["steps"], whole.summary["steps"]);
  EXPECT_EQ(resumed.summary["displacement_m"], whole.summary["displacement_m"]);
  EXPECT_NE(whole.summary["displacement_m"].get<double>(), 0.0);
  const Confirmed again = run_confirmed(prepared, (root / "b").string(), "design-0", 0, false, "", "axi");
  EXPECT_TRUE(again.reused);
  EXPECT_EQ(again.summary["displacement_m"], whole.summary["displacement_m"]);
  std::filesystem::remove_all(root);
}
