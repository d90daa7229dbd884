// `swim run --tier 3d` end to end on the small scene: the contract files, exit 2 for bad
// input such as an unknown cylinder wall method (nothing written), exit 3 with partial results for an unstable dt,
// --resume of a finished run folder, a damaged checkpoint refused (exit 2, folder untouched)
// and a checkpoint that cannot be written (exit 3 naming it).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <thread>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/run_folder.hpp"

namespace fs = std::filesystem;

namespace {
int swim_cli(const std::string& args) {
  const int s = std::system((std::string("\"") + SWIM_BINARY_DIR + "/bin/swim\" " + args + " > /dev/null 2>&1").c_str());
  return WIFEXITED(s) ? WEXITSTATUS(s) : -1;
}
// exit code and stderr
std::pair<int, std::string> swim_err(const std::string& args, const std::string& env = "") {
  const std::string err = std::string(SWIM_BINARY_DIR) + "/tests/out_run3d_cli/stderr.txt";
  fs::create_directories(fs::path(err).parent_path());
  const int s = std::system((env + " \"" + SWIM_BINARY_DIR + "/bin/swim\" " + args + " > /dev/null 2> \"" + err + "\"").c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(s) ? WEXITSTATUS(s) : -1, ss.str()};
}
// every file of a folder (relative name -> content)
std::map<std::string, std::string> snapshot(const std::string& d) {
  std::map<std::string, std::string> m;
  for (const auto& e : fs::recursive_directory_iterator(d)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    m[fs::relative(e.path(), d).string()] = ss.str();
  }
  return m;
}
const std::string kScene = "\"" SWIM_SOURCE_DIR "/data/scenes/tiny_3d.json\"";
std::string dir(const std::string& n) {
  const std::string d = std::string(SWIM_BINARY_DIR) + "/tests/out_run3d_cli/" + n;
  fs::remove_all(d);
  return d;
}
}  // namespace

TEST(SwimRun3d, WritesContractFiles) {
  const std::string d = dir("ok");
  ASSERT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --out \"" + d +
                 "\" --set full3d.dt='\"1 ms\"' --set time.duration='\"12 ms\"' --set full3d.output.vtk_interval='\"5 ms\"'"
                 " --set full3d.output.fluid_fields=true --set full3d.output.fluid_interval='\"10 ms\"'"),
            0);
  for (const char* f : {"summary.json", "series.csv", "radius.csv", "solver_stats.json", "scene.resolved.json",
                        "membrane.pvd", "fluid.pvd", "checkpoint.bin", "vtk/membrane_000000.vtp",
                        "vtk/membrane_000002.vtp", "vtk/fluid_000001.vti"})
    EXPECT_TRUE(fs::exists(d + "/" + f)) << f;
  std::ifstream in(d + "/summary.json");
  const auto s = nlohmann::json::parse(in);
  for (const char* k : {"tier", "scene", "displacement_m", "max_displacement_m", "cycles_completed", "cycle_times_s", "mean_velocity_m_per_s",
                        "body_lengths_per_s", "pumped_volume_m3", "wall_time_s", "status"})
    EXPECT_TRUE(s.contains(k)) << k;
  EXPECT_EQ(s["tier"], "3d");
  EXPECT_GE(s["max_displacement_m"].get<double>(), s["displacement_m"].get<double>());
  EXPECT_EQ(s["status"], "ok");
  EXPECT_EQ(s["scene"]["container"]["kind"], "duct");
  std::ifstream csv(d + "/series.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("t_s,x_center_m,velocity_m_per_s,energy_J,min_radius_m,max_radius_m", 0), 0u);
  // a finished run resumes to the same end (nothing left to do)
  EXPECT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --resume \"" + d +
                 "\" --set full3d.dt='\"1 ms\"' --set time.duration='\"12 ms\"' --set full3d.output.vtk_interval='\"5 ms\"'"
                 " --set full3d.output.fluid_fields=true --set full3d.output.fluid_interval='\"10 ms\"'"),
            0);
}

TEST(SwimRun3d, BadInputExits2AndWritesNothing) {
  const std::string d = dir("bad");
  EXPECT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set container.kind='\"cylinder\"'"
                 " --set full3d.scheme='\"bogus\"'"), 2);
  EXPECT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set full3d.bogus=1"), 2);
  EXPECT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set wave.kind='\"step\"' --set protocol=null"), 2);
  EXPECT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set wall.C1='\"4e6 Pa/m\"' --set wall.spring_constant=null"), 2);
  EXPECT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set container.radius='\"0.15 um\"'"), 2);
  // Chebyshev stages without the adaptive step that chooses them: the message names the key
  const auto [code, msg] = swim_err("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set full3d.scheme='\"chebyshev\"'");
  EXPECT_EQ(code, 2);
  EXPECT_NE(msg.find("'full3d.scheme'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("full3d.adaptive.enabled"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(d));
}

TEST(SwimRun3d, UnstableTimeStepExits3WithPartialResults) {
  const std::string d = dir("unstable");
  EXPECT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --out \"" + d +
                 "\" --set full3d.dt='\"50 ms\"' --set time.duration='\"2 s\"'"),
            3);
  std::ifstream in(d + "/summary.json");
  const auto s = nlohmann::json::parse(in);
  EXPECT_EQ(s["status"].get<std::string>().rfind("failed: ", 0), 0u);
  EXPECT_TRUE(fs::exists(d + "/checkpoint.bin"));
}

TEST(SwimRun3d, ADamagedCheckpointIsExitTwoAndTheFolderIsUntouched) {
  const std::string d = dir("damaged");
  const std::string sets = " --set full3d.dt='\"1 ms\"' --set time.duration='\"6 ms\"' --set full3d.checkpoint_interval='\"2 ms\"'";
  ASSERT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --out \"" + d + "\"" + sets), 0);
  const std::string ck = d + "/checkpoint.bin";
  std::string bytes = snapshot(d)["checkpoint.bin"];
  ASSERT_GT(bytes.size(), 1000u);
  bytes[bytes.size() / 2] ^= 0x20;
  std::ofstream(ck, std::ios::binary | std::ios::trunc) << bytes;
  const auto before = snapshot(d);
  const auto [code, err] = swim_err("run " + kScene + " --tier 3d --quiet --resume \"" + d + "\"" + sets);
  EXPECT_EQ(code, 2) << err;
  EXPECT_NE(err.find("checkpoint.bin"), std::string::npos) << err;
  EXPECT_NE(err.find("checksum"), std::string::npos) << err;
  EXPECT_NE(err.find("--overwrite"), std::string::npos) << err;
  EXPECT_EQ(snapshot(d), before);
  // as advised: the run again with --overwrite
  EXPECT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --overwrite --out \"" + d + "\"" + sets), 0);
}

TEST(SwimRun3d, ACheckpointWriteFailureIsExitThreeNamingTheFile) {
  const std::string d = dir("checkpoint_full");
  const auto [code, err] = swim_err("run " + kScene + " --tier 3d --quiet --out \"" + d +
                                        "\" --set full3d.dt='\"1 ms\"' --set time.duration='\"6 ms\"'",
                                    "SWIM_TEST_FAIL_WRITE=checkpoint.bin:100");
  EXPECT_EQ(code, 3) << err;
  EXPECT_NE(err.find("disk full while writing checkpoint.bin"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(d + "/checkpoint.bin"));
  for (const auto& e : fs::recursive_directory_iterator(d))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  std::ifstream in(d + "/summary.json");
  if (in) {
    EXPECT_EQ(nlohmann::json::parse(in)["status"].get<std::string>().rfind("failed: ", 0), 0u);
  }
}

// SIGTERM sent to a running `swim run --tier 3d` just after it wrote a checkpoint: the folder
// says "running", and its summary.json lists checkpoint.bin (and every file of the checkpoint)
// with the size and checksum on disk; `--resume` finishes the run, its folder verifies as a
// whole, and series.csv is byte-identical to the uninterrupted run's.
TEST(SwimRun3d, ASigtermedRunsFolderDescribesItsCheckpointAndItsResumeEqualsTheWholeRun) {
  const std::string sets = " --set full3d.dt='\"1 ms\"' --set time.duration='\"400 ms\"' --set time.output_interval='\"1 ms\"'"
                           " --set full3d.checkpoint_interval='\"20 ms\"' --set full3d.output.vtk_interval='\"50 ms\"'";
  const std::string whole = dir("sigterm_whole"), cut = dir("sigterm_cut");
  ASSERT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --out \"" + whole + "\"" + sets), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string exe = std::string(SWIM_BINARY_DIR) + "/bin/swim";
    const std::string cmd = "exec \"" + exe + "\" run " + kScene + " --tier 3d --quiet --out \"" + cut + "\"" + sets +
                            " > /dev/null 2>&1";
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // the first summary written at a checkpoint (status "running", checkpoint.bin listed)
  bool at_checkpoint = false;
  const auto t0 = std::chrono::steady_clock::now();
  while (!at_checkpoint && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    std::ifstream in(cut + "/summary.json");
    const auto j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.contains("status") || j["status"].get<std::string>().rfind("running", 0) != 0) continue;
    for (const auto& f : j["files"])
      if (f["name"] == "checkpoint.bin") at_checkpoint = true;
  }
  ASSERT_TRUE(at_checkpoint) << "the run never wrote a checkpoint";
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << "the run ended before the signal: " << status;
  // the folder as the signal left it: the summary describes the files of its checkpoint exactly
  {
    std::ifstream in(cut + "/summary.json");
    const auto j = nlohmann::json::parse(in);
    EXPECT_EQ(j["status"].get<std::string>().rfind("running", 0), 0u) << j["status"];
    int exact = 0;
    for (const auto& f : j["files"]) {
      const std::string name = f["name"], path = cut + "/" + name;
      ASSERT_TRUE(fs::exists(path)) << name;
      if (name.size() > 5 && name.substr(name.size() - 5) == ".part") {
        EXPECT_LE(f["bytes"].get<std::uintmax_t>(), fs::file_size(path)) << name;  // streamed on since
        continue;
      }
      EXPECT_EQ(f["bytes"].get<std::uintmax_t>(), fs::file_size(path)) << name;
      EXPECT_EQ(f["fnv1a64"], swim::output::file_checksum(path)) << name;
      ++exact;
    }
    EXPECT_GE(exact, 2);  // checkpoint.bin and scene.resolved.json at least
  }
  ASSERT_EQ(swim_cli("run " + kScene + " --tier 3d --quiet --resume \"" + cut + "\"" + sets), 0);
  EXPECT_EQ(swim::output::verify_folder(cut, {"series.csv", "radius.csv", "checkpoint.bin"}), "");
  EXPECT_EQ(snapshot(cut)["series.csv"], snapshot(whole)["series.csv"]);
  EXPECT_EQ(snapshot(cut)["radius.csv"], snapshot(whole)["radius.csv"]);
}
