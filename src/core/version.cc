#include "partsim/core/version.h"

namespace partsim {

// PARTSIM_VERSION comes from project(partsim VERSION ...) in CMakeLists.txt
const char* Version() { return PARTSIM_VERSION; }

}  // namespace partsim
