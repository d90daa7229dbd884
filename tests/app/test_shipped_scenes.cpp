// Drivers double as tests: every shipped scene runs (coarsened) to completion on the 1D
// tier, and the executable writes the contract's output files with finite values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <fstream>

#include "common/output.hpp"
#include "common/scene.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"

namespace fs = std::filesystem;
using swim::scene::json;

namespace {
std::vector<fs::path> shipped() {
  std::vector<fs::path> v;
  for (const auto& e : fs::directory_iterator(SWIM_SOURCE_DIR "/data/scenes"))
    if (e.path().extension() == ".json") v.push_back(e.path());
  std::sort(v.begin(), v.end());
  return v;
}
int run(const std::string& args) {
  const int s = std::system((std::string("\"") + SWIM_BINARY_DIR + "/bin/swim\" " + args + " > /dev/null 2>&1").c_str());
  return WIFEXITED(s) ? WEXITSTATUS(s) : -1;
}
}  // namespace

TEST(ShippedScenes, EveryConfigurationOfThePaperIsShipped) {
  std::vector<std::string> names;
  for (const auto& p : shipped()) names.push_back(p.stem().string());
  for (const char* n : {"demo", "paper_aspect_L0.2", "paper_aspect_L0.4", "paper_aspect_L0.8", "paper_amplitude_0.35",
                        "paper_amplitude_0.55", "paper_amplitude_0.82", "paper_slender", "paper_optimal_multicycle"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
}

TEST(ShippedScenes, EachRunsToCompletionOnTheCoarse1DTier) {
  for (const auto& path : shipped()) {
    SCOPED_TRACE(path.filename().string());
    json sc = swim::scene::load_file(path.string());
    swim::scene::apply_override(sc, "numerics1d.cells=60");
    json resolved;
    const auto p = swim::reduced1d::read_scene(sc, resolved, path.parent_path().string());
    const auto r = swim::reduced1d::solve(p);
    ASSERT_FALSE(r.failure) << r.failure->what();
    const auto m = swim::reduced1d::metrics(p, r);
    EXPECT_TRUE(std::isfinite(m.displacement_m));
    EXPECT_GT(m.displacement_m, 0.0) << "the swimmer must move against the wave (+z)";
    EXPECT_GT(m.pumped_volume_m3, 0.0) << "fluid is pumped backwards (-z)";
    // a scene with a fixed duration (tiny_3d: its first 30 ms) runs that span, not its cycles
    if (p.wave == swim::reduced1d::WaveKind::ForceDriven && resolved["time"]["duration"] == "auto") {
      EXPECT_EQ(m.cycles_completed, p.protocol.cycles);
    }
  }
}

TEST(Executable, RunWritesTheContractOutputs) {
  const fs::path out = fs::temp_directory_path() / "swim_run_outputs";
  fs::remove_all(out);
  ASSERT_EQ(run("run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --set numerics1d.cells=60 --out \"" +
                out.string() + "\""),
            0);
  std::ifstream in(out / "summary.json");
  const json s = json::parse(in);
  for (const char* k : {"tier", "scene", "displacement_m", "max_displacement_m", "cycles_completed", "cycle_times_s", "mean_velocity_m_per_s",
                        "body_lengths_per_s", "pumped_volume_m3", "wall_time_s", "status"})
    EXPECT_TRUE(s.contains(k)) << k;
  EXPECT_EQ(s["status"], "ok");
  EXPECT_EQ(s["scene"]["numerics1d"]["cells"], 60);
  EXPECT_GE(s["max_displacement_m"].get<double>(), s["displacement_m"].get<double>());
  EXPECT_TRUE(swim::output::all_finite(s));
  std::ifstream csv(out / "series.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("t_s,x_center_m,velocity_m_per_s,energy_J,min_radius_m,max_radius_m", 0), 0u) << header;
  std::string line;
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    EXPECT_EQ(line.find("nan"), std::string::npos);
    EXPECT_EQ(line.find("inf"), std::string::npos);
  }
  EXPECT_GT(rows, 10);
  EXPECT_TRUE(fs::exists(out / "radius.csv"));
  EXPECT_TRUE(fs::exists(out / "solver_stats.json"));
  fs::remove_all(out);
}

TEST(Executable, ScreenRanksASmallSweep) {
  const fs::path dir = fs::temp_directory_path() / "swim_screen_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const json sweep = {{"base", SWIM_SOURCE_DIR "/data/scenes/demo.json"},
                      {"vary",
                       {{"wave.kind", {"step"}},
                        {"protocol", {nullptr}},
                        {"numerics1d.cells", {40}},
                        {"swimmer.length", {{"from", "0.2 um"}, {"to", "0.4 um"}, {"count", 2}}},
                        {"wave.contracted_ratio", {0.4, 0.8}}}},
                      {"metric", "displacement_m"}};
  std::ofstream(dir / "sweep.json") << sweep.dump();
  const std::string printed = (dir / "stdout.txt").string();
  ASSERT_EQ(std::system(("\"" SWIM_BINARY_DIR "/bin/swim\" screen \"" + (dir / "sweep.json").string() +
                         "\" --quiet --jobs 2 --out \"" + (dir / "out").string() + "\" > \"" + printed + "\" 2>&1")
                            .c_str()),
            0);
  {  // the best value is printed with an SI-prefixed unit, e.g. "-> 16.2 nm"
    std::ifstream o(printed);
    const std::string text((std::istreambuf_iterator<char>(o)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("nm\n"), std::string::npos) << text;
  }
  std::ifstream in(dir / "out" / "screen.json");
  const json s = json::parse(in);
  EXPECT_EQ(s["designs"], 4);
  EXPECT_EQ(s["failed"], 0);
  // The longest swimmer with the deepest contraction displaces the most fluid and moves farthest.
  EXPECT_EQ(s["best_design"], 2) << s.dump(1);
  std::ifstream csv(dir / "out" / "designs.csv");
  std::string line;
  {  // the columns follow series.csv: a quantity as given and in SI with its unit, a choice once
    std::ifstream h(dir / "out" / "designs.csv");
    std::string header;
    std::getline(h, header);
    const std::string cols = "," + header + ",";
    EXPECT_NE(cols.find(",swimmer.length,swimmer.length_m,"), std::string::npos) << header;
    EXPECT_NE(cols.find(",wave.kind,"), std::string::npos) << header;
    EXPECT_NE(cols.find(",wave.contracted_ratio,"), std::string::npos) << header;
    EXPECT_EQ(cols.find("wave.kind_"), std::string::npos) << header;
    EXPECT_EQ(cols.find("wave.contracted_ratio_"), std::string::npos) << header;
    EXPECT_EQ(cols.find("_si"), std::string::npos) << header;
    EXPECT_EQ(cols.find('['), std::string::npos) << header;
  }
  int rows = -1;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 4);
  fs::remove_all(dir);
}
