// Every scene key that a message of the 3D tier names (remedies of InputError and
// NumericalError, exit 2 / exit 3) is a key the scene reader accepts: the messages tell the
// user which parameter to change, so the name must exist.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "common/scene.hpp"
#include "../common/message_keys.hpp"
#include "full3d/scene3d.hpp"

using namespace swim;
namespace fs = std::filesystem;

namespace {

/// Every key path the 3D reader resolves (it echoes every value it uses) for a few variants
/// that switch on the conditional keys.
std::set<std::string> accepted_keys() {
  const std::vector<std::vector<std::string>> variants = {
      {},
      {"container.kind=\"cylinder\""},
      {"full3d.grid.cell_size=null", "full3d.grid.cells_across=12"},
      {"full3d.adaptive.enabled=true", "full3d.output.fluid_fields=true"},
      {"full3d.membrane.bending_rigidity=\"2e-24 J\""},
  };
  std::set<std::string> keys = swim::testing::resolved_keys(scene::load_file(SWIM_SOURCE_DIR "/data/scenes/tiny_3d.json"), variants,
                                                            [](const scene::json& sc, scene::json& r) { swim::full3d::read_scene3d(sc, r); });
  return keys;
}

}  // namespace

TEST(MessageKeys3d, EveryNamedFull3dKeyExists) {
  const std::set<std::string> keys = accepted_keys();
  ASSERT_TRUE(keys.count("full3d.dt"));
  ASSERT_TRUE(keys.count("full3d.scheme"));
  ASSERT_FALSE(keys.count("full3d.cylinder_wall"));  // the staircase wall is the only product wall
  ASSERT_TRUE(keys.count("full3d.adaptive.dt_min"));
  const std::regex key(R"(\b(?:full3d|stokes|ib)\.[a-z_0-9]+(?:\.[a-z_0-9]+)*)");
  const auto named = swim::testing::named_keys(SWIM_SOURCE_DIR "/full3d", key, {"md", "hpp", "cpp", "json", "vti", "vtp", "pvd", "csv", "bin"});
  for (const auto& [file, name] : named)
    EXPECT_TRUE(keys.count(name)) << file << " names \"" << name << "\", which the scene reader does not accept";
  std::printf("%zu scene keys named in full3d/ messages, all accepted\n", named.size());
  EXPECT_GT(named.size(), 20u);
}
