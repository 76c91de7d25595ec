// libFuzzer target: partsim's OBJ reader (ParseObj) on arbitrary bytes. Material libraries
// resolve against the seed corpus, which holds one. Any exception other than partsim::Error,
// any crash and any sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "assets/obj_reader.h"
#include "partsim/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    for (const partsim::internal::FileSubMesh& m :
         partsim::internal::ParseObj(text, PARTSIM_FUZZ_OBJ_DIR, "fuzz.obj")) {
      // every triangle indexes the sub-mesh's own vertices
      const int n = static_cast<int>(m.positions.size());
      for (const auto& t : m.triangles)
        if (t.minCoeff() < 0 || t.maxCoeff() >= n) __builtin_trap();
      if (m.normals.size() != m.positions.size()) __builtin_trap();
      if (!m.uvs.empty() && m.uvs.size() != m.positions.size()) __builtin_trap();
    }
  } catch (const partsim::Error&) {
    // bad input is expected to be rejected this way
  }
  return 0;
}
