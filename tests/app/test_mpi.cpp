// `mpirun -n 3 swim …` against the single process (docs/mpi.md): the same designs.csv,
// confirm.json and validation report.json (wall times, the cache's reuse flags and the folder
// names aside); a rank killed mid-run is reported and its runs redone (--enable-recovery), or the
// job stops with the runs in flight named and a rerun reuses the finished runs. Three ranks on
// loopback, oversubscribed; skipped, saying why, when mpirun or MPI is absent.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "common/scene.hpp"
#include "tests/support/files.hpp"

namespace fs = std::filesystem;
using swim::scene::json;
using swim::test::slurp;

namespace {

const std::string kSwim = SWIM_BINARY_DIR "/bin/swim";
const std::string kTiny = SWIM_SOURCE_DIR "/data/scenes/tiny_3d_cycle.json";

#define SKIP_WITHOUT_MPI()                                                                                    \
  do {                                                                                                        \
    if (std::string(SWIM_MPIEXEC).empty())                                                                    \
      GTEST_SKIP() << "mpirun was not found when the build was configured (Debian openmpi-bin): MPI runs "    \
                      "are not tested";                                                                       \
    if (!SWIM_BUILT_WITH_MPI) GTEST_SKIP() << "swim was built without MPI (SWIM_MPI=OFF or no libopenmpi-dev)"; \
  } while (0)

struct Cli {
  int code = -1;
  std::string out, err;
};

// `env` is prepended to the command ("VAR=value ... ").
Cli sh(const std::string& cmd, const fs::path& scratch, const std::string& tag) {
  const fs::path o = scratch / (tag + ".out"), e = scratch / (tag + ".err");
  const int status = std::system((cmd + " > \"" + o.string() + "\" 2> \"" + e.string() + "\"").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(o), slurp(e)};
}

// Three ranks on one machine, over loopback; root needs Open MPI's explicit consent.
std::string mpirun(const std::string& extra = "") {
  std::string s = std::string("\"") + SWIM_MPIEXEC + "\" --oversubscribe -n 3 --mca btl self,tcp --mca btl_tcp_if_include lo "
                  "--mca oob_tcp_if_include lo";
  if (::geteuid() == 0) s += " --allow-run-as-root";
  return s + " " + extra + " ";
}

json read(const fs::path& p) { return json::parse(slurp(p)); }
void write(const fs::path& p, const json& j) { std::ofstream(p) << j.dump(2); }

// A copy without the figures that differ from one invocation to the next (wall times, whether
// a run was made here or reused, the cache's counters), the output folder's name written OUT.
json comparable(const json& j, const std::string& out) {
  if (j.is_object()) {
    json r = json::object();
    for (auto it = j.begin(); it != j.end(); ++it) {
      const std::string& k = it.key();
      if (k.find("wall_time") != std::string::npos || k == "cached" || k == "reused_3d" || k == "cache" || k == "mpi" ||
          k == "designs_per_s")
        continue;
      r[k] = comparable(it.value(), out);
    }
    return r;
  }
  if (j.is_array()) {
    json r = json::array();
    for (const auto& v : j) r.push_back(comparable(v, out));
    return r;
  }
  if (j.is_string()) {  // paths inside the output folder, relative or absolute, name it OUT
    std::string v = j.get<std::string>();
    for (const std::string& o : {fs::absolute(out).string(), out})
      for (std::size_t at; (at = v.find(o)) != std::string::npos;) v.replace(at, o.size(), "OUT");
    return v;
  }
  return j;
}

// designs.csv without its last column (wall_time_s).
std::string without_wall_times(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, out;
  while (std::getline(in, line)) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}

// The tiny duct scene cut to `duration`, its contracted ratio swept over five values.
json tiny_sweep(const std::string& duration) {
  json s = json::parse(slurp(kTiny));
  s["time"]["duration"] = duration;
  return {{"name", "tiny"},
          {"base", s},
          {"vary", {{"wave.contracted_ratio", {{"values", {0.6, 0.7, 0.75, 0.8, 0.9}}}}}},
          {"metric", "mean_velocity_m_per_s"},
          {"goal", "max"}};
}

// A wrapper that kills rank 1 (SIGKILL) `after` seconds into the command.
fs::path killer(const fs::path& d, double after) {
  const fs::path k = d / "kill_rank1.sh";
  std::ofstream(k) << "#!/bin/sh\nif [ \"${OMPI_COMM_WORLD_RANK:-0}\" = 1 ]; then\n  \"$@\" & pid=$!\n  sleep " << after
                   << "\n  kill -9 $pid\n  wait $pid\n  exit 137\nfi\nexec \"$@\"\n";
  fs::permissions(k, fs::perms::owner_all);
  return k;
}

}  // namespace

TEST(MpiScreen, ThreeRanksWriteTheDesignsAndTheConfirmationOfOneProcess) {
  SKIP_WITHOUT_MPI();
  const fs::path d = swim::test::scratch_dir("swim_mpi_screen");
  write(d / "tiny.json", tiny_sweep("20 ms"));
  // (with the grid check: each design's second run, on twice its cells, is a task of its own)
  const std::string args = " screen \"" + (d / "tiny.json").string() + "\" --confirm 4 --grid-check 0.05 --quiet --out ";
  const Cli one = sh("\"" + kSwim + "\"" + args + "\"" + (d / "one").string() + "\" --jobs 1", d, "one");
  ASSERT_EQ(one.code, 0) << one.err;
  const Cli three = sh(mpirun() + "\"" + kSwim + "\"" + args + "\"" + (d / "three").string() + "\"", d, "three");
  ASSERT_EQ(three.code, 0) << three.err;
  // every design's figures, to the last digit written, and the same 3D runs and agreement
  EXPECT_EQ(without_wall_times(slurp(d / "three/designs.csv")), without_wall_times(slurp(d / "one/designs.csv")));
  const json c1 = read(d / "one/confirm.json"), c3 = read(d / "three/confirm.json");
  EXPECT_EQ(comparable(c3, (d / "three").string()), comparable(c1, (d / "one").string()));
  EXPECT_EQ(c3["designs"].size(), 4u);
  for (const auto& x : c3["designs"]) EXPECT_EQ(x["reused_3d"], false);  // run by the ranks, not found
  // screen.json says how the work was spread: three ranks, none lost, every run kept once
  const json s3 = read(d / "three/screen.json");
  ASSERT_TRUE(s3.contains("mpi")) << s3.dump();
  EXPECT_EQ(s3["mpi"]["ranks"], 3);
  EXPECT_TRUE(s3["mpi"]["lost_ranks"].empty());
  long kept = 0;
  for (const auto& [r, n] : s3["mpi"]["tasks_per_rank"].items()) kept += n.get<long>();
  EXPECT_EQ(kept, 2 * 5 + 4);  // five 1D designs on two grids, four 3D runs
  EXPECT_FALSE(read(d / "one/screen.json").contains("mpi"));
  EXPECT_EQ(s3["grid_check"], read(d / "one/screen.json")["grid_check"]);
  EXPECT_EQ(s3["grid_check"]["designs_compared"], 5);
}

TEST(MpiScreen, AKilledRankIsReportedItsRunsRedoneOrTheRestartReusesTheFinishedRuns) {
  SKIP_WITHOUT_MPI();
  const fs::path d = swim::test::scratch_dir("swim_mpi_kill");
  write(d / "tiny.json", tiny_sweep("400 ms"));  // about a second per 3D run
  const std::string args = " screen \"" + (d / "tiny.json").string() + "\" --confirm 4 --quiet --out ";
  const Cli one = sh("\"" + kSwim + "\"" + args + "\"" + (d / "one").string() + "\" --jobs 1", d, "one");
  ASSERT_EQ(one.code, 0) << one.err;
  const json ref = comparable(read(d / "one/confirm.json"), (d / "one").string());
  const fs::path kill = killer(d, 1.5);

  // --enable-recovery: the others go on; rank 1 is declared lost after 3 s of silence and the
  // runs it held are redone
  const Cli rec = sh("SWIM_MPI_LOST_AFTER_S=3 " + mpirun("--enable-recovery") + "\"" + kill.string() + "\" \"" + kSwim +
                         "\"" + args + "\"" + (d / "recovered").string() + "\"",
                     d, "recovered");
  ASSERT_EQ(rec.code, 0) << rec.err;
  EXPECT_NE(rec.err.find("swim: rank 1 lost"), std::string::npos) << rec.err;
  const json s = read(d / "recovered/screen.json");
  ASSERT_EQ(s["mpi"]["lost_ranks"].size(), 1u) << s.dump();
  EXPECT_EQ(s["mpi"]["lost_ranks"][0]["rank"], 1);
  EXPECT_EQ(without_wall_times(slurp(d / "recovered/designs.csv")), without_wall_times(slurp(d / "one/designs.csv")));
  EXPECT_EQ(comparable(read(d / "recovered/confirm.json"), (d / "recovered").string()), ref);

  // without it mpirun ends the job: rank 0 names the runs in flight and writes no report
  const Cli aborted = sh(mpirun() + "\"" + kill.string() + "\" \"" + kSwim + "\"" + args + "\"" +
                             (d / "restarted").string() + "\"",
                         d, "aborted");
  EXPECT_NE(aborted.code, 0);
  // the user is told the job was stopped: by rank 0 when mpirun's SIGTERM reaches it before the
  // SIGKILL that follows (not guaranteed on a loaded machine), by mpirun in any case; mpirun
  // names the rank that died
  EXPECT_TRUE(aborted.err.find("swim: stopped by") != std::string::npos ||
              aborted.err.find("interrupted by SIGTERM") != std::string::npos ||
              aborted.err.find("the job has been aborted") != std::string::npos)
      << aborted.err;
  EXPECT_TRUE(aborted.err.find(",1]") != std::string::npos || aborted.err.find("rank 1") != std::string::npos)
      << aborted.err;
  EXPECT_FALSE(fs::exists(d / "restarted/confirm.json"));
  // screen.json is written only when the job stops while the screen's figure is drawn (on a
  // loaded machine the kill can come that late), and then its status says it was interrupted
  if (fs::exists(d / "restarted/screen.json"))
    EXPECT_NE(read(d / "restarted/screen.json")["status"].get<std::string>().find("interrupted"), std::string::npos)
        << slurp(d / "restarted/screen.json");
  // the runs that finished before the abort are reused by the restart, the others run again
  long finished = 0;
  if (fs::exists(d / "restarted/confirm-runs"))
    for (const auto& e : fs::directory_iterator(d / "restarted/confirm-runs"))
      if (fs::exists(e.path() / "summary.json") && read(e.path() / "summary.json")["status"] == "ok") ++finished;
  const Cli again = sh(mpirun() + "\"" + kSwim + "\"" + args + "\"" + (d / "restarted").string() + "\"", d, "again");
  ASSERT_EQ(again.code, 0) << again.err;
  const json c = read(d / "restarted/confirm.json");
  long reused = 0;
  for (const auto& x : c["designs"]) reused += x["reused_3d"].get<bool>();
  EXPECT_EQ(reused, finished) << aborted.err;
  EXPECT_EQ(comparable(c, (d / "restarted").string()), ref);
}

TEST(MpiValidate, ThreeRanksWriteTheReportOfOneProcess) {
  SKIP_WITHOUT_MPI();
  const fs::path d = swim::test::scratch_dir("swim_mpi_validate");
  // the quick suite cut down: two coarse grids, a time-step variant, two 1D models, an extreme
  // that fails and one the 3D tier refuses
  json q = read(SWIM_SOURCE_DIR "/data/validation/quick.json");
  q["name"] = "mpi_tiny";
  q["cells1d"] = {50};
  q["rtol1d"] = {1e-4};
  json& c = q["cases"][0];
  c["scene"] = kTiny;
  c["grids"] = {{{"cells_across", 12}}, {{"cells_across", 15}}};
  c["calibration_grid"] = 0;
  c["time_variants3d"] = {{{"label", "dt = 2 ms"}, {"set", {{"full3d.dt", "2 ms"}}}}};
  q["models1d"] = {q["models1d"][0], q["models1d"][1]};
  json ex = json::array();
  for (auto e : q["extremes3d"])
    if (e["label"].get<std::string>().rfind("dt", 0) == 0 || e["expect"] == "rejected") {
      e["scene"] = kTiny;
      ex.push_back(e);
    }
  q["extremes3d"] = ex;
  write(d / "suite.json", q);
  const std::string args = " validate \"" + (d / "suite.json").string() + "\" --threads 1 --quiet --out ";
  const Cli one = sh("\"" + kSwim + "\"" + args + "\"" + (d / "one").string() + "\"", d, "one");
  ASSERT_EQ(one.code, 0) << one.err;
  // with --progress the ranks' runs report as they start and finish, with the time left, and
  // each computed run's own progress lines name the run and its rank
  std::string progress_args = args;
  progress_args.replace(progress_args.find("--quiet"), 7, "--progress");
  const Cli three = sh(mpirun() + "\"" + kSwim + "\"" + progress_args + "\"" + (d / "three").string() + "\"", d, "three");
  ASSERT_EQ(three.code, 0) << three.err;
  const json plan_lines = [&] {
    json n = json::object();
    for (const char* what : {"started on rank ", " done; ", " done; about ", ": done in "}) {
      long k = 0;
      for (std::size_t at = three.err.find(what); at != std::string::npos; at = three.err.find(what, at + 1)) ++k;
      n[what] = k;
    }
    return n;
  }();
  const long planned = plan_lines["started on rank "];
  EXPECT_GE(planned, 5) << three.err;  // two grids, the variant, the calibration, an extreme
  EXPECT_EQ(plan_lines[" done; "], planned) << three.err;
  EXPECT_GE(plan_lines[" done; about "], 1) << three.err;  // the time left, once a run of a kind is timed
  EXPECT_NE(three.err.find("validate: run 1/" + std::to_string(planned) + " started on rank "), std::string::npos)
      << three.err;
  EXPECT_NE(three.err.find(" of " + std::to_string(planned) + " done; the report next"), std::string::npos)
      << three.err;
  EXPECT_TRUE(std::regex_search(three.err, std::regex("\\nrun [0-9]+/" + std::to_string(planned) +
                                                       " on rank [0-2]: 3d [^\\n]*: done in ")))
      << three.err;
  const json r1 = read(d / "one/report.json"), r3 = read(d / "three/report.json");
  EXPECT_EQ(comparable(r3, (d / "three").string()), comparable(r1, (d / "one").string()));
  // the ranks made the 3D runs; the report's pass found them in the cache, verified
  EXPECT_EQ(r1["cache"]["reused"], 0);
  EXPECT_GE(r3["cache"]["reused"].get<long>(), 3);  // two grids and the variant at least
  EXPECT_TRUE(r3["cache"]["verified"].get<bool>());
  ASSERT_EQ(r3["cases"][0]["runs3d"].size(), 2u);
  for (const auto& run : r3["cases"][0]["runs3d"]) EXPECT_EQ(run["cached"], true);
  EXPECT_EQ(r3["extremes3d"].size(), 2u);
  // again into the same folder: the grids' runs come from the cache, and say so instead of a time
  const Cli again = sh(mpirun() + "\"" + kSwim + "\"" + progress_args + "\"" + (d / "three").string() + "\"", d, "again");
  ASSERT_EQ(again.code, 0) << again.err;
  for (const char* grid : {"{\"cells_across\":12}", "{\"cells_across\":15}"})
    EXPECT_TRUE(std::regex_search(again.err, std::regex(std::string("3d run of tiny_3d_cycle at ") +
                                                        std::regex_replace(grid, std::regex("[{}]"), "\\$&") +
                                                        " on rank [0-2] \\(from the cache\\): ok;")))
        << grid << "\n" << again.err;
}
