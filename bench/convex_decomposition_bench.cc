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

#include "partsim/assets/convex_decomposition.h"
#include "partsim/assets/mesh.h"

namespace {

using partsim::MeshData;

// closed surface of the voxels for which occ(i, j, k) holds, cells of side h
MeshData VoxelMesh(int nx, int ny, int nz, double h,
                   const std::function<bool(int, int, int)>& occ) {
  MeshData m;
  std::map<std::tuple<int, int, int>, int> ids;
  auto vertex = [&](int i, int j, int k) {
    auto [it, fresh] = ids.emplace(std::make_tuple(i, j, k), static_cast<int>(m.vertices.size()));
    if (fresh) m.vertices.emplace_back(i * h, j * h, k * h);
    return it->second;
  };
  auto full = [&](int i, int j, int k) {
    return i >= 0 && j >= 0 && k >= 0 && i < nx && j < ny && k < nz && occ(i, j, k);
  };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        if (!full(i, j, k)) continue;
        for (int a = 0; a < 3; ++a)
          for (int s = 0; s < 2; ++s) {
            int c[3] = {i, j, k};
            c[a] += s ? 1 : -1;
            if (full(c[0], c[1], c[2])) continue;
            const int b = (a + 1) % 3, d = (a + 2) % 3;
            auto corner = [&](int u, int v) {
              int q[3] = {i, j, k};
              q[a] += s;
              q[b] += u;
              q[d] += v;
              return vertex(q[0], q[1], q[2]);
            };
            const int v00 = corner(0, 0), v10 = corner(1, 0), v11 = corner(1, 1),
                      v01 = corner(0, 1);
            if (s) {
              m.faces.emplace_back(v00, v10, v11);
              m.faces.emplace_back(v00, v11, v01);
            } else {
              m.faces.emplace_back(v00, v11, v10);
              m.faces.emplace_back(v00, v01, v11);
            }
          }
      }
  return m;
}

MeshData Torus(double R, double r, int nu, int nv) {
  MeshData m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
      m.vertices.emplace_back((R + r * std::cos(v)) * std::cos(u),
                              (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
  auto id = [nu, nv](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return m;
}

// a cup: a profile (r, z) from the outer bottom centre round to the inner bottom centre, turned
// about z in n steps
MeshData Cup(double radius, double height, double wall, int n) {
  const std::vector<std::pair<double, double>> profile = {
      {radius, 0}, {radius, height}, {radius - wall, height}, {radius - wall, wall}};
  MeshData m;
  const int bottom = 0, inner = 1;
  m.vertices.emplace_back(0, 0, 0);
  m.vertices.emplace_back(0, 0, wall);
  const int np = static_cast<int>(profile.size());
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    for (const auto& [r, z] : profile) m.vertices.emplace_back(r * std::cos(a), r * std::sin(a), z);
  }
  auto id = [n, np](int i, int p) { return 2 + (i % n) * np + p; };
  for (int i = 0; i < n; ++i) {
    m.faces.emplace_back(bottom, id(i + 1, 0), id(i, 0));
    for (int p = 0; p + 1 < np; ++p) {
      m.faces.emplace_back(id(i, p), id(i + 1, p), id(i + 1, p + 1));
      m.faces.emplace_back(id(i, p), id(i + 1, p + 1), id(i, p + 1));
    }
    m.faces.emplace_back(inner, id(i, np - 1), id(i + 1, np - 1));
  }
  if (partsim::MeshVolume(m) < 0) {
    for (auto& f : m.faces) std::swap(f[1], f[2]);
  }
  return m;
}

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
