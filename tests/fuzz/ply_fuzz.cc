// libFuzzer target: PLY files through LoadMeshFile (CheckMeshClaims, then assimp) on arbitrary
// bytes. Run with -rss_limit_mb: a header whose counts are not held to the file's size makes
// assimp allocate what it claims, which the limit reports. Any exception other than
// partsim::Error, any crash and any sanitizer report is a bug.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "partsim/assets/mesh.h"
#include "partsim/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // assimp reads files: each input is written to this process's own scratch file
  static const std::string path = (std::filesystem::temp_directory_path() /
                                   ("partsim_ply_fuzz_" + std::to_string(getpid()) + ".ply"))
                                      .string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    for (const partsim::LoadedMesh& m : partsim::LoadMeshFile(path)) {
      // every triangle indexes the mesh's own vertices
      const int n = static_cast<int>(m.mesh->vertices.size());
      for (const auto& t : m.mesh->faces)
        if (t.minCoeff() < 0 || t.maxCoeff() >= n) __builtin_trap();
    }
  } catch (const partsim::Error&) {
    // bad input is expected to be rejected this way
  }
  return 0;
}
