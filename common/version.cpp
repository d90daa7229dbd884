#include "common/version.hpp"

#ifndef SWIM_VERSION
#error "SWIM_VERSION is set by common/CMakeLists.txt from the project version"
#endif

namespace swim {

const char* version() { return SWIM_VERSION; }

}  // namespace swim
