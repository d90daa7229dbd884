// `swim run --tier 3d` end to end on the small scene: the contract files, exit 2 for bad
// input such as an unknown cylinder wall method (nothing written), exit 3 with partial results for an unstable dt,
// --resume of a finished run folder, a damaged checkpoint refused (exit 2, folder untouched)
// and a checkpoint that cannot be written (exit 3 naming it).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

namespace fs = std::filesystem;

namespace {
int swim(const std::string& args) {
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
  ASSERT_EQ(swim("run " + kScene + " --tier 3d --quiet --out \"" + d +
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
  EXPECT_EQ(swim("run " + kScene + " --tier 3d --quiet --resume \"" + d +
                 "\" --set full3d.dt='\"1 ms\"' --set time.duration='\"12 ms\"' --set full3d.output.vtk_interval='\"5 ms\"'"
                 " --set full3d.output.fluid_fields=true --set full3d.output.fluid_interval='\"10 ms\"'"),
            0);
}

TEST(SwimRun3d, BadInputExits2AndWritesNothing) {
  const std::string d = dir("bad");
  EXPECT_EQ(swim("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set container.kind='\"cylinder\"'"
                 " --set full3d.scheme='\"bogus\"'"), 2);
  EXPECT_EQ(swim("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set full3d.bogus=1"), 2);
  EXPECT_EQ(swim("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set wave.kind='\"step\"' --set protocol=null"), 2);
  EXPECT_EQ(swim("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set wall.C1='\"4e6 Pa/m\"' --set wall.spring_constant=null"), 2);
  EXPECT_EQ(swim("run " + kScene + " --tier 3d --quiet --out \"" + d + "\" --set container.radius='\"0.15 um\"'"), 2);
  EXPECT_FALSE(fs::exists(d));
}

TEST(SwimRun3d, UnstableTimeStepExits3WithPartialResults) {
  const std::string d = dir("unstable");
  EXPECT_EQ(swim("run " + kScene + " --tier 3d --quiet --out \"" + d +
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
  ASSERT_EQ(swim("run " + kScene + " --tier 3d --quiet --out \"" + d + "\"" + sets), 0);
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
  EXPECT_EQ(swim("run " + kScene + " --tier 3d --quiet --overwrite --out \"" + d + "\"" + sets), 0);
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
