// The product's version: the CMake project version (CMakeLists.txt, project(... VERSION ...)).
#pragma once

namespace swim {

/// e.g. "0.1.0"; printed by `swim --version` and written into every summary.json (`swim_version`).
const char* version();

}  // namespace swim
