// The keys of the 1D tier's own sections (`model1d`, `numerics1d`), with the kind of each
// value, for the 3D tier: it passes the sections through but must still reject malformed
// ones, so that a resolved scene runs on both tiers (scene::check_section). Kept next to
// scene1d.cpp; tests/common/test_strict_scene.cpp checks it against read_scene.
#pragma once

#include "common/scene.hpp"

namespace swim::reduced1d {

/// Schema of the 1D sections: {"model1d": {...}, "numerics1d": {...}}.
const scene::json& section_keys();

}  // namespace swim::reduced1d
