// swim run --tier 3d --error-estimate: a 3D run that reports its own discretisation error from
// a second run of the scene on a coarser grid (docs/full3d.md, "A run's own error estimate").
// On the small cycle scene tiny_3d_cycle (12 cells across; the coarse grid 9): both run folders,
// the estimate's numbers, a coarse run that fails (an injected full disk in its folder alone),
// and the bad input refused before anything is written.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "common/run_folder.hpp"
#include "common/scene.hpp"
#include "tests/support/files.hpp"

namespace fs = std::filesystem;
using swim::scene::json;

namespace {

const std::string kTinyCycle = SWIM_SOURCE_DIR "/data/scenes/tiny_3d_cycle.json";
// no VTK frames (they are not what is tested), two threads as the other 3D tests
const std::string kFast = " --set full3d.output.vtk=false";

struct Cli {
  int code = -1;
  std::string out, err;
};

Cli swim_cli(const std::string& args, const fs::path& scratch, const std::string& env = "") {
  const fs::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string cmd = env + (env.empty() ? "" : " ") + "\"" + SWIM_BINARY_DIR + "/bin/swim\" " + args +
                          " --progress > \"" + out.string() + "\" 2> \"" + err.string() + "\"";
  const int status = std::system(cmd.c_str());
  Cli c;
  c.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  c.out = swim::test::slurp(out);
  c.err = swim::test::slurp(err);
  fs::remove(out);
  fs::remove(err);
  return c;
}

json summary_of(const fs::path& dir) {
  const std::string t = swim::test::slurp(dir / "summary.json");
  return t.empty() ? json(nullptr) : json::parse(t);
}

}  // namespace

// Expected: exit 0; the run's folder and its coarse run's folder (error_estimate/coarse) both
// verify, the run's summary lists the coarse run's files; summary.json's error_estimate holds
// the method, the two grids (12 and 9 cells across: h = 40 and 53.3 nm), the order range
// [0.5, 2] and, per headline figure, finite numbers with interval_low <= extrapolated_order1 <=
// interval_high; the figures are those of the two runs' own summaries; the progress says which
// run goes. Then the same scene with the coarse run's radius.csv failing (a full disk in the
// coarse folder only): exit 0, the run's figures are those of the first run, and
// error_estimate is {"status": "failed: ..."} naming the file, with no numbers.
TEST(ErrorEstimateCli, ACoarseRunGivesTheErrorOfEachHeadlineFigureOrSaysWhyItFailed) {
  const fs::path d = swim::test::scratch_dir("swim_error_estimate");
  const fs::path out = d / "run", coarse = out / "error_estimate" / "coarse";
  const std::string cmd = "run \"" + kTinyCycle + "\" --tier 3d --error-estimate --out \"" + out.string() + "\"" + kFast;
  const Cli c = swim_cli(cmd, d);
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_NE(c.err.find("error estimate: 1 of 2, the coarse run (9 cells across"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("error estimate: 2 of 2, the run itself (12 cells across"), std::string::npos) << c.err;
  EXPECT_NE(c.out.find("error estimate, displacement per cycle"), std::string::npos) << c.out;
  EXPECT_EQ(swim::output::verify_folder(out.string(), {"series.csv", "error_estimate/coarse/summary.json"}), "");
  EXPECT_EQ(swim::output::verify_folder(coarse.string(), {"series.csv", "radius.csv"}), "");
  const json s = summary_of(out), cs = summary_of(coarse);
  ASSERT_TRUE(s.is_object());
  ASSERT_TRUE(cs.is_object());
  EXPECT_EQ(s["status"], "ok");
  EXPECT_EQ(cs["status"], "ok");
  EXPECT_EQ(cs["scene"]["full3d"]["grid"]["cells_across"], 9);
  ASSERT_TRUE(s.contains("error_estimate")) << s.dump(1);
  const json& e = s["error_estimate"];
  EXPECT_EQ(e["status"], "ok");
  EXPECT_TRUE(e["method"].is_string());
  EXPECT_EQ(e["coarse_cells_across"], 9);
  EXPECT_NEAR(e["fine_cell_size_m"].get<double>(), 0.04e-6, 1e-15);
  EXPECT_NEAR(e["coarse_cell_size_m"].get<double>(), 0.48e-6 / 9, 1e-15);
  EXPECT_EQ(e["order_range"], json({0.5, 2.0}));
  for (const char* k : {"displacement_per_cycle_m", "cycle_time_s", "mean_velocity_per_cycle_m_per_s"}) {
    ASSERT_TRUE(e.contains(k)) << k;
    const json& f = e[k];
    for (const char* v : {"fine", "coarse", "extrapolated_order1", "interval_low", "interval_high", "error"}) {
      ASSERT_TRUE(f.contains(v) && f[v].is_number()) << k << "." << v;
      EXPECT_TRUE(std::isfinite(f[v].get<double>())) << k << "." << v;
    }
    EXPECT_LE(f["interval_low"].get<double>(), f["extrapolated_order1"].get<double>()) << k;
    EXPECT_LE(f["extrapolated_order1"].get<double>(), f["interval_high"].get<double>()) << k;
    EXPECT_GE(f["error"].get<double>(), 0.0) << k;
    EXPECT_EQ(f["fine"].get<double>(), s[k].get<double>()) << k;
    EXPECT_EQ(f["coarse"].get<double>(), cs[k].get<double>()) << k;
  }
  const double fine_displacement = s["displacement_per_cycle_m"].get<double>();

  // the coarse run fails; the run itself completes, and its estimate says why there is none
  const Cli f = swim_cli(cmd, d, "SWIM_TEST_FAIL_WRITE=coarse/radius.csv:0");
  ASSERT_EQ(f.code, 0) << f.err;
  EXPECT_NE(f.err.find("the coarse run failed"), std::string::npos) << f.err;
  const json s2 = summary_of(out);
  EXPECT_EQ(s2["status"], "ok");
  EXPECT_EQ(s2["displacement_per_cycle_m"].get<double>(), fine_displacement);
  ASSERT_TRUE(s2.contains("error_estimate"));
  EXPECT_EQ(s2["error_estimate"].size(), 1u) << s2["error_estimate"].dump();
  const std::string status = s2["error_estimate"]["status"].get<std::string>();
  EXPECT_EQ(status.rfind("failed: the coarse run (9 cells across): ", 0), 0u) << status;
  EXPECT_NE(status.find("radius.csv"), std::string::npos) << status;
  EXPECT_EQ(swim::output::verify_folder(out.string(), {"series.csv"}), "");
  EXPECT_EQ(summary_of(coarse)["status"].get<std::string>().rfind("failed", 0), 0u);
  fs::remove_all(d);
}

// Expected: exit 2 before anything is written, the message naming --error-estimate, the tier
// and what is allowed (--tier 3d); with --resume, naming both options; a scene whose coarse grid
// the reader refuses (a swimmer of radius 0.135 um fits the 0.24 um duct with the kernel's 2 h
// on 12 cells across, not on 9), naming --error-estimate, the coarse grid and the reader's key.
TEST(ErrorEstimateCli, OnlyA3dRunWithoutResumeTakesTheOption) {
  const fs::path d = swim::test::scratch_dir("swim_error_estimate_bad");
  for (const std::string tier : {"1d", "axi"}) {
    const fs::path out = d / tier;
    const Cli c = swim_cli("run \"" + kTinyCycle + "\" --tier " + tier + " --error-estimate --out \"" + out.string() + "\"", d);
    EXPECT_EQ(c.code, 2) << c.err;
    EXPECT_NE(c.err.find("--error-estimate"), std::string::npos) << c.err;
    EXPECT_NE(c.err.find("--tier " + tier), std::string::npos) << c.err;
    EXPECT_NE(c.err.find("--tier 3d"), std::string::npos) << c.err;
    EXPECT_FALSE(fs::exists(out)) << out;
  }
  const fs::path out = d / "resume";
  fs::create_directories(out);
  const Cli c = swim_cli("run \"" + kTinyCycle + "\" --tier 3d --error-estimate --resume \"" + out.string() + "\"", d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("--error-estimate"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("--resume"), std::string::npos) << c.err;
  EXPECT_TRUE(fs::is_empty(out));
  const fs::path wide = d / "wide";
  const Cli w = swim_cli("run \"" + kTinyCycle + "\" --tier 3d --error-estimate --set swimmer.radius='\"0.135 um\"' --out \"" +
                             wide.string() + "\"",
                         d);
  EXPECT_EQ(w.code, 2) << w.err;
  EXPECT_NE(w.err.find("'--error-estimate' = the coarse grid full3d.grid.cells_across = 9"), std::string::npos) << w.err;
  EXPECT_NE(w.err.find("container.radius"), std::string::npos) << w.err;
  EXPECT_FALSE(fs::exists(wide));
  fs::remove_all(d);
}
