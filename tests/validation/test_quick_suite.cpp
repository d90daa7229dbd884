// The quick validation suite end to end (swim validate --quick, without the figures): three
// coarse 3D grids of the small duct scene, the calibration, every 1D model, the report; the
// cache of runs (other output settings, an older resolution, an interrupted run).
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "common/output.hpp"
#include "common/scene.hpp"

#include "full3d/run3d.hpp"
#include "full3d/scene3d.hpp"
#include "validation/suite.hpp"

using namespace swim;
namespace fs = std::filesystem;

TEST(QuickSuite, ReportHoldsEveryMetricAndResumesFromItsCache) {
  const std::string out = testing::TempDir() + "/swim_quick_suite_" + std::to_string(::getpid());
  fs::remove_all(out);
  fs::create_directories(out);
  validation::SuiteOptions o;
  o.suite = SWIM_SOURCE_DIR "/data/validation/quick.json";
  o.out_dir = out;
  o.data_dir = SWIM_SOURCE_DIR "/data";
  o.threads = 1;
  const scene::json r = validation::run_suite(o);
  ASSERT_EQ(r["cases"].size(), 1u);
  const scene::json& c = r["cases"][0];
  // every 3D grid completes its cycle and moves the swimmer forwards
  ASSERT_EQ(c["runs3d"].size(), 3u);
  for (const auto& run : c["runs3d"]) {
    EXPECT_EQ(run["status"], "ok");
    EXPECT_GT(run["displacement_per_cycle_m"].get<double>(), 0.0);
    EXPECT_FALSE(run["cached"].get<bool>());
  }
  ASSERT_TRUE(c["reference3d"].contains("displacement_per_cycle_m"));
  // calibration at the finest grid: C1 within 2 % of the spring network, offsets about a cell
  const scene::json& cal = c["calibration"];
  ASSERT_TRUE(cal.contains("C1_Pa_per_m")) << cal.dump();
  EXPECT_NEAR(cal["C1_Pa_per_m"].get<double>() / cal["C1_spring_network_Pa_per_m"].get<double>(), 1.0, 0.02);
  const double h = c["runs3d"][2]["cell_size_m"];
  EXPECT_GT(cal["hydraulic_offset_inner_m"].get<double>(), 0.3 * h);
  EXPECT_LT(cal["hydraulic_offset_inner_m"].get<double>(), 2.0 * h);
  // the towed tube's drag gives a second a_out, of order the cell too
  ASSERT_TRUE(cal.contains("towed_drag_coefficient_N_s_per_m")) << cal.dump();
  EXPECT_GT(cal["towed_drag_coefficient_N_s_per_m"].get<double>(), 0.0);
  ASSERT_TRUE(cal["hydraulic_offset_outer_from_drag_m"].is_number()) << cal.dump();
  EXPECT_GT(cal["hydraulic_offset_outer_from_drag_m"].get<double>(), 0.3 * h);
  EXPECT_LT(cal["hydraulic_offset_outer_from_drag_m"].get<double>(), 2.0 * h);
  // every model of the suite ran and carries its verdicts
  ASSERT_EQ(c["models1d"].size(), 4u);
  for (const auto& m : c["models1d"]) {
    EXPECT_EQ(m["status"], "ok") << m["label"];
    ASSERT_TRUE(m.contains("verdicts")) << m["label"];
    for (const auto& [k, v] : m["verdicts"].items())
      EXPECT_TRUE(v == "pass" || v == "fail" || v == "inconclusive") << k << ": " << v;
  }
  // the report's phase table: the force-free models and the finest 3D run carry the protocol's
  // phases (each segment's contraction and the recovery), whose times sum to the cycle time and
  // whose distances sum to the displacement per cycle
  for (const scene::json* m : {&c["models1d"][0], &c["runs3d"].back()}) {
    ASSERT_TRUE(m->contains("cycle_phase_times_s") && m->contains("cycle_phase_displacements_m")) << m->dump();
    const auto& pt = (*m)["cycle_phase_times_s"];
    const auto& pd = (*m)["cycle_phase_displacements_m"];
    ASSERT_EQ(pt.size(), pd.size());
    EXPECT_GE(pt.size(), 3u);
    double T = 0, d = 0;
    for (std::size_t k = 0; k < pt.size(); ++k) {
      EXPECT_GT(pt[k].get<double>(), 0.0) << k;
      T += pt[k].get<double>();
      d += pd[k].get<double>();
    }
    EXPECT_NEAR(T, (*m)["cycle_time_s"].get<double>(), 1e-9 * T);
    EXPECT_NEAR(d, (*m)["displacement_per_cycle_m"].get<double>(), 1e-6 * std::abs(d));
  }
  // the default model (the first) carries its grid error, from its run on twice its cells: the
  // error bar of its figures in the trend claims; a small fraction of each figure on 100 cells
  {
    const auto& g = c["models1d"][0]["grid_error"];
    ASSERT_EQ(g.value("status", ""), "ok") << g.dump();
    EXPECT_EQ(g["cells"], 100);
    EXPECT_EQ(g["refined_cells"], 200);
    for (const char* k : {"displacement_per_cycle_m", "cycle_time_s", "mean_velocity_per_cycle_m_per_s"}) {
      const double e = g[k].get<double>(), v = c["models1d"][0][k].get<double>();
      EXPECT_GE(e, 0.0) << k;
      EXPECT_LT(e, 0.05 * std::abs(v)) << k;
    }
    for (std::size_t i = 1; i < c["models1d"].size(); ++i) EXPECT_FALSE(c["models1d"][i].contains("grid_error")) << i;
  }
  // the force-free models swim the way 3D does; the paper's reproduction overestimates the
  // displacement by orders of magnitude (its thrust has no opposing force but wall inertia)
  const double ref = c["reference3d"]["displacement_per_cycle_m"]["value"];
  EXPECT_GT(c["models1d"][0]["displacement_per_cycle_m"].get<double>(), 0.0);
  EXPECT_GT(c["models1d"][1]["displacement_per_cycle_m"].get<double>(), 0.0);
  EXPECT_GT(c["models1d"][3]["displacement_per_cycle_m"].get<double>(), 100.0 * ref);
  // speed/accuracy: 1D at three cell counts and three tolerances, 3D at three grids and two
  // time steps
  std::map<std::string, int> per_axis;
  for (const auto& q : c["speed_accuracy"]) ++per_axis[q["tier"].get<std::string>() + " " + q["axis"].get<std::string>()];
  EXPECT_EQ(per_axis["1d cells"], 3);
  EXPECT_EQ(per_axis["1d rtol"], 3);
  EXPECT_EQ(per_axis["3d h"], 3);
  EXPECT_EQ(per_axis["3d time step"], 2);
  // the 1D result is converged in the integrator tolerance: rtol 1e-6 and 1e-8 give the same
  // displacement per cycle to 0.1 % of the reference (the model error is what remains)
  std::map<std::string, double> err;
  for (const auto& q : c["speed_accuracy"])
    if (q["axis"] == "rtol") err[q["resolution"].get<std::string>()] = q["displacement_per_cycle_error"].get<double>();
  ASSERT_TRUE(err.count("rtol = 1e-06") && err.count("rtol = 1e-08"));
  EXPECT_LT(std::abs(err["rtol = 1e-06"] - err["rtol = 1e-08"]), 1e-3);
  EXPECT_GT(c["wall_time_ratio_3d_over_1d"].get<double>(), 10.0);
  // five claims, the four trends again on the 1D tier, the 1D agreement one per figure (four
  // rows); each with a status and its rule
  ASSERT_EQ(r["findings"].size(), 13u);
  for (const auto& f : r["findings"]) {
    EXPECT_TRUE(f["status"] == "reproduced" || f["status"] == "refuted" || f["status"] == "inconclusive" ||
                f["status"] == "not assessed")
        << f.dump();
    EXPECT_FALSE(f["rule"].get<std::string>().empty());
  }
  EXPECT_EQ(r.dump().find("NaN"), std::string::npos);
  // 3D at the extremes: each case ends as the suite states (a step beyond the stability limit
  // and a stiff wall stop naming full3d.dt; a container too tight for the grid is refused)
  ASSERT_EQ(r["extremes3d"].size(), 3u);
  for (const auto& e : r["extremes3d"]) EXPECT_TRUE(e["as_expected"].get<bool>()) << e.dump();
  EXPECT_EQ(r["extremes3d"][2]["outcome"], "rejected");

  // a second run reuses every 3D run and the calibration, with identical figures
  const scene::json r2 = validation::run_suite(o);
  const scene::json& c2 = r2["cases"][0];
  for (std::size_t g = 0; g < 3; ++g) {
    EXPECT_TRUE(c2["runs3d"][g]["cached"].get<bool>());
    EXPECT_EQ(c2["runs3d"][g]["displacement_per_cycle_m"], c["runs3d"][g]["displacement_per_cycle_m"]);
  }
  EXPECT_EQ(c2["calibration"]["C1_Pa_per_m"], cal["C1_Pa_per_m"]);
  EXPECT_EQ(c2["models1d"][0]["displacement_per_cycle_m"], c["models1d"][0]["displacement_per_cycle_m"]);

  // other output settings do not change the physics: the cached 3D runs are found again
  scene::json suite = scene::load_file(o.suite);
  suite["cases"][0]["set"]["full3d.output.vtk_interval"] = "5 ms";
  suite["cases"][0]["scene"] = SWIM_SOURCE_DIR "/data/scenes/tiny_3d_cycle.json";
  const std::string edited = out + "/suite_other_output.json";
  std::ofstream(edited) << suite.dump(2);
  o.suite = edited;
  const scene::json r3 = validation::run_suite(o);
  for (std::size_t g = 0; g < 3; ++g) EXPECT_TRUE(r3["cases"][0]["runs3d"][g]["cached"].get<bool>()) << g;

  // a run folder written before the scene reader gained a key (here the round-wall switch,
  // whose default leaves the physics as it was), under another folder name, is still found
  {
    const fs::path folder = c["runs3d"][1]["folder"].get<std::string>();
    scene::json older = scene::load_file((folder / "scene.resolved.json").string());
    ASSERT_TRUE(older["full3d"]["membrane"].contains("axisymmetric"));
    older["full3d"]["membrane"].erase("axisymmetric");
    std::ofstream(folder / "scene.resolved.json") << older.dump(2);
    // as that older run listed it: its size and checksum in summary.json, whose own checksum follows
    std::ifstream in(folder / "summary.json");
    scene::json summary = scene::json::parse(in);
    for (auto& f : summary["files"])
      if (f["name"] == "scene.resolved.json") {
        f["bytes"] = fs::file_size(folder / "scene.resolved.json");
        f["fnv1a64"] = output::file_checksum((folder / "scene.resolved.json").string());
      }
    std::ofstream(folder / "summary.json") << output::json_text_with_checksum(summary);
    fs::rename(folder, folder.string() + "-older");
  }
  // a run stopped part way (the suite interrupted) continues from its checkpoint and ends
  // where the uninterrupted run ended
  const std::string stopped = c["runs3d"][0]["folder"].get<std::string>();
  {
    // the scene the edited suite runs on the first grid, as the suite builds it (the output
    // settings are part of what a checkpoint resumes)
    scene::json sc = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/tiny_3d_cycle.json"), again;
    for (const auto& [k, v] : suite["cases"][0]["set"].items()) scene::apply_override(sc, k + "=" + v.dump());
    scene::apply_override(sc, "full3d.grid=" + suite["cases"][0]["grids"][0].dump());
    for (const char* set : {"full3d.threads=1", "full3d.output.vtk=false", "full3d.output.fluid_fields=false"})
      scene::apply_override(sc, set);
    const full3d::Params3d p = full3d::read_scene3d(sc, again);
    fs::remove_all(stopped);
    fs::create_directories(stopped);
    full3d::RunControl ctl;
    ctl.progress = 0;
    ctl.quiet_vtk = true;
    ctl.stop_after_steps = c["runs3d"][0]["steps"].get<long>() / 2;
    const full3d::RunOutcome part = full3d::run3d(p, again, stopped, ctl);
    ASSERT_TRUE(part.interrupted);
    ASSERT_TRUE(fs::exists(stopped + "/checkpoint.bin"));
  }
  const scene::json r4 = validation::run_suite(o);
  const scene::json& c4 = r4["cases"][0];
  EXPECT_FALSE(c4["runs3d"][0]["cached"].get<bool>());
  EXPECT_EQ(c4["runs3d"][0]["folder"], stopped);
  EXPECT_EQ(c4["runs3d"][0]["displacement_per_cycle_m"], c["runs3d"][0]["displacement_per_cycle_m"]);
  EXPECT_EQ(c4["runs3d"][0]["cycle_time_s"], c["runs3d"][0]["cycle_time_s"]);
  EXPECT_TRUE(c4["runs3d"][1]["cached"].get<bool>());
  EXPECT_EQ(c4["runs3d"][1]["folder"], c["runs3d"][1]["folder"].get<std::string>() + "-older");
  EXPECT_EQ(c4["runs3d"][1]["displacement_per_cycle_m"], c["runs3d"][1]["displacement_per_cycle_m"]);
  EXPECT_EQ(r4["cache"]["rejected"], 0) << r4["cache"].dump();
  EXPECT_TRUE(r4["cache"]["verified"].get<bool>());

  // nothing cached is used unverified: a changed digit in a cached run's series.csv and in the
  // cached calibration's C1 are found, reported with the file and the reason, and recomputed; the
  // figures are those of the first suite
  auto change_digit = [](const fs::path& p, const std::string& near) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string t = ss.str();
    std::size_t at = t.find(near);
    ASSERT_NE(at, std::string::npos) << p << " " << near;
    at = t.find_first_of("123456789", at + near.size());
    t[at] = t[at] == '9' ? '8' : char(t[at] + 1);
    std::ofstream(p, std::ios::binary) << t;
  };
  change_digit(fs::path(stopped) / "series.csv", "\n");
  change_digit(c4["calibration"]["file"].get<std::string>(), "\"C1_Pa_per_m\"");
  const scene::json r5 = validation::run_suite(o);
  const scene::json& c5 = r5["cases"][0];
  ASSERT_EQ(r5["cache"]["rejected"], 2) << r5["cache"].dump();
  std::string reasons;
  for (const auto& j : r5["cache"]["rejections"]) reasons += j["reason"].get<std::string>() + "\n";
  EXPECT_NE(reasons.find("series.csv: changed"), std::string::npos) << reasons;
  EXPECT_NE(reasons.find("calibration.json: changed or cut after it was written"), std::string::npos) << reasons;
  EXPECT_TRUE(r5["cache"]["verified"].get<bool>());
  EXPECT_FALSE(c5["runs3d"][0]["cached"].get<bool>());
  EXPECT_EQ(c5["runs3d"][0]["displacement_per_cycle_m"], c["runs3d"][0]["displacement_per_cycle_m"]);
  EXPECT_EQ(c5["calibration"]["C1_Pa_per_m"], cal["C1_Pa_per_m"]);
  EXPECT_EQ(c5["models1d"][0]["displacement_per_cycle_m"], c["models1d"][0]["displacement_per_cycle_m"]);

  // through the command line: a damaged cached run and calibration are rejected, named,
  // recomputed, and the command exits 0 with a report whose figures are those of the first
  // suite; with --progress it says which stage and run it is in, each recomputed run's and the
  // calibration's own progress, and the time left in the stage
  change_digit(fs::path(stopped) / "series.csv", "\n");
  change_digit(c5["calibration"]["file"].get<std::string>(), "\"C1_Pa_per_m\"");
  const std::string log = out + "/validate.txt";
  const std::string cmd = std::string("\"") + SWIM_BINARY_DIR + "/bin/swim\" validate \"" + o.suite + "\" --out \"" + out +
                          "\" --threads 1 --progress > \"" + log + "\" 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  std::stringstream printed;
  printed << in.rdbuf();
  const std::string text = printed.str();
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << text;
  EXPECT_NE(text.find("2 rejected and recomputed"), std::string::npos) << text;
  EXPECT_NE(text.find("series.csv: changed"), std::string::npos) << text;
  // the stage and the run: case, grid and its value
  EXPECT_NE(text.find("validate: case 1/1"), std::string::npos) << text;
  EXPECT_NE(text.find(": 3D grid 1/3 (full3d.grid = {\"cells_across\":12})"), std::string::npos) << text;
  // the recomputed run's own progress (its label names the scene), then the stage's time left
  // estimated from it before the next grid
  const std::size_t run_done = text.find("3d tiny_3d_cycle");
  ASSERT_NE(run_done, std::string::npos) << text;
  EXPECT_NE(text.find(": done in ", run_done), std::string::npos) << text;
  EXPECT_NE(text.find("3d tiny_3d_cycle (auto: until 1 cycle, progress against full3d.time_limit)"), std::string::npos)
      << text;
  const std::size_t grid2 = text.find(": 3D grid 2/3 (");
  ASSERT_NE(grid2, std::string::npos) << text;
  EXPECT_GT(grid2, run_done) << text;
  EXPECT_NE(text.substr(grid2, text.find('\n', grid2) - grid2).find(" s left in this stage (so far "), std::string::npos)
      << text;
  // the calibration's own progress: its loads, the hydraulic radii, the towed tube, time left
  const std::size_t cal_at = text.find("calibration at grid 3");
  ASSERT_NE(cal_at, std::string::npos) << text;
  EXPECT_NE(text.find("calibration tiny_3d_cycle: ", cal_at), std::string::npos) << text;
  EXPECT_NE(text.find("load 1/", cal_at), std::string::npos) << text;
  EXPECT_NE(text.find("hydraulic radii  ~", cal_at), std::string::npos) << text;
  EXPECT_NE(text.find("s left", cal_at), std::string::npos) << text;
  std::ifstream rin(out + "/report.json");
  const scene::json r6 = scene::json::parse(rin);
  EXPECT_EQ(r6["cache"]["rejected"], 2) << r6["cache"].dump();
  EXPECT_EQ(r6["cases"][0]["runs3d"][0]["displacement_per_cycle_m"], c["runs3d"][0]["displacement_per_cycle_m"]);
  EXPECT_EQ(r6["cases"][0]["calibration"]["C1_Pa_per_m"], cal["C1_Pa_per_m"]);
}
