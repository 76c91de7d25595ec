// Closed test meshes shared by the convex decomposition tests and benchmark: voxel shapes (an L,
// a box), a torus and a thin-walled cup.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <functional>

#include "partsim/physics/description.h"

namespace partsim::testing {

using Eigen::Vector3d;
using Eigen::Vector3f;

// Closed surface of a set of voxels (cells of side `h`, cell (0,0,0) at the origin): one quad per
// face between an occupied and an empty cell, vertices shared, counter-clockwise from outside.
inline MeshData VoxelMesh(int nx, int ny, int nz, double h,
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
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      for (int k = 0; k < nz; ++k) {
        if (!full(i, j, k)) continue;
        for (int a = 0; a < 3; ++a) {
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
      }
    }
  }
  return m;
}

// An L in the xz plane extruded along y: a floor 0.3 x 0.05 and a wall 0.05 x 0.3 (m); cells of
// 0.05 m, 0.15 m deep. Its inner corner is at x = z = 0.05.
inline MeshData LShape() {
  return VoxelMesh(6, 3, 6, 0.05, [](int i, int, int k) { return i == 0 || k == 0; });
}

// A box 0.2 x 0.1 x 0.05 m.
inline MeshData Box() {
  return VoxelMesh(4, 2, 1, 0.05, [](int, int, int) { return true; });
}

// A round torus about z: major radius R, minor radius r (m).
inline MeshData Torus(double R, double r, int nu = 32, int nv = 16) {
  MeshData m;
  for (int i = 0; i < nu; ++i) {
    const double u = 2 * M_PI * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double v = 2 * M_PI * j / nv;
      m.vertices.emplace_back((R + r * std::cos(v)) * std::cos(u),
                              (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
  }
  auto id = [nu, nv](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  }
  return m;
}

// A cup about z: outer radius, height and wall thickness (m), turned in n steps; triangles
// counter-clockwise from outside. Its bottom's two faces are flat discs that touch only the walls.
inline MeshData Cup(double radius, double height, double wall, int n) {
  const std::vector<std::pair<double, double>> profile = {
      {radius, 0}, {radius, height}, {radius - wall, height}, {radius - wall, wall}};
  const int np = static_cast<int>(profile.size());
  MeshData m;
  m.vertices.emplace_back(0, 0, 0);     // outer bottom centre
  m.vertices.emplace_back(0, 0, wall);  // inner bottom centre
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    for (const auto& [r, z] : profile) m.vertices.emplace_back(r * std::cos(a), r * std::sin(a), z);
  }
  auto id = [n, np](int i, int p) { return 2 + (i % n) * np + p; };
  for (int i = 0; i < n; ++i) {
    m.faces.emplace_back(0, id(i + 1, 0), id(i, 0));
    for (int p = 0; p + 1 < np; ++p) {
      m.faces.emplace_back(id(i, p), id(i + 1, p), id(i + 1, p + 1));
      m.faces.emplace_back(id(i, p), id(i + 1, p + 1), id(i, p + 1));
    }
    m.faces.emplace_back(1, id(i, np - 1), id(i + 1, np - 1));
  }
  return m;
}

// Whether x is inside the convex piece (on the inner side of every face plane).

}  // namespace partsim::testing
