// Convex decomposition on a few meshes: piece count, coverage, largest surface distance, excess
// volume and time. Usage: partsim_convex_decomposition_bench [MESH_FILE ...]
// (without files: generated shapes and the arm's collision meshes in tests/data).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "assets/shape_meshes.h"
#include "partsim/assets/convex_decomposition.h"
#include "partsim/assets/mesh.h"

namespace {

using partsim::MeshData;

using partsim::testing::Cup;
using partsim::testing::Torus;
using partsim::testing::VoxelMesh;

void Run(const std::string& label, const MeshData& mesh,
         const partsim::ConvexDecompositionOptions& o = {}) {
  const auto start = std::chrono::steady_clock::now();
  partsim::ConvexDecompositionResult r = partsim::DecomposeConvex(mesh, o);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("| %s | %zu | %zu | %.3f | %.4f | %.2f | %.4f | %.3f |\n", label.c_str(),
              mesh.faces.size(), r.pieces.size(), r.diagonal, r.coverage,
              r.max_surface_distance * 1000, r.excess, s);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  std::printf(
      "| mesh | triangles | pieces | diagonal (m) | coverage | max surface dist. (mm) | excess "
      "| time (s) |\n|---|---:|---:|---:|---:|---:|---:|---:|\n");
  if (argc > 1) {
    for (int i = 1; i < argc; ++i) {
      auto mesh = partsim::LoadMergedMesh(argv[i]);
      Run(std::filesystem::path(argv[i]).filename().string(), *mesh);
    }
    return 0;
  }
  Run("L (0.3 x 0.3 x 0.15 m)",
      VoxelMesh(6, 3, 6, 0.05, [](int i, int, int k) { return i == 0 || k == 0; }));
  Run("torus R 0.1, r 0.03 (32 x 16)", Torus(0.1, 0.03, 32, 16));
  partsim::ConvexDecompositionOptions capped;
  capped.max_pieces = 8;
  Run("torus, max_pieces 8", Torus(0.1, 0.03, 32, 16), capped);
  Run("cup r 0.04, h 0.1, wall 4 mm (48 steps)", Cup(0.04, 0.1, 0.004, 48));
  Run("cup, max_pieces 8", Cup(0.04, 0.1, 0.004, 48), capped);
  partsim::ConvexDecompositionOptions simple;
  simple.max_hull_vertices = 16;
  Run("cup, max_hull_vertices 16", Cup(0.04, 0.1, 0.004, 48), simple);
  const std::string dir =
      std::string(PARTSIM_SOURCE_DIR) + "/tests/data/arm/arm_description/meshes/collision/";
  for (const char* name :
       {"link0", "link1", "link2", "link3", "link4", "link5", "link6", "link7", "hand", "finger"}) {
    auto mesh = partsim::LoadMergedMesh(dir + name + ".stl");
    Run(std::string("arm ") + name + ".stl", *mesh);
  }
  return 0;
}
