// Every scene key that a message of the 1D tier names (InputError and NumericalError
// remedies: exit 2 / exit 3) is a key the scene reader accepts: the messages tell the user
// which parameter to change, so the name must exist.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "common/scene.hpp"
#include "../common/message_keys.hpp"
#include "reduced1d/scene1d.hpp"

using namespace swim;
namespace fs = std::filesystem;

namespace {

/// Every key path the 1D reader resolves, for variants that switch on the conditional keys.
std::set<std::string> accepted_keys() {
  const std::vector<std::vector<std::string>> variants = {
      {},
      {"model1d.model=paper"},
      {"protocol.total_force=null", "protocol.pressure=0.32 Pa"},
      {"protocol.total_force=null", "protocol.load_factor=1.5"},
      {"wave.kind=step", "protocol=null", "time.duration=0.1 s"},
      {"wave.kind=sine", "protocol=null", "wave.contracted_ratio=null", "wave.contracted_radius=0.1 um"},
      {"wall.spring_constant=null", "wall.C1=4e6 Pa/m", "wall.mass_per_length=null", "wall.mass_per_area=1e-3 kg/m^2"},
      {"wall.law=linear"},
      {"model1d.axial_bending.source=scene", "model1d.axial_bending.rigidity=1e-24 J"},
  };
  std::set<std::string> keys = swim::testing::resolved_keys(scene::json::object(), variants,
                                                            [](const scene::json& sc, scene::json& r) { reduced1d::read_scene(sc, r); });
  keys.insert("wall.calibration");  // needs a file to resolve; read by the same wall reader
  keys.insert("wave.radius_file");  // needs a record to resolve (wave.kind = recorded)
  return keys;
}

}  // namespace

TEST(MessageKeys1d, EveryNamedKeyExists) {
  const std::set<std::string> keys = accepted_keys();
  ASSERT_TRUE(keys.count("numerics1d.cells"));
  ASSERT_TRUE(keys.count("model1d.paper.closure"));
  ASSERT_TRUE(keys.count("protocol.pressure"));
  const std::regex key(
      R"(\b(?:swimmer|fluid|wall|container|wave|protocol|model1d|numerics1d|time)\.[a-z_0-9]+(?:\.[a-z_0-9]+)*)");
  const auto named = swim::testing::named_keys(SWIM_SOURCE_DIR "/reduced1d", key, {"md", "hpp", "cpp", "json", "csv", "png"});
  for (const auto& [file, name] : named)
    EXPECT_TRUE(keys.count(name)) << file << " names \"" << name << "\", which the scene reader does not accept";
  EXPECT_GT(named.size(), 30u) << "the scan found the messages";
}
