// A run folder belongs to one run, and its files never lie: atomic result files, exit 3 on a
// write failure (injected full disk) with nothing claiming success, the lock against two
// runs on one folder, stale results from another run refused or cleared with --overwrite,
// --resume only for the run the folder belongs to, the output-size limit, and the same
// ownership for the folders of swim screen and swim calibrate.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "common/atomic_file.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/run_folder.hpp"
#include "tests/support/files.hpp"

namespace fs = std::filesystem;
using swim::scene::json;

namespace {

const std::string kDemo = SWIM_SOURCE_DIR "/data/scenes/demo.json";
const std::string kTiny3d = SWIM_SOURCE_DIR "/data/scenes/tiny_3d.json";
const std::string kTiny3dFast =
    " --set full3d.dt='\"1 ms\"' --set time.duration='\"12 ms\"' --set full3d.output.vtk_interval='\"5 ms\"'";

fs::path tmpdir(const std::string& tag) { return swim::test::scratch_dir("swim_folder_" + tag); }
using swim::test::slurp;

struct Cli {
  int code = -1;
  std::string err;
};

// Runs the executable; `env` is prepended to the command line (e.g. "SWIM_TEST_FAIL_WRITE=x").
// quiet: add --quiet (no progress lines).
Cli swim_cli(const std::string& args, const fs::path& scratch, const std::string& env = "", bool quiet = true) {
  const fs::path err = scratch / ("stderr_" + std::to_string(::getpid()) + ".txt");
  const std::string cmd = env + (env.empty() ? "" : " ") + "\"" + SWIM_BINARY_DIR + "/bin/swim\" " + args +
                          (quiet ? " --quiet" : "") + " > /dev/null 2> \"" + err.string() + "\"";
  const int status = std::system(cmd.c_str());
  Cli c;
  c.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  c.err = slurp(err);
  fs::remove(err);
  return c;
}

json summary_of(const fs::path& dir) {
  const std::string t = slurp(dir / "summary.json");
  return t.empty() ? json(nullptr) : json::parse(t);
}

// Nothing in the folder claims success: no summary, or one whose status is not "ok".
void expect_no_success_claim(const fs::path& dir) {
  const json s = summary_of(dir);
  if (s.is_null()) return;
  ASSERT_TRUE(s.contains("status"));
  EXPECT_EQ(s["status"].get<std::string>().rfind("failed", 0), 0u) << s["status"];
}

// Every file the summary lists exists with the recorded size and checksum; no temporary
// files remain; nothing else than the listed files, the summary and the run's records.
void expect_consistent_folder(const fs::path& dir) {
  const json s = summary_of(dir);
  ASSERT_TRUE(s.is_object());
  ASSERT_TRUE(s.contains("files"));
  // the summary's own checksum too (output::verify_folder)
  EXPECT_EQ(swim::output::verify_folder(dir.string()), "");
  std::set<std::string> listed = {"summary.json", ".swim.lock", ".swim-run.json"};
  for (const auto& f : s["files"]) {
    const fs::path p = dir / f["name"].get<std::string>();
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_EQ(fs::file_size(p), f["bytes"].get<std::uintmax_t>()) << p;
    EXPECT_EQ(swim::output::file_checksum(p.string()), f["fnv1a64"].get<std::string>()) << p;
    listed.insert(f["name"].get<std::string>());
  }
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_directory()) continue;
    const std::string rel = fs::relative(e.path(), dir).generic_string();
    EXPECT_TRUE(listed.count(rel)) << "file not from this run: " << rel;
    EXPECT_EQ(rel.find(".tmp"), std::string::npos) << "temporary file left: " << rel;
  }
}

}  // namespace

TEST(AtomicFile, AFileAppearsOnlyWhenCompleteAndAFailedRewriteKeepsTheOldOne) {
  const fs::path d = tmpdir("atomic");
  const std::string p = (d / "a.txt").string();
  {
    swim::output::AtomicFile f(p);
    f.stream() << "partial";
    EXPECT_FALSE(fs::exists(p));  // not yet published
  }                               // not committed: discarded
  EXPECT_FALSE(fs::exists(p));
  EXPECT_TRUE(fs::is_empty(d)) << "temporary file left behind";
  {
    swim::output::AtomicFile f(p);
    f.stream() << "complete\n";
    f.commit();
  }
  EXPECT_EQ(slurp(p), "complete\n");
  ::setenv("SWIM_TEST_FAIL_WRITE", "a.txt:4", 1);
  try {
    swim::output::AtomicFile f(p);
    f.stream() << std::string(100000, 'x');
    f.commit();
    ADD_FAILURE() << "a failed write was committed";
  } catch (const swim::OutputError& e) {
    EXPECT_EQ(e.file(), "a.txt");
    EXPECT_NE(std::string(e.what()).find("disk full while writing a.txt"), std::string::npos) << e.what();
  }
  ::unsetenv("SWIM_TEST_FAIL_WRITE");
  EXPECT_EQ(slurp(p), "complete\n") << "the old file was damaged by a failed rewrite";
  // the folder's summary is refused after a failure in it
  EXPECT_THROW(swim::output::write_json((d / "summary.json").string(), json{{"status", "ok"}}), swim::OutputError);
  EXPECT_FALSE(fs::exists(d / "summary.json"));
  // a writer whose folder is gone (read-only or missing) fails with OutputError, not a crash
  EXPECT_THROW(swim::output::AtomicFile((d / "missing" / "x.csv").string()), swim::OutputError);
  fs::remove_all(d);
}

TEST(RunFolderCli, AFullDiskIsExitThreeNamingTheFileAndNothingClaimsSuccess) {
  const fs::path d = tmpdir("full");
  for (const std::string f : {"radius.csv", "series.csv", "solver_stats.json", "scene.resolved.json", "summary.json"}) {
    SCOPED_TRACE(f);
    const fs::path out = d / ("run_" + f);
    const Cli c = swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\"", d,
                           "SWIM_TEST_FAIL_WRITE=" + f + ":100");
    EXPECT_EQ(c.code, 3) << c.err;
    EXPECT_NE(c.err.find("disk full while writing " + f), std::string::npos) << c.err;
    expect_no_success_claim(out);
    if (f != "summary.json") {
      EXPECT_FALSE(fs::exists(out / f)) << "a partial " << f << " was published";
    }
    for (const auto& e : fs::directory_iterator(out))
      EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  }
  // 3D: a membrane frame in the middle of the run
  const fs::path out3 = d / "run3d";
  const Cli c = swim_cli("run \"" + kTiny3d + "\" --tier 3d --out \"" + out3.string() + "\"" + kTiny3dFast, d,
                         "SWIM_TEST_FAIL_WRITE=membrane_000001.vtp:500");
  EXPECT_EQ(c.code, 3) << c.err;
  EXPECT_NE(c.err.find("disk full while writing membrane_000001.vtp"), std::string::npos) << c.err;
  expect_no_success_claim(out3);
  EXPECT_FALSE(fs::exists(out3 / "vtk" / "membrane_000001.vtp"));
  // the same run without the failure succeeds, and its folder is consistent
  const fs::path ok = d / "ok";
  ASSERT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + ok.string() + "\"", d).code, 0);
  EXPECT_EQ(summary_of(ok)["status"], "ok");
  expect_consistent_folder(ok);
  fs::remove_all(d);
}

TEST(RunFolderCli, ASecondRunIntoALockedFolderExitsTwoNamingThePid) {
  const fs::path d = tmpdir("lock");
  const fs::path out = d / "run";
  {
    swim::output::RunFolder held(out.string(), {"1d", json::object(), false, false, "--out"});
    const Cli c = swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\" --overwrite", d);
    EXPECT_EQ(c.code, 2) << c.err;
    EXPECT_NE(c.err.find("PID " + std::to_string(::getpid())), std::string::npos) << c.err;
    EXPECT_FALSE(fs::exists(out / "summary.json"));
    // in process too
    EXPECT_THROW(swim::output::RunFolder(out.string(), {"1d", json::object(), true, false, "--out"}), swim::InputError);
  }
  // released: the folder can be used (the lock is a kernel lock, so a killed run never blocks it)
  EXPECT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\" --overwrite", d).code, 0);
  fs::remove_all(d);
}

TEST(RunFolderCli, TwoRunsStartedOnOneFolderNeverMix) {
  const fs::path d = tmpdir("two");
  const fs::path out = d / "run";
  const std::string bin = std::string("\"") + SWIM_BINARY_DIR + "/bin/swim\"";
  const std::string a = bin + " run \"" + kDemo + "\" --quiet --out \"" + out.string() + "\" --set swimmer.length='0.3 um'";
  const std::string b = bin + " run \"" + kDemo + "\" --quiet --out \"" + out.string() + "\" --set swimmer.length='0.5 um'";
  const std::string cmd = "cd \"" + d.string() + "\"; (" + a + " >/dev/null 2>a.err; echo $? > a.code) & (" + b +
                          " >/dev/null 2>b.err; echo $? > b.code) & wait";
  ASSERT_EQ(std::system(("bash -c '" + std::regex_replace(cmd, std::regex("'"), "'\\''") + "'").c_str()), 0);
  const int ca = std::stoi(slurp(d / "a.code")), cb = std::stoi(slurp(d / "b.code"));
  EXPECT_EQ(std::min(ca, cb), 0) << slurp(d / "a.err") << slurp(d / "b.err");
  EXPECT_EQ(std::max(ca, cb), 2) << slurp(d / "a.err") << slurp(d / "b.err");
  const json s = summary_of(out);
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s["scene"]["swimmer"]["length"], ca == 0 ? "0.3 um" : "0.5 um");
  EXPECT_EQ(s["status"], "ok");
  EXPECT_EQ(json::parse(slurp(out / "scene.resolved.json"))["swimmer"]["length"], s["scene"]["swimmer"]["length"]);
  expect_consistent_folder(out);
  fs::remove_all(d);
}

TEST(RunFolderCli, StaleResultsOfAnotherRunAreRefusedOrClearedWithOverwrite) {
  const fs::path d = tmpdir("stale");
  const fs::path out = d / "run";
  // a longer 3D run's results
  ASSERT_EQ(swim_cli("run \"" + kTiny3d + "\" --tier 3d --out \"" + out.string() + "\"" + kTiny3dFast, d).code, 0);
  ASSERT_TRUE(fs::exists(out / "vtk" / "membrane_000002.vtp"));
  // a 1D run into it is refused, and leaves it untouched
  const std::string before = slurp(out / "summary.json");
  Cli c = swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\"", d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("--overwrite"), std::string::npos) << c.err;
  EXPECT_EQ(slurp(out / "summary.json"), before);
  // a shorter 3D run (another scene) too
  c = swim_cli("run \"" + kTiny3d + "\" --tier 3d --out \"" + out.string() + "\"" + kTiny3dFast +
                   " --set time.duration='\"6 ms\"'",
               d);
  EXPECT_EQ(c.code, 2) << c.err;
  // --resume of the 3D folder as a 1D run is refused
  EXPECT_EQ(swim_cli("run \"" + kDemo + "\" --resume \"" + out.string() + "\"", d).code, 2);
  // with --overwrite the old files are gone first: nothing of the 3D run is left
  c = swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\" --overwrite", d);
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_FALSE(fs::exists(out / "vtk"));
  EXPECT_FALSE(fs::exists(out / "checkpoint.bin"));
  EXPECT_FALSE(fs::exists(out / "membrane.pvd"));
  EXPECT_EQ(summary_of(out)["tier"], "1d");
  expect_consistent_folder(out);
  // now a 3D --resume on the 1D folder is refused (it would replace the 1D results)
  std::ofstream(out / "checkpoint.bin") << "not a checkpoint";
  c = swim_cli("run \"" + kTiny3d + "\" --tier 3d --resume \"" + out.string() + "\"" + kTiny3dFast, d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("1d run"), std::string::npos) << c.err;
  EXPECT_EQ(summary_of(out)["tier"], "1d");
  fs::remove(out / "checkpoint.bin");
  // re-running the identical scene replaces its own finished results
  EXPECT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\"", d).code, 0);
  expect_consistent_folder(out);
  // also in a folder written before run records existed (identified by its summary's scene)
  fs::remove(out / ".swim-run.json");
  EXPECT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\"", d).code, 0);
  fs::remove(out / ".swim-run.json");
  EXPECT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\" --set swimmer.length='0.3 um'", d).code, 2);
  fs::remove_all(d);
}

TEST(RunFolderCli, FilesSwimDidNotWriteAreNeverRemoved) {
  const fs::path d = tmpdir("foreign");
  const fs::path out = d / "run";
  fs::create_directories(out);
  std::ofstream(out / "notes.txt") << "mine";
  for (const std::string flag : {"", " --overwrite"}) {
    const Cli c = swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\"" + flag, d);
    EXPECT_EQ(c.code, 2) << c.err;
    EXPECT_NE(c.err.find("notes.txt"), std::string::npos) << c.err;
  }
  EXPECT_EQ(slurp(out / "notes.txt"), "mine");
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  // a directory where a result file should be: exit 2 before anything is written
  const fs::path out2 = d / "run2";
  fs::create_directories(out2 / "radius.csv" / "x");
  EXPECT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + out2.string() + "\" --overwrite", d).code, 2);
  EXPECT_FALSE(fs::exists(out2 / "summary.json"));
  // --out naming a file
  std::ofstream(d / "plain") << "x";
  EXPECT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + (d / "plain").string() + "\"", d).code, 2);
  fs::remove_all(d);
}

TEST(RunFolderCli, ARunWhoseOutputWouldExceedTheLimitIsRefused) {
  const fs::path d = tmpdir("limit");
  const fs::path out = d / "run";
  const std::string demo20 = "run \"" + kDemo + "\" --out \"" + out.string() + "\" --set time.duration='20 ms'";
  Cli c = swim_cli(demo20 + " --set output.max_bytes=100000", d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("'time.output_interval'"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("output.max_bytes"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(out));
  // the estimate is realistic: within a factor 2 of what the run then writes
  std::smatch m;
  ASSERT_TRUE(std::regex_search(c.err, m, std::regex(R"(about ([0-9.]+) (kB|MB|GB))"))) << c.err;
  const double estimate = std::stod(m[1]) * (m[2] == "kB" ? 1e3 : m[2] == "MB" ? 1e6 : 1e9);
  ASSERT_EQ(swim_cli(demo20, d).code, 0);
  double total = 0;
  for (const auto& e : fs::recursive_directory_iterator(out))
    if (e.is_regular_file()) total += static_cast<double>(e.file_size());
  EXPECT_GT(estimate, 0.5 * total);
  EXPECT_LT(estimate, 2.0 * total);
  fs::remove_all(out);
  // the default limit (1 GB) refuses a long run with a fine interval
  c = swim_cli("run \"" + kDemo + "\" --out \"" + out.string() +
                   "\" --set time.duration='1000 s' --set time.output_interval='10 us'",
               d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("'time.output_interval'"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(out));
  // 3D: the VTK frames dominate
  c = swim_cli("run \"" + kTiny3d + "\" --tier 3d --out \"" + out.string() + "\"" + kTiny3dFast +
                   " --set output.max_bytes=200000 --set full3d.output.vtk_interval='\"1 ms\"'",
               d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("'full3d.output.vtk_interval'"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(out));
  // the 3D estimate bounds what the run writes (the frames' size before compression), and is
  // not far above it (compression gains a factor of about 3.5 on the membrane frames)
  const std::string frames = " --set full3d.output.vtk_interval='\"1 ms\"' --set full3d.output.fluid_fields=true"
                             " --set full3d.output.fluid_interval='\"2 ms\"'";
  c = swim_cli("run \"" + kTiny3d + "\" --tier 3d --out \"" + out.string() + "\"" + kTiny3dFast + frames +
                   " --set output.max_bytes=1000",
               d);
  ASSERT_EQ(c.code, 2) << c.err;
  ASSERT_TRUE(std::regex_search(c.err, m, std::regex(R"(about ([0-9.]+) (kB|MB|GB))"))) << c.err;
  const double estimate3d = std::stod(m[1]) * (m[2] == "kB" ? 1e3 : m[2] == "MB" ? 1e6 : 1e9);
  ASSERT_EQ(swim_cli("run \"" + kTiny3d + "\" --tier 3d --out \"" + out.string() + "\"" + kTiny3dFast + frames, d).code, 0);
  double written = 0;
  for (const auto& e : fs::recursive_directory_iterator(out))
    if (e.is_regular_file() && e.path().extension() != ".bin") written += static_cast<double>(e.file_size());
  EXPECT_GT(estimate3d, written);
  EXPECT_LT(estimate3d, 6.0 * written);
  fs::remove_all(d);
}

// A fluid grid whose Stokes factors for two time steps exceed full3d.memory_limit_gib is refused
// when the scene is read (exit 2 naming the grid key and the limit's key), before the folder
// exists: the solver would otherwise refuse it only when built.
TEST(RunFolderCli, AFluidGridBeyondTheMemoryLimitIsRefusedBeforeAnythingIsWritten) {
  const fs::path d = tmpdir("memory");
  const fs::path out = d / "run";
  const Cli c = swim_cli("run \"" SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json\" --tier 3d --out \"" +
                             out.string() + "\" --set full3d.grid.cells_across=80 --set full3d.memory_limit_gib=0.125",
                         d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("'full3d.grid.cells_across' = 320 x 84 x 84 cells"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("full3d.memory_limit_gib"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("0.125000 GiB allowed"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(d);
}

TEST(RunFolderCli, ARealFullFilesystemIsExitThreeAndNothingClaimsSuccess) {
  // A 600 kB tmpfs: the 1D demo's radius.csv (3.5 MB) cannot fit. Needs the right to mount
  // (root in a container that allows it); skipped otherwise -- the injected failure above
  // covers the same code path.
  const fs::path d = tmpdir("tmpfs");
  const fs::path mnt = d / "mnt";
  fs::create_directories(mnt);
  if (::geteuid() != 0 ||
      std::system(("mount -t tmpfs -o size=600k tmpfs \"" + mnt.string() + "\" 2>/dev/null").c_str()) != 0) {
    fs::remove_all(d);
    GTEST_SKIP() << "cannot mount a tmpfs here";
  }
  struct Cleanup {
    fs::path mnt, dir;
    ~Cleanup() {
      if (std::system(("umount \"" + mnt.string() + "\"").c_str()) == 0) fs::remove_all(dir);
    }
  } cleanup{mnt, d};
  const fs::path out = mnt / "run";
  const Cli c = swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\"", d);
  EXPECT_EQ(c.code, 3) << c.err;
  EXPECT_NE(c.err.find("disk full while writing radius.csv"), std::string::npos) << c.err;
  expect_no_success_claim(out);
  EXPECT_FALSE(fs::exists(out / "radius.csv"));
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// Both tiers write their folders with one writer (common/run_record.hpp): the same summary
// keys, the same leading series columns in the same order, the same radius.csv columns.
TEST(RunFolderCli, BothTiersWriteTheSameKeysAndColumns) {
  const fs::path d = tmpdir("same_keys");
  ASSERT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + (d / "a").string() + "\"", d).code, 0);
  ASSERT_EQ(swim_cli("run \"" + kTiny3d + "\" --tier 3d" + kTiny3dFast + " --out \"" + (d / "b").string() + "\"", d).code,
            0);
  const json a = summary_of(d / "a"), b = summary_of(d / "b");
  // the tier-specific summary keys, documented in docs/outputs.md
  const std::set<std::string> only1d = {"pumped_volume_lab_m3", "brownian"};
  const std::set<std::string> only3d = {"steps", "steps_per_cycle", "max_edge_over_h", "max_wrinkle_m", "max_wrinkle_over_h",
                                           "max_wrinkle_mode", "wrinkle_by_cycle", "wrinkle_modes_over_half_cell"};
  std::set<std::string> ka, kb;
  for (const auto& [k, v] : a.items())
    if (!only1d.count(k)) ka.insert(k);
  for (const auto& [k, v] : b.items())
    if (!only3d.count(k)) kb.insert(k);
  EXPECT_EQ(ka, kb);
  for (const char* k : {"tier", "model", "status", "displacement_m", "cycle_start_times_s", "cycle_end_times_s",
                        "displacement_per_cycle_m", "pumped_volume_m3", "plausible", "series_rows", "files"})
    EXPECT_TRUE(a.contains(k) && b.contains(k)) << k;
  for (const char* k : {"C1_Pa_per_m", "mass_per_area_kg_per_m2", "aspect_ratio_R0_over_L", "contracted_ratio",
                        "actuation_pressure_Pa"})
    EXPECT_TRUE(a["derived"].contains(k) && b["derived"].contains(k)) << k;
  // series.csv: the 12 common columns lead in both
  const auto header = [](const fs::path& p) {
    std::ifstream in(p);
    std::string line;
    std::getline(in, line);
    std::vector<std::string> c;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) c.push_back(x);
    return c;
  };
  const auto ha = header(d / "a" / "series.csv"), hb = header(d / "b" / "series.csv");
  const std::vector<std::string> common = {"t_s",           "x_center_m",         "velocity_m_per_s",    "energy_J",
                                           "min_radius_m",  "max_radius_m",       "flux_rear_m3_per_s",  "flux_front_m3_per_s",
                                           "volume_rear_m3", "volume_front_m3",   "tube_volume_m3",      "phase"};
  ASSERT_GE(ha.size(), common.size());
  ASSERT_GE(hb.size(), common.size());
  EXPECT_TRUE(std::equal(common.begin(), common.end(), ha.begin()));
  EXPECT_TRUE(std::equal(common.begin(), common.end(), hb.begin()));
  EXPECT_EQ(header(d / "a" / "radius.csv"), header(d / "b" / "radius.csv"));
  // the rows written are those the summary counts
  const auto rows = [](const fs::path& p) {
    std::ifstream in(p);
    long n = -1;
    for (std::string l; std::getline(in, l);) ++n;
    return n;
  };
  EXPECT_EQ(rows(d / "a" / "series.csv"), a["series_rows"].get<long>());
  EXPECT_EQ(rows(d / "b" / "series.csv"), b["series_rows"].get<long>());
  expect_consistent_folder(d / "a");
  expect_consistent_folder(d / "b");
  fs::remove_all(d);
}

// A 1D run without a size estimate (a force-driven run until its cycles complete) whose
// end-time bound's output exceeds output.max_bytes is first integrated without output: the demo
// (a cycle of 0.52 s) at 20 kB and the default 0.5 ms interval has not completed its cycle when
// its samples (about 2.9 kB each) would reach the limit, so it is refused (exit 2 naming
// time.output_interval and the limit) before anything is written; at a 0.1 s interval its cycle
// completes within the budget and the run writes its results below the limit (exit 0). Fails if
// the run starts and stops at the limit (exit 3, a folder of partial results), or if a run
// that fits is refused.
TEST(RunFolderCli, AnAutoRunWhoseCyclesOutlastTheOutputLimitIsRefusedBeforeItWrites) {
  const fs::path d = tmpdir("runtime_limit");
  const fs::path out = d / "run";
  const Cli c = swim_cli("run \"" + kDemo + "\" --set output.max_bytes=20000 --out \"" + out.string() + "\"", d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("time.output_interval"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("output.max_bytes = 20000"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(out));
  const Cli ok = swim_cli("run \"" + kDemo + "\" --set output.max_bytes=60000 --set time.output_interval='0.1 s' --out \"" +
                              out.string() + "\"",
                          d);
  EXPECT_EQ(ok.code, 0) << ok.err;
  const json s = summary_of(out);
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s["status"], "ok");
  EXPECT_EQ(s["cycles_completed"], 1);
  const auto written = fs::file_size(out / "series.csv") + fs::file_size(out / "radius.csv");
  EXPECT_LT(written, 60000u);
  expect_consistent_folder(out);
  // the same run with the default limit completes
  EXPECT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + (d / "full").string() + "\"", d).code, 0);
  fs::remove_all(d);
}

// The VTK frames count toward the same limit while the run goes: a 3D run with an auto duration
// (no estimate) and a frame every step stops at the frame that passes output.max_bytes, exit 3
// naming the key and the interval of the frames that dominate (membrane or fluid), its files so
// far complete and listed, and at most one frame beyond the limit.
TEST(RunFolderCli, A3dRunWithoutAnEstimateStopsAtTheFrameThatPassesTheOutputLimit) {
  const fs::path d = tmpdir("runtime_limit_3d");
  const fs::path out = d / "run";
  const std::uintmax_t limit = 2000000;  // compressed frames of this scene: about 75 kB each
  const Cli c = swim_cli("run \"" + kTiny3d + "\" --tier 3d --out \"" + out.string() +
                             "\" --set full3d.dt='\"1 ms\"' --set full3d.output.vtk_interval='\"1 ms\"'"
                             " --set time.duration=auto --set output.max_bytes=" + std::to_string(limit),
                         d);
  EXPECT_EQ(c.code, 3) << c.err;
  EXPECT_NE(c.err.find("output.max_bytes = " + std::to_string(limit)), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("raise full3d.output.vtk_interval or output.max_bytes"), std::string::npos) << c.err;
  const json s = summary_of(out);
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s["status"].get<std::string>().rfind("failed", 0), 0u) << s["status"];
  EXPECT_NE(s["status"].get<std::string>().find("output.max_bytes"), std::string::npos) << s["status"];
  expect_consistent_folder(out);
  // what the limit covers: the two series files, the frames and their collection
  std::uintmax_t written = fs::file_size(out / "series.csv") + fs::file_size(out / "radius.csv") +
                           fs::file_size(out / "membrane.pvd");
  std::uintmax_t largest = 0;
  int frames = 0;
  for (const auto& e : fs::directory_iterator(out / "vtk")) {
    written += e.file_size();
    largest = std::max<std::uintmax_t>(largest, e.file_size());
    ++frames;
  }
  EXPECT_GE(frames, 5);
  EXPECT_GT(written, limit);
  // within one frame (and the last row and snapshot, a few kB) of the limit
  EXPECT_LT(written - largest, limit + 4000) << written << " bytes, " << frames << " frames of up to " << largest;
  // every frame written is listed in membrane.pvd
  const std::string pvd = slurp(out / "membrane.pvd");
  int listed = 0;
  for (std::size_t at = pvd.find("<DataSet"); at != std::string::npos; at = pvd.find("<DataSet", at + 1)) ++listed;
  EXPECT_EQ(listed, frames);
  // fluid frames alone: they pass the limit, and their interval is the key to raise
  const fs::path fluid = d / "fluid";
  const Cli f = swim_cli("run \"" + kTiny3d + "\" --tier 3d --out \"" + fluid.string() +
                             "\" --set full3d.dt='\"1 ms\"' --set full3d.output.vtk=false"
                             " --set full3d.output.fluid_fields=true --set full3d.output.vtk_interval='\"1 ms\"'"
                             " --set full3d.output.fluid_interval='\"1 ms\"' --set time.duration=auto"
                             " --set output.max_bytes=600000",
                         d);
  EXPECT_EQ(f.code, 3) << f.err;
  EXPECT_NE(f.err.find("fluid frames"), std::string::npos) << f.err;
  EXPECT_NE(f.err.find("raise full3d.output.fluid_interval or output.max_bytes"), std::string::npos) << f.err;
  EXPECT_FALSE(fs::exists(fluid / "membrane.pvd"));
  expect_consistent_folder(fluid);
  fs::remove_all(d);
}

// swim calibrate keeps what it measured: when the hydraulic radii cannot be measured (here a
// grid so coarse that the lumen holds no velocity sample inside R0 - 2h), calibration.json
// holds the fitted C1 and the axial stiffness with a failed status and no offsets (exit 3), and a 1D scene that asks
// for the offsets from that file is refused naming the key (exit 2).
TEST(CalibrateCli, AFailedHydraulicMeasurementKeepsTheMeasuredStiffness) {
  const fs::path d = tmpdir("calibrate_partial");
  const std::string scene = SWIM_SOURCE_DIR "/data/scenes/tiny_3d_cycle.json";
  const fs::path out = d / "cal";
  const Cli c = swim_cli("calibrate \"" + scene +
                             "\" --set full3d.grid.cell_size='\"0.06 um\"' --set container.period='\"1.32 um\"' "
                             "--set container.radius='\"0.27 um\"' --out \"" + out.string() + "\"",
                         d, "", false);
  EXPECT_EQ(c.code, 3) << c.err;
  EXPECT_NE(c.err.find("hydraulic radii failed"), std::string::npos) << c.err;
  const std::string text = slurp(out / "calibration.json");
  ASSERT_FALSE(text.empty());
  const json j = json::parse(text);
  EXPECT_EQ(j["status"].get<std::string>().rfind("failed: hydraulic radii", 0), 0u) << j["status"];
  EXPECT_NEAR(j["C1_Pa_per_m"].get<double>() / j["C1_spring_network_Pa_per_m"].get<double>(), 1.0, 0.02);
  // the wall's stiffness along the axis is measured before the hydraulic radii and kept too
  ASSERT_TRUE(j.contains("axial_bending_rigidity_J"));
  EXPECT_GT(j["axial_bending_rigidity_J"].get<double>(), 0.0);
  EXPECT_EQ(j["axial_bending_rigidity_J"], j["axial_stiffness"]["bending_rigidity_fit_J"]);
  EXPECT_EQ(j["axial_stiffness"]["C_Pa_per_m"].size(), 4u);
  EXPECT_FALSE(j.contains("hydraulic_offset_inner_m"));
  const Cli r = swim_cli("run \"" + kDemo + "\" --set wall.spring_constant=null --set wall.C1=null --set wall.calibration='\"" +
                             (out / "calibration.json").string() +
                             "\"' --set model1d.hydraulic_offsets.source=calibration --out \"" + (d / "run").string() + "\"",
                         d);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("hydraulic"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "run"));
  fs::remove_all(d);
}

// swim screen and swim calibrate own their output folders like swim run: a folder holding
// another run's results is refused (exit 2, nothing touched) unless --overwrite, the same
// sweep's finished results are replaced, files swim did not write are never removed.
TEST(ScreenCli, AnotherSweepsResultsAreRefusedOrReplacedWithOverwrite) {
  const fs::path d = tmpdir("screen");
  const fs::path out = d / "sweep";
  auto sweep_file = [&](const std::string& name, const json& lengths) {
    const json j = {{"name", name},
                    {"base", kDemo},
                    {"vary", {{"wave.kind", {"step"}}, {"protocol", {nullptr}}, {"swimmer.length", lengths}}}};
    const fs::path p = d / (name + ".json");
    std::ofstream(p) << j.dump();
    return p.string();
  };
  const std::string a = sweep_file("a", {"0.3 um", "0.4 um"}), b = sweep_file("b", {"0.5 um"});
  auto screen = [&](const std::string& sweep, const fs::path& dir, const std::string& flags = "") {
    return swim_cli("screen \"" + sweep + "\" --jobs 1 --out \"" + dir.string() + "\"" + flags, d);
  };
  Cli c = screen(a, out);
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(json::parse(slurp(out / "screen.json"))["status"], "ok");
  EXPECT_EQ(json::parse(slurp(out / ".swim-run.json"))["tier"], "screen");
  EXPECT_EQ(screen(a, out).code, 0);  // the same sweep replaces its own results
  const std::string before = slurp(out / "screen.json"), designs = slurp(out / "designs.csv");
  c = screen(b, out);  // another sweep
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("--overwrite"), std::string::npos) << c.err;
  EXPECT_EQ(c.err.find("--resume"), std::string::npos) << c.err;  // not a 3D run to continue
  EXPECT_EQ(slurp(out / "screen.json"), before);
  EXPECT_EQ(slurp(out / "designs.csv"), designs);
  c = swim_cli("run \"" + kDemo + "\" --out \"" + out.string() + "\"", d);  // a 1D run into the sweep's folder
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_EQ(slurp(out / "designs.csv"), designs);
  c = screen(b, out, " --overwrite");
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_NE(slurp(out / "designs.csv").find("0.5 um"), std::string::npos);
  EXPECT_EQ(slurp(out / "designs.csv").find("0.3 um"), std::string::npos);
  // a run folder and a folder with a file of the user's are refused, even with --overwrite
  const fs::path run = d / "run";
  ASSERT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + run.string() + "\"", d).code, 0);
  const std::string run_summary = slurp(run / "summary.json");
  EXPECT_EQ(screen(a, run).code, 2);
  EXPECT_EQ(slurp(run / "summary.json"), run_summary);
  EXPECT_FALSE(fs::exists(run / "designs.csv"));
  const fs::path mine = d / "mine";
  fs::create_directories(mine);
  std::ofstream(mine / "notes.txt") << "mine";
  c = screen(a, mine, " --overwrite");
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("notes.txt"), std::string::npos) << c.err;
  EXPECT_EQ(slurp(mine / "notes.txt"), "mine");
  EXPECT_FALSE(fs::exists(mine / "designs.csv"));
  fs::remove_all(d);
}

TEST(CalibrateCli, AFolderHoldingAnotherRunsResultsIsRefused) {
  const fs::path d = tmpdir("calibrate_guard");
  const fs::path run = d / "run";
  ASSERT_EQ(swim_cli("run \"" + kDemo + "\" --out \"" + run.string() + "\"", d).code, 0);
  const std::string run_summary = slurp(run / "summary.json");
  const Cli c = swim_cli("calibrate \"" SWIM_SOURCE_DIR "/data/scenes/tiny_3d_cycle.json\" --out \"" + run.string() + "\"",
                         d, "", false);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("--overwrite"), std::string::npos) << c.err;
  EXPECT_EQ(slurp(run / "summary.json"), run_summary);
  EXPECT_FALSE(fs::exists(run / "calibration.json"));
  fs::remove_all(d);
}

// swim calibrate shows its progress like swim run: with --progress a line per load on stderr
// (percentage, loads done, time left), with --quiet none.
TEST(CalibrateCli, ProgressLinesWithProgressNoneWithQuiet) {
  const fs::path d = tmpdir("calibrate_progress");
  const std::string args = "calibrate \"" SWIM_SOURCE_DIR "/data/scenes/tiny_3d_cycle.json\" --set "
                           "full3d.grid.cell_size='\"0.06 um\"' --set container.period='\"1.32 um\"' "
                           "--set container.radius='\"0.27 um\"' --out \"";
  const Cli on = swim_cli(args + (d / "on").string() + "\" --progress", d, "", false);
  EXPECT_EQ(on.code, 3) << on.err;  // the coarse grid: C1 measured, the hydraulic radii not
  // 16 steps: the 13 loads, the axial stiffness, the hydraulic radii, the towed tube
  EXPECT_NE(on.err.find("calibrate tiny_3d_cycle:   6.2%  load 1/13  ~"), std::string::npos) << on.err;
  EXPECT_NE(on.err.find("axial stiffness  ~"), std::string::npos) << on.err;
  EXPECT_NE(on.err.find("s left\n"), std::string::npos) << on.err;
  EXPECT_NE(on.err.find("calibrate tiny_3d_cycle: done in"), std::string::npos) << on.err;
  const Cli off = swim_cli(args + (d / "off").string() + "\"", d);  // --quiet
  EXPECT_EQ(off.code, 3) << off.err;
  EXPECT_EQ(off.err.find("% "), std::string::npos) << off.err;
  EXPECT_EQ(off.err.find("done in"), std::string::npos) << off.err;
  fs::remove_all(d);
}

namespace {
const std::string kL02 = SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json";
}

// A seeded 3D run of the paper's buckling wall (24 cells across, one cycle, about 8 s): the
// summary records the lobes cycle by cycle (the cycle's largest wrinkle is the run's, in the
// seeded m = 8, the only lobe number shown above half a cell), and the note names the lobes
// and the seed that chose them and reports no change.
TEST(RunFolderCli, ASeededBucklingRunRecordsItsLobesCycleByCycle) {
  const fs::path d = tmpdir("lobes");
  const fs::path out = d / "run";
  const Cli c = swim_cli("run \"" + kL02 + "\" --tier 3d --threads 1 --set full3d.grid.cells_across=24" +
                             " --set full3d.membrane.seed_mode=8 --set full3d.membrane.seed_amplitude=0.01" +
                             " --out \"" + out.string() + "\"",
                         d);
  ASSERT_EQ(c.code, 0) << c.err;
  const json s = summary_of(out);
  ASSERT_EQ(s["cycles_completed"].get<int>(), 1);
  ASSERT_TRUE(s["wrinkle_by_cycle"].is_array());
  ASSERT_EQ(s["wrinkle_by_cycle"].size(), 1u);  // the row at the cycle's end belongs to the cycle
  const json& c1 = s["wrinkle_by_cycle"][0];
  EXPECT_EQ(c1["cycle"].get<int>(), 1);
  EXPECT_EQ(c1["max_wrinkle_m"].get<double>(), s["max_wrinkle_m"].get<double>());
  EXPECT_EQ(c1["max_wrinkle_mode"].get<int>(), 8);
  EXPECT_GT(s["max_wrinkle_over_h"].get<double>(), 0.5);
  EXPECT_EQ(c1["modes_over_half_cell"].get<std::vector<int>>(), std::vector<int>({8}));
  EXPECT_EQ(s["wrinkle_modes_over_half_cell"].get<std::vector<int>>(), std::vector<int>({8}));
  EXPECT_NE(c.err.find("buckled into m = 8 lobes"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("full3d.membrane.seed_mode = 8"), std::string::npos) << c.err;
  EXPECT_EQ(c.err.find("lobes changed"), std::string::npos) << c.err;
}
