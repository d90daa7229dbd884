// What the 1D scene reader says of a scene a test expects it to refuse: the one place the 1D
// tests turn a refusal (swim::InputError, the executable's exit 2) into values to assert on.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "common/errors.hpp"
#include "common/scene.hpp"
#include "reduced1d/scene1d.hpp"

namespace swim::reduced1d::test {

/// The reader's answer: refused with the key it named and its message, or accepted.
struct Refusal {
  bool refused = false;
  std::string key;      ///< the key the refusal names ("(accepted)" when the scene was read)
  std::string message;  ///< the whole message (empty when accepted)
};

/// Read `scene` and report whether it was refused.
inline Refusal refusal_of(const scene::json& scene) {
  scene::json resolved;
  try {
    (void)read_scene(scene, resolved);
  } catch (const swim::InputError& e) {
    return {true, e.key(), e.what()};
  }
  return {false, "(accepted)", {}};
}

/// The scene is refused and its message names `key`.
inline void expect_refused(const scene::json& scene, const std::string& key) {
  const Refusal r = refusal_of(scene);
  if (!r.refused) {
    ADD_FAILURE() << "accepted " << scene.dump();
    return;
  }
  EXPECT_NE(r.message.find(key), std::string::npos) << r.message;
}

}  // namespace swim::reduced1d::test
