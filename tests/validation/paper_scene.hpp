// The paper's amplitude scene for the calibration tests.
#pragma once

#include "common/scene.hpp"
#include "full3d/scene3d.hpp"

namespace swim::test {

/// data/scenes/paper_amplitude_0.55.json; cells_across > 0 replaces its grid (the membrane follows it).
inline full3d::Params3d paper_scene(int cells_across = 0) {
  scene::json sc = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_amplitude_0.55.json");
  if (cells_across > 0) sc["full3d"]["grid"] = {{"cells_across", cells_across}};
  scene::json resolved;
  return full3d::read_scene3d(sc, resolved);
}

}  // namespace swim::test
