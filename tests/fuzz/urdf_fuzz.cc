// libFuzzer target: UrdfLoader::Parse on arbitrary bytes, with no scene. Any exception other
// than partsim::Error, any crash and any sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  // mesh paths resolve against the committed test meshes
  partsim::UrdfLoader loader(nullptr);
  try {
    loader.Parse(text, PARTSIM_FUZZ_MESH_DIR, "fuzz.urdf");
  } catch (const partsim::Error&) {
    // bad input is expected to be rejected this way
  }
  // a second pass with other options exercises scaling and collision splitting
  loader.scale = 0.5;
  loader.fix_root_link = false;
  loader.load_multiple_collisions_from_file = true;
  try {
    loader.Parse(text, PARTSIM_FUZZ_MESH_DIR, "fuzz.urdf");
  } catch (const partsim::Error&) {
  }
  return 0;
}
