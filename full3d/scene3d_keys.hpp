// The keys of the 3D tier's own section (`full3d`), with the kind of each value, for the
// 1D tier: it passes the section through but must still reject a malformed one, so that a
// resolved scene runs on both tiers (scene::check_section). Kept next to scene3d.cpp;
// tests/common/test_strict_scene.cpp checks it against read_scene3d.
#pragma once

#include "common/scene.hpp"

namespace swim::full3d {

/// Schema of the `full3d` section (format: scene::check_section).
const scene::json& section_keys();

}  // namespace swim::full3d
