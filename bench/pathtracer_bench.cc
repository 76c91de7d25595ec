// Path tracer benchmark: seconds per frame of the Embree path tracer for two scenes (a cabinet
// built from boxes, and a 50k-triangle mesh), at 16 and 64 samples per pixel and at 128 x 128
// and 512 x 512 pixels, with the median over several runs; then the cost of a scene update
// (moving an instance: new transform, top-level BVH only; a new geometry_version: every BVH
// rebuilt). See README.md.
//
// Usage: partsim_pathtracer_bench [--runs N] [--depth N] [--threads N] [--save PREFIX]
//   --runs N      renders per configuration (default 5); the median is reported
//   --depth N     max_depth (default 4, the PathTracerOptions default)
//   --threads N   threads (default 0: all cores)
//   --save PREFIX write the last picture of each scene as PREFIX<scene>.ppm (sRGB)
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "partsim/core/constants.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera_math.h"

namespace {

using partsim::CameraParams;
using partsim::MeshData;
using partsim::Pose;
using partsim::RenderInstance;
using partsim::RenderWorld;

using partsim::kPi;

/// An axis-aligned box of half-size h: 12 triangles with face normals.
std::shared_ptr<MeshData> BoxMesh(const Eigen::Vector3f& h) {
  auto m = std::make_shared<MeshData>();
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = static_cast<float>(sign);
      Eigen::Vector3f u = Eigen::Vector3f::Zero();
      u[(axis + 1) % 3] = 1.0f;
      Eigen::Vector3f v = n.cross(u);
      int base = static_cast<int>(m->vertices.size());
      for (auto [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        m->vertices.push_back((n + a * u + b * v).cwiseProduct(h));
        m->normals.push_back(n);
      }
      m->faces.emplace_back(base, base + 1, base + 2);
      m->faces.emplace_back(base, base + 2, base + 3);
    }
  }
  return m;
}

/// A bumpy sphere of radius r with 2 * rings * (segments) - 2 * segments triangles.
std::shared_ptr<MeshData> BumpySphere(float r, int rings, int segments) {
  auto m = std::make_shared<MeshData>();
  for (int i = 0; i <= rings; ++i) {
    double theta = kPi * i / rings;
    for (int j = 0; j <= segments; ++j) {
      double phi = 2 * kPi * j / segments;
      Eigen::Vector3f n(static_cast<float>(std::sin(theta) * std::cos(phi)),
                        static_cast<float>(std::sin(theta) * std::sin(phi)),
                        static_cast<float>(std::cos(theta)));
      float bump = 1.0f + 0.04f * static_cast<float>(std::sin(9 * theta) * std::sin(7 * phi));
      m->vertices.push_back(r * bump * n);
      m->normals.push_back(n);
    }
  }
  const int row = segments + 1;
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      int a = i * row + j, b = a + row;
      if (i > 0) m->faces.emplace_back(a, b, a + 1);
      if (i < rings - 1) m->faces.emplace_back(a + 1, b, b + 1);
    }
  }
  return m;
}

RenderInstance Instance(std::shared_ptr<MeshData> mesh, const Eigen::Vector3f& color,
                        const Eigen::Vector3d& p, uint32_t id, float roughness = 0.7f,
                        float metallic = 0.0f) {
  RenderInstance inst;
  inst.mesh = std::move(mesh);
  inst.material.base_color << color, 1.0f;
  inst.material.roughness = roughness;
  inst.material.metallic = metallic;
  inst.X_WV.topRightCorner<3, 1>() = p;
  inst.visual_id = id;
  inst.entity_id = id;
  return inst;
}

void AddLights(RenderWorld* world) {
  partsim::LightDesc sun;
  sun.type = partsim::LightType::kDirectional;
  sun.direction = Eigen::Vector3d(-0.4, 0.3, -1.0).normalized();
  sun.color = Eigen::Vector3f(2.0f, 1.9f, 1.8f);
  world->lights.push_back(sun);
  partsim::LightDesc lamp;
  lamp.type = partsim::LightType::kPoint;
  lamp.position = Eigen::Vector3d(1.2, -0.8, 1.5);
  lamp.color = Eigen::Vector3f::Constant(1.5f);
  world->lights.push_back(lamp);
  world->ambient = Eigen::Vector3f::Constant(0.3f);
}

/// A cabinet of wooden panels (0.8 x 0.6 x 0.5 m) with three drawers and bar handles, one drawer
/// pulled out, on a floor.
RenderWorld CabinetWorld() {
  RenderWorld world;
  uint32_t id = 1;
  const Eigen::Vector3f wood(0.55f, 0.35f, 0.2f), metal(0.9f, 0.9f, 0.92f);
  world.instances.push_back(
      Instance(BoxMesh({3, 3, 0.01f}), {0.7f, 0.7f, 0.7f}, {0, 0, -0.01}, id++));
  // walls: left, right, top, bottom, back
  world.instances.push_back(Instance(BoxMesh({0.25f, 0.01f, 0.4f}), wood, {0, -0.29, 0.4}, id++));
  world.instances.push_back(Instance(BoxMesh({0.25f, 0.01f, 0.4f}), wood, {0, 0.29, 0.4}, id++));
  world.instances.push_back(Instance(BoxMesh({0.25f, 0.3f, 0.01f}), wood, {0, 0, 0.79}, id++));
  world.instances.push_back(Instance(BoxMesh({0.25f, 0.3f, 0.01f}), wood, {0, 0, 0.01}, id++));
  world.instances.push_back(Instance(BoxMesh({0.01f, 0.3f, 0.4f}), wood, {-0.24, 0, 0.4}, id++));
  // drawers: front panel, bottom, sides, back, handle bar and posts
  for (int k = 0; k < 3; ++k) {
    double z = 0.14 + 0.26 * k;
    double out = k == 1 ? 0.25 : 0.0;
    double x = 0.24 + out;
    world.instances.push_back(Instance(BoxMesh({0.01f, 0.28f, 0.12f}), wood, {x, 0, z}, id++));
    world.instances.push_back(
        Instance(BoxMesh({0.22f, 0.27f, 0.005f}), wood, {x - 0.23, 0, z - 0.1}, id++));
    world.instances.push_back(
        Instance(BoxMesh({0.22f, 0.005f, 0.09f}), wood, {x - 0.23, -0.27, z - 0.02}, id++));
    world.instances.push_back(
        Instance(BoxMesh({0.22f, 0.005f, 0.09f}), wood, {x - 0.23, 0.27, z - 0.02}, id++));
    world.instances.push_back(
        Instance(BoxMesh({0.005f, 0.27f, 0.09f}), wood, {x - 0.45, 0, z - 0.02}, id++));
    world.instances.push_back(
        Instance(BoxMesh({0.01f, 0.1f, 0.01f}), metal, {x + 0.05, 0, z}, id++, 0.3f, 1.0f));
    world.instances.push_back(
        Instance(BoxMesh({0.02f, 0.005f, 0.005f}), metal, {x + 0.03, -0.08, z}, id++, 0.3f, 1.0f));
    world.instances.push_back(
        Instance(BoxMesh({0.02f, 0.005f, 0.005f}), metal, {x + 0.03, 0.08, z}, id++, 0.3f, 1.0f));
  }
  AddLights(&world);
  return world;
}

/// A 50k-triangle bumpy sphere (0.4 m radius) on a floor.
RenderWorld MeshWorld() {
  RenderWorld world;
  world.instances.push_back(Instance(BoxMesh({3, 3, 0.01f}), {0.7f, 0.7f, 0.7f}, {0, 0, -0.01}, 1));
  world.instances.push_back(
      Instance(BumpySphere(0.4f, 126, 200), {0.2f, 0.5f, 0.8f}, {0, 0, 0.42}, 2, 0.4f));
  AddLights(&world);
  return world;
}

size_t Triangles(const RenderWorld& world) {
  size_t n = 0;
  for (const auto& inst : world.instances) n += inst.mesh->faces.size();
  return n;
}

CameraParams Camera(int size) {
  Eigen::Vector3d eye(1.6, -1.1, 1.1), target(0, 0, 0.4);
  Eigen::Vector3d x = (target - eye).normalized();
  Eigen::Vector3d y = Eigen::Vector3d::UnitZ().cross(x).normalized();
  Eigen::Matrix3d R;
  R << x, y, x.cross(y);
  return partsim::MakeCameraParams(size, size, partsim::IntrinsicsFromFovy(size, size, 0.8), 0.01,
                                   100.0, Pose(eye, Eigen::Quaterniond(R)));
}

/// CPU time of the whole process (all threads), s.
double CpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double Seconds(const std::chrono::steady_clock::time_point& t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Binary PPM of the colour, sRGB-encoded.
void SavePpm(const std::string& path, const partsim::Picture& pic) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return;
  std::fprintf(f, "P6\n%d %d\n255\n", pic.width, pic.height);
  for (int i = 0; i < pic.width * pic.height; ++i) {
    for (int k = 0; k < 3; ++k) {
      float c = std::clamp(pic.color[4 * i + k], 0.0f, 1.0f);
      c = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1 / 2.4f) - 0.055f;
      std::fputc(static_cast<int>(std::lround(255 * c)), f);
    }
  }
  std::fclose(f);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 5, depth = 4, threads = 0;
  std::string save;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--depth" && i + 1 < argc) {
      depth = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--threads" && i + 1 < argc) {
      threads = std::max(0, std::atoi(argv[++i]));
    } else if (a == "--save" && i + 1 < argc) {
      save = argv[++i];
    } else {
      std::fprintf(stderr, "usage: %s [--runs N] [--depth N] [--threads N] [--save PREFIX]\n",
                   argv[0]);
      return 2;
    }
  }

  struct Named {
    const char* name;
    RenderWorld world;
  };
  std::vector<Named> scenes = {{"cabinet", CabinetWorld()}, {"mesh50k", MeshWorld()}};

  std::printf("%-8s %9s %6s %4s %12s %12s %12s %14s\n", "scene", "triangles", "size", "spp",
              "median [s]", "min [s]", "Msamples/s", "cpu median [s]");
  for (const auto& [name, world] : scenes) {
    for (int size : {128, 512}) {
      for (int spp : {16, 64}) {
        partsim::PathTracerOptions o;
        o.samples_per_pixel = spp;
        o.max_depth = depth;
        o.threads = threads;
        auto backend = partsim::MakePathTracerBackend(o);
        CameraParams cam = Camera(size);
        partsim::Picture pic;
        // the first render builds the BVHs; time the others
        backend->Render(world, cam, &pic);
        std::vector<double> t, cpu;
        for (int r = 0; r < runs; ++r) {
          auto t0 = std::chrono::steady_clock::now();
          double c0 = CpuSeconds();
          backend->Render(world, cam, &pic);
          t.push_back(Seconds(t0));
          cpu.push_back(CpuSeconds() - c0);
        }
        double med = Median(t);
        std::printf("%-8s %9zu %6s %4d %12.3f %12.3f %12.2f %14.3f\n", name, Triangles(world),
                    (std::to_string(size) + "^2").c_str(), spp, med,
                    *std::min_element(t.begin(), t.end()), 1e-6 * size * size * spp / med,
                    Median(cpu));
        std::fflush(stdout);
        if (!save.empty()) SavePpm(save + name + ".ppm", pic);
      }
    }
  }

  // scene updates, timed through a 1 x 1 picture at 1 sample
  std::printf("\n%-8s %28s %28s\n", "scene", "move every instance [ms]",
              "new geometry_version [ms]");
  for (auto& [name, world] : scenes) {
    partsim::PathTracerOptions o;
    o.samples_per_pixel = 1;
    o.threads = threads;
    auto backend = partsim::MakePathTracerBackend(o);
    CameraParams cam = Camera(1);
    partsim::Picture pic;
    backend->Render(world, cam, &pic);
    std::vector<double> move, rebuild;
    for (int r = 0; r < 20 * runs; ++r) {
      for (auto& inst : world.instances) inst.X_WV(0, 3) += (r % 2 ? -1e-3 : 1e-3);
      auto t0 = std::chrono::steady_clock::now();
      backend->Render(world, cam, &pic);
      move.push_back(1e3 * Seconds(t0));
      ++world.geometry_version;
      t0 = std::chrono::steady_clock::now();
      backend->Render(world, cam, &pic);
      rebuild.push_back(1e3 * Seconds(t0));
    }
    std::printf("%-8s %28.3f %28.3f\n", name, Median(move), Median(rebuild));
  }
  partsim::PathTracerOptions o;
  o.threads = threads;
  std::printf("\n%s\n", partsim::MakePathTracerBackend(o)->Device().c_str());
  return 0;
}
