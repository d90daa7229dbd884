// What a new user meets in the first hour: every shipped scene runs, as shipped or shortened,
// on each tier it is meant for and succeeds; every example of README.md runs as written; the
// command line's conventions (--version, an unknown subcommand named, the help naming swim,
// --threads); run.png listed by the summary; printouts in one unit style.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "common/run_folder.hpp"
#include "common/scene.hpp"
#include "tests/support/files.hpp"
#include "tests/support/vtk_read.hpp"

namespace fs = std::filesystem;
using swim::scene::json;
using swim::test::slurp;

namespace {

struct Cli {
  int code = -1;
  std::string out, err;
};

// Runs the executable with `args` (shell syntax), stdout and stderr captured.
Cli swim_cli(const std::string& args, const fs::path& scratch) {
  const fs::path o = scratch / "stdout.txt", e = scratch / "stderr.txt";
  const std::string cmd = "\"" SWIM_BINARY_DIR "/bin/swim\" " + args + " > \"" + o.string() + "\" 2> \"" +
                          e.string() + "\"";
  const int status = std::system(cmd.c_str());
  Cli c;
  c.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  c.out = slurp(o);
  c.err = slurp(e);
  return c;
}

json summary_of(const fs::path& dir) {
  const std::string t = slurp(dir / "summary.json");
  return t.empty() ? json(nullptr) : json::parse(t);
}

std::vector<fs::path> shipped_scenes() {
  std::vector<fs::path> v;
  for (const auto& e : fs::directory_iterator(SWIM_SOURCE_DIR "/data/scenes"))
    if (e.path().extension() == ".json") v.push_back(e.path());
  std::sort(v.begin(), v.end());
  return v;
}

// The scene's own settings take seconds in 3D only for the small check scenes; the paper
// scenes (10 s to minutes per cycle) run their first steps.
bool fast_in_3d(const fs::path& scene) { return scene.stem().string().rfind("tiny_3d", 0) == 0; }

// The CMake project version, read from the top-level CMakeLists.txt.
std::string project_version() {
  const std::string text = slurp(SWIM_SOURCE_DIR "/CMakeLists.txt");
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(R"(project\(swim[^)]*VERSION ([0-9]+\.[0-9]+\.[0-9]+))"))) return "";
  return m[1];
}

bool have_matplotlib() { return std::system("/usr/bin/python3 -c 'import matplotlib' > /dev/null 2>&1") == 0; }

}  // namespace

TEST(ShippedScenesRun, EachSucceedsOnThe1dTierAsShipped) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_1d");
  for (const auto& scene : shipped_scenes()) {
    SCOPED_TRACE(scene.filename().string());
    const fs::path out = d / scene.stem();
    const Cli c = swim_cli("run \"" + scene.string() + "\" --quiet --out \"" + out.string() + "\"", d);
    EXPECT_EQ(c.code, 0) << c.err;
    const json s = summary_of(out);
    ASSERT_TRUE(s.is_object());
    EXPECT_EQ(s["status"], "ok");
    const json& sc = s["scene"];
    if (sc["wave"]["kind"] == "force_driven" && sc["time"]["duration"] == "auto") {
      EXPECT_EQ(s["cycles_completed"].get<int>(), sc["protocol"]["cycles"].get<int>());
    }
    EXPECT_EQ(swim::output::verify_folder(out.string()), "");
  }
  fs::remove_all(d);
}

// The paper scenes take 10 s to minutes per 3D cycle: their first 4 ms on the scene's own grid
// and membrane. The small check scenes run as shipped; tiny_3d_cycle completes its cycle.
TEST(ShippedScenesRun, EachSucceedsOnThe3dTier) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_3d");
  for (const auto& scene : shipped_scenes()) {
    SCOPED_TRACE(scene.filename().string());
    const fs::path out = d / scene.stem();
    const std::string shorten = fast_in_3d(scene) ? "" : " --set time.duration='\"4 ms\"' --set full3d.output.vtk=false";
    const Cli c = swim_cli("run \"" + scene.string() + "\" --tier 3d --quiet --threads 2 --out \"" + out.string() + "\"" +
                           shorten,
                       d);
    EXPECT_EQ(c.code, 0) << c.err;
    const json s = summary_of(out);
    ASSERT_TRUE(s.is_object());
    EXPECT_EQ(s["status"], "ok");
    EXPECT_GE(s["steps"].get<long>(), 4);
    if (scene.stem() == "tiny_3d_cycle") {
      EXPECT_EQ(s["cycles_completed"].get<int>(), 1);
      EXPECT_NE(c.out.find("; 1 cycle of "), std::string::npos) << c.out;  // not "1 cycle(s)"
    }
    EXPECT_EQ(c.out.find("cycle(s)"), std::string::npos) << c.out;
    EXPECT_EQ(swim::output::verify_folder(out.string()), "");
  }
  fs::remove_all(d);
}

// The axisymmetric tier is meant for round-wall scenes (full3d.membrane.axisymmetric = true):
// each shipped one runs its first steps; the others are refused naming the key (exit 2).
TEST(ShippedScenesRun, RoundWallScenesSucceedOnTheAxiTierAndOthersAreRefused) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_axi");
  for (const auto& scene : shipped_scenes()) {
    SCOPED_TRACE(scene.filename().string());
    const json sc = swim::scene::load_file(scene.string());
    const bool round = sc.contains("full3d") && sc["full3d"].contains("membrane") &&
                       sc["full3d"]["membrane"].value("axisymmetric", false) &&
                       sc["container"].value("kind", std::string()) == "cylinder";
    const fs::path out = d / scene.stem();
    const Cli c = swim_cli("run \"" + scene.string() + "\" --tier axi --quiet --out \"" + out.string() +
                           "\" --set time.duration='\"10 ms\"'",
                       d);
    if (round) {
      EXPECT_EQ(c.code, 0) << c.err;
      EXPECT_EQ(summary_of(out)["status"], "ok");
    } else {
      EXPECT_EQ(c.code, 2) << c.err;
      EXPECT_NE(c.err.find("full3d.membrane.axisymmetric"), std::string::npos) << c.err;
    }
  }
  fs::remove_all(d);
}

// Every example of README.md, as written: the --set examples on the demo scene, the minimal
// scene, re-plotting a run folder and asking for fluid frames.
TEST(Readme, EveryExampleRunsAsWritten) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_readme");
  const std::string readme = slurp(SWIM_SOURCE_DIR "/README.md");
  ASSERT_FALSE(readme.empty());

  // 1. the --set examples: each backticked "--set ..." of the paragraph on --set
  const std::size_t at = readme.find("`--set` takes the scene syntax");
  ASSERT_NE(at, std::string::npos);
  const std::string para = readme.substr(at, readme.find("\n\n", at) - at);
  const std::regex example(R"(`(--set [^`]+)`)");
  int examples = 0, n = 0;
  for (auto it = std::sregex_iterator(para.begin(), para.end(), example); it != std::sregex_iterator(); ++it) {
    const std::string args = (*it)[1];
    if (args.find("=null") != std::string::npos) continue;  // the syntax of a removal, not a run
    SCOPED_TRACE(args);
    ++examples;
    const fs::path out = d / ("set" + std::to_string(n++));
    const Cli c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --out \"" + out.string() + "\" " + args, d);
    EXPECT_EQ(c.code, 0) << c.err;
    const json s = summary_of(out);
    ASSERT_TRUE(s.is_object());
    EXPECT_EQ(s["status"], "ok");
    EXPECT_EQ(s["cycles_completed"], 1);
  }
  EXPECT_GE(examples, 3);

  // 2. the minimal scene (the README's one JSON block)
  const std::size_t j0 = readme.find("```json\n");
  ASSERT_NE(j0, std::string::npos);
  const std::size_t j1 = readme.find("```", j0 + 8);
  const json minimal = json::parse(readme.substr(j0 + 8, j1 - j0 - 8));
  std::ofstream(d / "minimal.json") << minimal.dump(2);
  const fs::path out = d / "minimal";
  Cli c = swim_cli("run \"" + (d / "minimal.json").string() + "\" --quiet --out \"" + out.string() + "\"", d);
  EXPECT_EQ(c.code, 0) << c.err;
  const json s = summary_of(out);
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s["status"], "ok");
  EXPECT_EQ(s["cycles_completed"], minimal["protocol"]["cycles"]);

  // 3. re-plotting a run folder
  ASSERT_NE(readme.find("/usr/bin/python3 tools/plot_run.py DIR"), std::string::npos);
  if (have_matplotlib()) {
    EXPECT_EQ(std::system(("/usr/bin/python3 \"" SWIM_SOURCE_DIR "/tools/plot_run.py\" \"" + out.string() +
                           "\" > /dev/null 2>&1")
                              .c_str()),
              0);
    EXPECT_TRUE(fs::exists(out / "run.png"));
  }

  // 4. fluid frames on request
  const std::string fluid = "--set full3d.output.fluid_fields=true";
  ASSERT_NE(readme.find(fluid), std::string::npos);
  const fs::path f = d / "fluid";
  c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/tiny_3d.json\" --tier 3d --quiet --out \"" + f.string() + "\" " +
               fluid + " --set full3d.output.fluid_interval='\"10 ms\"'",
           d);
  EXPECT_EQ(c.code, 0) << c.err;
  EXPECT_TRUE(fs::exists(f / "fluid.pvd"));
  EXPECT_TRUE(fs::exists(f / "vtk" / "fluid_000000.vti"));

  // 5. every file the README names exists
  for (const char* file : {"LICENSE", "CITATION.cff", "docs/contract-changes.md", "tools/plot_run.py"})
    EXPECT_TRUE(fs::exists(fs::path(SWIM_SOURCE_DIR) / file)) << file;
  fs::remove_all(d);
}

TEST(CommandLine, VersionIsTheProjectVersionInTheCliTheSummaryAndTheCitation) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_version");
  const std::string v = project_version();
  ASSERT_FALSE(v.empty());
  Cli c = swim_cli("--version", d);
  EXPECT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(c.out, "swim " + v + "\n");
  const fs::path out = d / "run";
  c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --out \"" + out.string() +
               "\" --set time.duration='\"5 ms\"'",
           d);
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(summary_of(out)["swim_version"], v);
  EXPECT_NE(slurp(SWIM_SOURCE_DIR "/CITATION.cff").find("version: \"" + v + "\""), std::string::npos);
  fs::remove_all(d);
}

TEST(CommandLine, AnUnknownSubcommandIsNamedAndTheHelpNamesSwim) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_cli");
  Cli c = swim_cli("runn demo.json", d);
  EXPECT_EQ(c.code, 2);
  EXPECT_NE(c.err.find("unknown subcommand runn"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("run, "), std::string::npos) << c.err;  // the subcommands that exist
  c = swim_cli("--help", d);
  EXPECT_EQ(c.code, 0);
  EXPECT_NE(c.out.find("swim [OPTIONS] SUBCOMMAND"), std::string::npos) << c.out;
  EXPECT_EQ(c.out.find(SWIM_BINARY_DIR), std::string::npos) << c.out;
  EXPECT_EQ(c.out.find("bin/swim"), std::string::npos) << c.out;
  c = swim_cli("run --help", d);
  EXPECT_NE(c.out.find("swim run"), std::string::npos) << c.out;
  fs::remove_all(d);
}

// swim bench --fine-cycle N (one cycle of the paper's buckling wall on a fine grid): a grid it
// cannot run, or the flag without the 3D tier, is exit 2 naming the flag, before anything is
// written.
TEST(CommandLine, BenchRefusesAFineCycleItCannotRun) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_bench");
  for (const std::string args : {"--fine-cycle 7", "--fine-cycle 1000", "--tier 1d --fine-cycle 96"}) {
    const Cli c = swim_cli("bench --quick " + args + " --out \"" + (d / "b").string() + "\"", d);
    EXPECT_EQ(c.code, 2) << args;
    EXPECT_NE(c.err.find("--fine-cycle"), std::string::npos) << c.err;
    EXPECT_FALSE(fs::exists(d / "b")) << args;
  }
  // the cycles' scene overrides: only with --fine-cycle, and a value the scene reader refuses
  // is exit 2 naming its key, before anything runs
  for (const auto& [args, key] :
       std::vector<std::pair<std::string, std::string>>{
           {"--tier 3d --fine-cycle-set full3d.wall_stabilization=bending", "--fine-cycle-set"},
           {"--tier 3d --fine-cycle 96 --fine-cycle-set full3d.wall_stabilization=elastic", "full3d.wall_stabilization"}}) {
    const Cli c = swim_cli("bench --quick " + args + " --out \"" + (d / "b").string() + "\"", d);
    EXPECT_EQ(c.code, 2) << args;
    EXPECT_NE(c.err.find(key), std::string::npos) << c.err;
    EXPECT_FALSE(fs::exists(d / "b")) << args;
  }
  fs::remove_all(d);
}

// --threads sets the 3D run's threads (full3d.threads, in the resolved scene) and the 1D run's
// (numerics1d.threads, 1 or 2: the same files either way; more is refused naming the flag);
// swim calibrate takes it too.
TEST(CommandLine, RunAndCalibrateAcceptThreads) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_threads");
  const fs::path out = d / "run3d";
  Cli c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/tiny_3d.json\" --tier 3d --quiet --threads 2 --out \"" +
                   out.string() + "\" --set time.duration='\"3 ms\"'",
               d);
  EXPECT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(summary_of(out)["scene"]["full3d"]["threads"], 2);
  c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --threads 2 --out \"" + (d / "run1d").string() + "\"", d);
  EXPECT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(summary_of(d / "run1d")["scene"]["numerics1d"]["threads"], 2);
  // the files the second thread streamed are the one-thread run's, byte for byte
  c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --threads 1 --out \"" + (d / "run1d1").string() + "\"", d);
  EXPECT_EQ(c.code, 0) << c.err;
  for (const char* f : {"series.csv", "radius.csv"}) {
    const std::string one = slurp(d / "run1d1" / f), two = slurp(d / "run1d" / f);
    EXPECT_GT(one.size(), 10000u) << f;
    EXPECT_TRUE(one == two) << f << " differs between --threads 1 and 2";
  }
  c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --threads 3 --out \"" + (d / "run1d3").string() + "\"", d);
  EXPECT_EQ(c.code, 2);
  EXPECT_NE(c.err.find("--threads"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(d / "run1d3"));
  // a calibration takes minutes: its --threads is parsed, then the missing scene is the refusal
  c = swim_cli("calibrate \"" + (d / "missing.json").string() + "\" --threads 2", d);
  EXPECT_EQ(c.code, 2);
  EXPECT_EQ(c.err.find("--threads"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("missing.json"), std::string::npos) << c.err;
  fs::remove_all(d);
}

// run.png is a file of the run: listed in summary.json (the folder verifies); a rerun without
// --plot removes it with the earlier results and says so.
TEST(RunPlot, TheSummaryListsRunPngAndARerunWithoutPlotSaysItWentAway) {
  if (!have_matplotlib()) GTEST_SKIP() << "python3-matplotlib is not installed";
  const fs::path d = swim::test::scratch_dir("swim_first_hour_plot");
  const fs::path out = d / "run";
  const std::string args = "run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --out \"" + out.string() +
                           "\" --set time.duration='\"20 ms\"'";
  Cli c = swim_cli(args + " --plot", d);
  ASSERT_EQ(c.code, 0) << c.err;
  ASSERT_TRUE(fs::exists(out / "run.png"));
  bool listed = false;
  const json summary = summary_of(out);
  for (const auto& f : summary["files"]) listed = listed || f["name"] == "run.png";
  EXPECT_TRUE(listed);
  EXPECT_EQ(swim::output::verify_folder(out.string(), {"run.png"}), "");
  c = swim_cli(args, d);
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_FALSE(fs::exists(out / "run.png"));
  EXPECT_NE(c.err.find("run.png"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("--plot"), std::string::npos) << c.err;
  EXPECT_EQ(swim::output::verify_folder(out.string()), "");
  fs::remove_all(d);
}

// Volumes print in one unit (µm³) in every run; a prescribed wave, which has no protocol
// cycles, prints its transit instead of "0 cycle(s)".
TEST(Printouts, VolumesInOneUnitAndAPrescribedWavePrintsItsTransit) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_print");
  const Cli f = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --out \"" + (d / "f").string() + "\"", d);
  ASSERT_EQ(f.code, 0) << f.err;
  EXPECT_NE(f.out.find("\u00b5m\u00b3"), std::string::npos) << f.out;
  EXPECT_EQ(f.out.find("nm\u00b3"), std::string::npos) << f.out;
  const Cli p = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --out \"" + (d / "p").string() +
                         "\" --set wave.kind=step --set protocol=null",
                     d);
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_EQ(p.out.find("0 cycle"), std::string::npos) << p.out;
  EXPECT_NE(p.out.find("per wave transit"), std::string::npos) << p.out;
  EXPECT_NE(p.out.find("\u00b5m\u00b3"), std::string::npos) << p.out;
  fs::remove_all(d);
}

// The README's warning, tried: the demo's total force on half the tube, above C1 R0, on the
// lubrication-only wall (no continued end to fall back on) closes the tube at its open end
// (exit 3). The message gives lengths with their SI prefix and the parameter to change; with
// --plot the failed run still gets its run.png, marked failed, and listed in summary.json.
TEST(Printouts, AFailedRunNamesLengthsWithPrefixesAndItsPlotIsDrawn) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_failed");
  const fs::path out = d / "run";
  const Cli c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/demo.json\" --quiet --out \"" + out.string() +
                             "\" --set swimmer.length='\"0.2 um\"' --set model1d.short_wave_traction=false" +
                             (have_matplotlib() ? " --plot" : ""),
                         d);
  EXPECT_EQ(c.code, 3) << c.err;
  EXPECT_NE(c.err.find("collapsed to zero at z = 200 nm"), std::string::npos) << c.err;
  EXPECT_EQ(c.err.find("e-0"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("protocol.total_force"), std::string::npos) << c.err;
  const json s = summary_of(out);
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s["status"].get<std::string>().rfind("failed: ", 0), 0u) << s["status"];
  if (have_matplotlib()) {
    EXPECT_EQ(c.err.find("plotting with plot_run.py failed"), std::string::npos) << c.err;
    EXPECT_TRUE(fs::exists(out / "run.png"));
    EXPECT_EQ(swim::output::verify_folder(out.string(), {"run.png"}), "");
  }
  fs::remove_all(d);
}

// The frames of a run read back with an independent decoder (tests/support/vtk_read.hpp): each
// compressed, carrying its time (the same as its collection's timestep), segment as integers,
// and the cylinder's fluid frames with the inside/outside mask of the fictitious domain.
TEST(VtkFrames, ARunsFramesReadBackWithTheirTimeSegmentsAndTheCylindersMask) {
  using namespace swim::test::vtk_read;
  const fs::path d = swim::test::scratch_dir("swim_first_hour_vtk");
  const fs::path out = d / "run";
  const Cli c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json\" --tier 3d --quiet --threads 2 --out \"" +
                         out.string() +
                         "\" --set time.duration='\"4 ms\"' --set full3d.output.vtk_interval='\"2 ms\"'"
                         " --set full3d.output.fluid_fields=true --set full3d.output.fluid_interval='\"2 ms\"'",
                     d);
  ASSERT_EQ(c.code, 0) << c.err;
  const json summary = summary_of(out);
  const int segments = summary["scene"]["protocol"]["segments"].get<int>();
  for (const std::string kind : {"membrane", "fluid"}) {
    SCOPED_TRACE(kind);
    const std::string pvd = slurp(out / (kind + ".pvd"));
    const std::regex entry(R"re(<DataSet timestep="([^"]+)" part="0" file="([^"]+)"/>)re");
    int frames = 0;
    for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), entry); it != std::sregex_iterator(); ++it) {
      ++frames;
      const std::string xml = slurp(out / std::string((*it)[2]));
      EXPECT_NE(xml.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
      std::map<std::string, Array> by;
      for (const auto& a : arrays(xml)) by[a.name] = a;
      ASSERT_TRUE(by.count("TimeValue"));
      const auto t = decode<double>(by["TimeValue"].body);
      ASSERT_EQ(t.size(), 1u);
      EXPECT_NEAR(t[0], std::stod((*it)[1]), 1e-9 * std::max(1.0, t[0]));
      if (kind == "membrane") {
        EXPECT_EQ(by["segment"].type, "Int32");
        const auto seg = decode<std::int32_t>(by["segment"].body);
        ASSERT_FALSE(seg.empty());
        EXPECT_EQ(*std::min_element(seg.begin(), seg.end()), 0);
        EXPECT_EQ(*std::max_element(seg.begin(), seg.end()), segments - 1);
      } else {
        ASSERT_TRUE(by.count("inside_container"));
        EXPECT_EQ(by["inside_container"].type, "Int32");
        const auto mask = decode<std::int32_t>(by["inside_container"].body);
        const auto p = decode<float>(by["pressure_Pa"].body);
        ASSERT_EQ(mask.size(), p.size());
        // the cylinder (Rc = 0.25 um, the scene's) fills pi Rc^2 of the duct's cross-section
        // (grid cells ny x nz of size h, from summary.json), up to its staircase
        double inside = 0;
        for (auto m : mask) {
          EXPECT_TRUE(m == 0 || m == 1);
          inside += m;
        }
        ASSERT_EQ(summary["scene"]["container"]["radius"], "0.25 um");
        const double rc = 0.25e-6, h = summary["derived"]["cell_size_m"].get<double>();
        const auto grid = summary["derived"]["grid"];
        const double fraction = M_PI * rc * rc / (grid[1].get<double>() * grid[2].get<double>() * h * h);
        EXPECT_NEAR(inside / double(mask.size()), fraction, 0.02);
      }
    }
    EXPECT_GE(frames, 2);
  }
  fs::remove_all(d);
}

// Every shipped sweep (data/sweeps, README "swim screen") screens on the 1D tier with every
// design succeeding; its 3D confirmation (--confirm, minutes) is the design loop's own test.
TEST(ShippedSweeps, EachScreensOnThe1dTier) {
  const fs::path d = swim::test::scratch_dir("swim_first_hour_sweeps");
  for (const auto& e : fs::directory_iterator(SWIM_SOURCE_DIR "/data/sweeps")) {
    if (e.path().extension() != ".json") continue;
    SCOPED_TRACE(e.path().filename().string());
    const fs::path out = d / e.path().stem();
    const Cli c = swim_cli("screen \"" + e.path().string() + "\" --quiet --jobs 2 --out \"" + out.string() + "\"", d);
    EXPECT_EQ(c.code, 0) << c.err;
    const json s = json::parse(slurp(out / "screen.json"));
    EXPECT_EQ(s["status"], "ok");
    EXPECT_EQ(s["failed"], 0);
    EXPECT_GT(s["designs"].get<int>(), 1);
  }
  fs::remove_all(d);
}
