// partsim's version: one number, the project's (CMakeLists.txt), for the library, the command
// line and the Python package alike.
#pragma once

namespace partsim {

/// "MAJOR.MINOR.PATCH" of this build.
const char* Version();

}  // namespace partsim
