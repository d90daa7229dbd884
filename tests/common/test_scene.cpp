// Scene reading: defaults filled and echoed, overrides, unknown keys, and the corpus of
// malformed scenes (in process: the InputError names the expected key; through the
// executable: exit code 2, the key in the message, and nothing written).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "common/errors.hpp"
#include "common/scene.hpp"
#include "reduced1d/scene1d.hpp"

namespace fs = std::filesystem;
using swim::InputError;
using swim::scene::json;

TEST(Scene, EmptySceneGetsEveryDefaultAndTheEchoIsItselfAValidScene) {
  json resolved;
  const auto p = swim::reduced1d::read_scene(json::object(), resolved);
  EXPECT_NEAR(p.geometry.R0, 0.125e-6, 1e-20);
  EXPECT_NEAR(p.geometry.L, 0.4e-6, 1e-20);
  EXPECT_EQ(resolved["swimmer"]["radius"], "0.125 um");
  EXPECT_EQ(resolved["wave"]["kind"], "force_driven");
  EXPECT_EQ(resolved["model1d"]["model"], "force_free");
  EXPECT_EQ(resolved["model1d"]["outer_flow"], "confined");
  EXPECT_EQ(resolved["container"]["kind"], "duct");
  EXPECT_EQ(resolved["fluid"]["temperature"], "310 K");
  EXPECT_FALSE(resolved["model1d"].contains("paper"));
  json again;
  const auto q = swim::reduced1d::read_scene(resolved, again);
  EXPECT_EQ(resolved, again);
  EXPECT_DOUBLE_EQ(p.wall.C1, q.wall.C1);
  EXPECT_DOUBLE_EQ(p.protocol.q, q.protocol.q);
}

TEST(Scene, SpringNetworkStiffnessAndMassPerLengthConvertAsDocumented) {
  json resolved;
  const auto p = swim::reduced1d::read_scene(json::object(), resolved);
  // C1 = 2 k_s / (sqrt 3 R0^2), m = m_l / (2 pi R0)
  EXPECT_NEAR(p.wall.C1, 2 * 5.5e-8 / (std::sqrt(3.0) * 0.125e-6 * 0.125e-6), 1e-6 * p.wall.C1);
  EXPECT_NEAR(p.wall.m, 2.25e-6 / (2 * M_PI * 0.125e-6), 1e-9 * p.wall.m);
  // total force spread over the wall area
  EXPECT_NEAR(p.protocol.q, 1e-13 / (2 * M_PI * 0.125e-6 * 0.4e-6), 1e-9 * p.protocol.q);
}

TEST(Scene, OverridesUseTheFileSyntaxAndNullRemovesAKey) {
  json s = json::object();
  swim::scene::apply_override(s, "swimmer.length=0.2 um");
  swim::scene::apply_override(s, "numerics1d.cells=64");
  swim::scene::apply_override(s, "model1d.model=paper");
  swim::scene::apply_override(s, "model1d.paper.thrust=false");
  json resolved;
  const auto p = swim::reduced1d::read_scene(s, resolved);
  EXPECT_NEAR(p.geometry.L, 0.2e-6, 1e-20);
  EXPECT_EQ(p.numerics.cells, 64);
  EXPECT_FALSE(p.swimmer.thrust);
  swim::scene::apply_override(s, "swimmer.length=null");
  EXPECT_FALSE(s["swimmer"].contains("length"));
  EXPECT_THROW(swim::scene::apply_override(s, "noequals"), InputError);
  swim::scene::apply_override(s, "swimmer.length=0.3 um");
  EXPECT_THROW(swim::scene::apply_override(s, "swimmer.length.x=1"), InputError);  // path through a string
}

namespace {
json manifest() {
  std::ifstream in(SWIM_SOURCE_DIR "/tests/data/malformed/manifest.json");
  return json::parse(in);
}
}  // namespace

TEST(MalformedScenes, CorpusHasAtLeastTwentyCases) { EXPECT_GE(manifest().size(), 20u); }

TEST(MalformedScenes, EachIsRejectedNamingTheOffendingKey) {
  const std::string dir = SWIM_SOURCE_DIR "/tests/data/malformed/";
  for (const auto& c : manifest()) {
    const std::string file = c["file"], key = c["key"];
    SCOPED_TRACE(file);
    try {
      json s = swim::scene::load_file(dir + file);
      json resolved;
      swim::reduced1d::read_scene(s, resolved, dir);
      ADD_FAILURE() << file << " was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  }
}

TEST(MalformedScenes, TheExecutableExitsWithCodeTwoAndWritesNothing) {
  const std::string dir = SWIM_SOURCE_DIR "/tests/data/malformed/";
  const fs::path tmp = fs::temp_directory_path() / "swim_malformed_test";
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  for (const auto& c : manifest()) {
    const std::string file = c["file"], key = c["key"];
    SCOPED_TRACE(file);
    const fs::path out = tmp / "run";
    const fs::path err = tmp / "stderr.txt";
    const std::string cmd = std::string("\"") + SWIM_BINARY_DIR + "/bin/swim\" run \"" + dir + file + "\" --out \"" +
                            out.string() + "\" > /dev/null 2> \"" + err.string() + "\"";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2);
    EXPECT_FALSE(fs::exists(out)) << "output written for a rejected scene";
    std::ifstream in(err);
    const std::string msg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(msg.find("'" + key + "'"), std::string::npos) << msg;
  }
  fs::remove_all(tmp);
}

TEST(Cli, BadFlagsExitWithCodeTwo) {
  const std::string swim = std::string("\"") + SWIM_BINARY_DIR + "/bin/swim\"";
  for (const std::string args : {"run", "run x.json --tier 2d", "frobnicate", "screen", "run /no/such/scene.json"}) {
    const int status = std::system((swim + " " + args + " > /dev/null 2>&1").c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2) << args;
  }
}

TEST(Scene, WallStiffnessFromACalibrationFileRelativeToTheScene) {
  const fs::path dir = fs::temp_directory_path() / "swim_calib_test";
  fs::create_directories(dir);
  std::ofstream(dir / "calibration.json") << R"({"C1_Pa_per_m": 3.5e6, "C1_stderr_Pa_per_m": 1e4})";
  json s = {{"wall", {{"calibration", "calibration.json"}}}};
  json resolved;
  const auto p = swim::reduced1d::read_scene(s, resolved, dir.string());
  EXPECT_DOUBLE_EQ(p.wall.C1, 3.5e6);
  EXPECT_EQ(resolved["wall"]["calibration"], "calibration.json");
  std::ofstream(dir / "bad.json") << R"({"C1": 3.5e6})";
  s["wall"]["calibration"] = "bad.json";
  try {
    swim::reduced1d::read_scene(s, resolved, dir.string());
    FAIL() << "accepted a calibration file without C1_Pa_per_m";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "wall.calibration");
  }
  fs::remove_all(dir);
}
