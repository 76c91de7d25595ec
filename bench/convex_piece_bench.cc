// Convex collision pieces with many points: CheckConvexPiece and MuJoCo's compile of the piece
// (a dynamic actor with the piece as its one collision shape, added to a fresh scene and stepped
// once), for flat n-corner faces (a regular polygon, fanned), an n-segment open cylinder (its
// rims: 2n points on two planes) and a UV sphere. "old" is the path before the vertex limit:
// qhull on every point without a limit (the pushed-out points of a flat face), and MuJoCo given
// every vertex (the thin hull, or the mesh itself); it runs only up to --old-max points, as it
// grows about as n^2.5.
//
// Usage: partsim_convex_piece_bench [--sizes 1000,5000,10000,50000] [--old-max 10000]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "partsim/assets/convex_decomposition.h"
#include "partsim/assets/mesh.h"
#include "partsim/physics/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// A regular n-gon of radius 0.5 m in the plane z = 0, as a triangle fan.
std::shared_ptr<partsim::MeshData> FlatFace(int n) {
  auto m = std::make_shared<partsim::MeshData>();
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    m->vertices.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.0f);
  }
  for (int i = 1; i + 1 < n; ++i) m->faces.emplace_back(0, i, i + 1);
  return m;
}

// The side of a cylinder (radius 0.5 m, 0.3 m high) with n segments: 2n points on two planes.
std::shared_ptr<partsim::MeshData> Cylinder(int n) {
  auto m = std::make_shared<partsim::MeshData>();
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    m->vertices.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.0f);
    m->vertices.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.3f);
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i, b = 2 * ((i + 1) % n);
    m->faces.emplace_back(a, b, b + 1);
    m->faces.emplace_back(a, b + 1, a + 1);
  }
  return m;
}

// A UV sphere of radius 0.5 m with about n vertices (poles repeated per segment).
std::shared_ptr<partsim::MeshData> Sphere(int n) {
  auto m = std::make_shared<partsim::MeshData>();
  const int rings = std::max(4, static_cast<int>(std::sqrt(n / 2.0)));
  const int segments = 2 * rings;
  for (int r = 0; r <= rings; ++r) {
    const double t = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double p = 2 * M_PI * s / segments;
      m->vertices.emplace_back(0.5 * std::sin(t) * std::cos(p), 0.5 * std::sin(t) * std::sin(p),
                               0.5 * std::cos(t));
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const int a = r * segments + s, b = r * segments + (s + 1) % segments;
      m->faces.emplace_back(a, a + segments, b + segments);
      m->faces.emplace_back(a, b + segments, b);
    }
  }
  return m;
}

// Seconds to add a dynamic actor colliding as `piece` to a fresh scene and step once.
double Compile(const std::shared_ptr<const partsim::MeshData>& piece) {
  auto t0 = Clock::now();
  partsim::Scene scene;
  partsim::ActorDesc actor;
  actor.name = "piece";
  partsim::CollisionShape shape;
  shape.type = partsim::ShapeType::kConvexMesh;
  shape.mesh = piece;
  actor.collisions.push_back(shape);
  actor.pose.p = Eigen::Vector3d(0, 0, 1);
  scene.AddActor(actor);
  scene.Step();
  return Seconds(t0);
}

// The path before the vertex limit: the thin hull of a flat face without a limit, a sound mesh
// as it is. Returns the seconds in partsim (qhull) and in MuJoCo's compile.
std::pair<double, double> Old(const std::shared_ptr<partsim::MeshData>& mesh, bool flat) {
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3f& v : mesh->vertices) points.push_back(v.cast<double>());
  auto t0 = Clock::now();
  std::shared_ptr<partsim::MeshData> piece = mesh;
  if (flat) {
    // CheckConvexPiece's thin hull: each point pushed 2.5 mm both ways along z (5 mm thick)
    std::vector<Eigen::Vector3d> pushed;
    for (const Eigen::Vector3d& p : points) {
      pushed.push_back(p + Eigen::Vector3d(0, 0, 0.0025));
      pushed.push_back(p - Eigen::Vector3d(0, 0, 0.0025));
    }
    piece = partsim::ConvexHull(pushed);
  } else {
    partsim::ConvexHull(points);
  }
  const double partsim_s = Seconds(t0);
  return {partsim_s, Compile(piece)};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes = {1000, 5000, 10000, 50000};
  size_t old_max = 10000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i];
    if (arg == "--sizes") {
      sizes.clear();
      std::stringstream list(argv[i + 1]);
      std::string item;
      while (std::getline(list, item, ',')) sizes.push_back(std::stoi(item));
    } else if (arg == "--old-max") {
      old_max = std::stoul(argv[i + 1]);
    } else {
      std::fprintf(stderr, "unknown option %s\n", arg.c_str());
      return 2;
    }
  }
  std::printf(
      "| mesh | points | piece vertices | check [s] | compile [s] | old check [s] | "
      "old compile [s] |\n|---|---:|---:|---:|---:|---:|---:|\n");
  for (const std::string kind : {"flat", "cylinder", "sphere"}) {
    for (int n : sizes) {
      std::shared_ptr<partsim::MeshData> mesh = kind == "flat"       ? FlatFace(n)
                                                : kind == "cylinder" ? Cylinder(n)
                                                                     : Sphere(n);
      auto t0 = Clock::now();
      partsim::ConvexPieceCheck check = partsim::CheckConvexPiece(mesh);
      const double check_s = Seconds(t0);
      const double compile_s = Compile(check.piece);
      std::string old_check = "-", old_compile = "-";
      if (mesh->vertices.size() <= old_max) {
        auto [a, b] = Old(mesh, kind == "flat");
        char buf[32];
        std::snprintf(buf, sizeof(buf), "%.2f", a);
        old_check = buf;
        std::snprintf(buf, sizeof(buf), "%.2f", b);
        old_compile = buf;
      }
      std::printf("| %s %d | %zu | %zu | %.2f | %.2f | %s | %s |\n", kind.c_str(), n,
                  mesh->vertices.size(), check.piece->vertices.size(), check_s, compile_s,
                  old_check.c_str(), old_compile.c_str());
      std::fflush(stdout);
    }
  }
  return 0;
}
