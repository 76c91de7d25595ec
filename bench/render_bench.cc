// Renderer benchmark: frames per second of partsim's rasterizer, read-back included, against a
// bare OpenGL program in the same binary that draws the same triangles on the same kind of EGL
// context (one simple shader writing colour and depth, the same read-back of colour and depth).
//
// Scenes: (a) a cabinet (body walls, a drawer with a handle, a door) with a parallel gripper
// (palm, wrist, two fingers) on a ground plane, built from boxes; (b) 50 UV spheres of 1000
// triangles each (50k triangles) on a ground plane. Sizes 128x128 and 512x512.
//
// Runs per scene and size:
//   bare         the bare program: one Lambert term, colour (RGBA float) + depth (float) read back
//   bare PBR     the bare program shading like partsim (Oren-Nayar + GGX for the scene's
//                directional and point light, ambient), same targets and read-back; the program
//                checks that its colours match partsim's (mean difference < 0.01)
//   partsim c+d  partsim asked for Color and Position only (RenderBackend::Render's outputs
//                mask): its forward path, one pass shading colour and writing depth, Position
//                rebuilt from depth on the CPU (like for like with the bare programs)
//   partsim all  partsim asked for every output (colour, albedo, normal, position,
//                segmentation), as Camera::TakePicture does by default: G-buffer + lighting
// The ratio to "bare PBR" is partsim's overhead for the same work; the ratio to "bare" also
// counts the cost of its shading model. Runs interleave within each repetition; the summary
// gives medians over repetitions.
//
// Usage: partsim_render_bench [--reps N] [--seconds S] [--shadows] [--cpu-time] [--shadow-modes]
//                             [--batch] [--camera-set]
// (--cpu-time: frames per second of process CPU time, all of llvmpipe's threads together)
//
// --shadow-modes: instead, partsim alone (c+d, the forward path) under the shadowing sun, against
// the same scene without shadows, with the maps
//   redrawn      drawn for every picture (RasterOptions::reuse_shadow_maps = false), 2048 texels
//   kept         kept while nothing they hold moves (the default), 2048 texels
//   kept, auto   kept, sized from the picture (shadow_map_size = 0: 512 at 128², 1024 at 512²)
//   moving       a gripper-sized box moving every picture (the maps drawn again), auto size
// each as fps and as a ratio to shadows off; the same rotation and medians as above.
//
// --batch: instead, partsim c+d with every picture taking and releasing the GL context (as
// pictures outside a batch do) against the same pictures inside one RenderBatch (the context
// kept current), with the bare program beside them; the same rotation and medians.
//
// --camera-set: instead, four cameras around each scene (shadowing sun): one Render per camera
// in a batch, against one RenderMany of the four (the world uploaded once, each picture read
// back through pixel-pack buffers while the next is drawn), for c+d and all outputs; pictures
// per second and their ratio, the same rotation and medians.
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "bare_renderer.h"
#include "partsim/core/constants.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera_math.h"
#include "render/gl_util.h"

namespace {

using partsim::CameraParams;
using partsim::MeshData;
using partsim::RenderInstance;
using partsim::RenderWorld;

using partsim::kPi;
using partsim_bench::BareRenderer;

std::shared_ptr<MeshData> Box(const Eigen::Vector3f& h) {
  auto m = std::make_shared<MeshData>();
  for (int i = 0; i < 8; ++i) {
    m->vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                             (i & 4) ? h.z() : -h.z());
  }
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& q : quads) {
    m->faces.emplace_back(q[0], q[1], q[2]);
    m->faces.emplace_back(q[0], q[2], q[3]);
  }
  return m;
}

// UV sphere with smooth normals: 2 * slices * (stacks - 1) triangles (25 x 21 -> 1000)
std::shared_ptr<MeshData> Sphere(float r, int slices, int stacks) {
  auto m = std::make_shared<MeshData>();
  for (int i = 0; i <= stacks; ++i) {
    double theta = kPi * i / stacks;
    for (int j = 0; j <= slices; ++j) {
      double phi = 2 * kPi * j / slices;
      Eigen::Vector3f n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                        std::cos(theta));
      m->vertices.push_back(r * n);
      m->normals.push_back(n);
    }
  }
  auto id = [&](int i, int j) { return i * (slices + 1) + j; };
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      if (i != 0) m->faces.emplace_back(id(i, j), id(i + 1, j), id(i, j + 1));
      if (i != stacks - 1) m->faces.emplace_back(id(i, j + 1), id(i + 1, j), id(i + 1, j + 1));
    }
  }
  return m;
}

RenderInstance Instance(std::shared_ptr<MeshData> mesh, const Eigen::Vector3d& p,
                        const Eigen::Vector4f& color, uint32_t id, uint32_t entity) {
  RenderInstance inst;
  inst.mesh = std::move(mesh);
  inst.material.base_color = color;
  inst.X_WV.topRightCorner<3, 1>() = p;
  inst.visual_id = id;
  inst.entity_id = entity;
  return inst;
}

void AddLights(RenderWorld* world, bool shadows) {
  partsim::LightDesc sun;
  sun.direction = Eigen::Vector3d(0.4, 0.3, -1).normalized();
  sun.color = Eigen::Vector3f::Constant(2.5f);
  sun.shadow = shadows;
  world->lights.push_back(sun);
  partsim::LightDesc point;
  point.type = partsim::LightType::kPoint;
  point.position = {-1, 1, 2};
  point.color = Eigen::Vector3f::Constant(2.0f);
  world->lights.push_back(point);
  world->ambient = Eigen::Vector3f::Constant(0.15f);
}

// (a) cabinet 0.8 x 0.6 x 0.5 m (x depth, y width, z height) with a drawer, a door and a handle;
// a gripper in front of the handle
RenderWorld CabinetScene(bool shadows) {
  RenderWorld w;
  Eigen::Vector4f wood(0.6f, 0.45f, 0.3f, 1), metal(0.7f, 0.7f, 0.75f, 1),
      dark(0.2f, 0.2f, 0.2f, 1);
  uint32_t id = 1;
  auto add = [&](const Eigen::Vector3f& h, const Eigen::Vector3d& p, const Eigen::Vector4f& c,
                 uint32_t entity) { w.instances.push_back(Instance(Box(h), p, c, id++, entity)); };
  add({3, 3, 0.01f}, {0, 0, -0.01}, {0.5f, 0.5f, 0.5f, 1}, 1);  // ground
  // body walls: back, left, right, top, bottom, middle shelf
  add({0.01f, 0.3f, 0.25f}, {-0.39, 0, 0.25}, wood, 2);
  add({0.4f, 0.01f, 0.25f}, {0, 0.29, 0.25}, wood, 2);
  add({0.4f, 0.01f, 0.25f}, {0, -0.29, 0.25}, wood, 2);
  add({0.4f, 0.3f, 0.01f}, {0, 0, 0.49}, wood, 2);
  add({0.4f, 0.3f, 0.01f}, {0, 0, 0.01}, wood, 2);
  add({0.4f, 0.28f, 0.01f}, {0, 0, 0.25}, wood, 2);
  // drawer (upper half, pulled 0.15 m): front, bottom, sides, back, handle bar and posts
  add({0.01f, 0.28f, 0.11f}, {0.54, 0, 0.37}, wood, 3);
  add({0.38f, 0.27f, 0.005f}, {0.16, 0, 0.275}, wood, 3);
  add({0.38f, 0.005f, 0.1f}, {0.16, 0.265, 0.37}, wood, 3);
  add({0.38f, 0.005f, 0.1f}, {0.16, -0.265, 0.37}, wood, 3);
  add({0.005f, 0.27f, 0.1f}, {-0.22, 0, 0.37}, wood, 3);
  add({0.01f, 0.1f, 0.01f}, {0.59, 0, 0.37}, metal, 4);
  add({0.02f, 0.005f, 0.005f}, {0.565, 0.08, 0.37}, metal, 4);
  add({0.02f, 0.005f, 0.005f}, {0.565, -0.08, 0.37}, metal, 4);
  // door (lower half) with a knob
  add({0.01f, 0.28f, 0.11f}, {0.4, 0, 0.13}, wood, 5);
  add({0.02f, 0.02f, 0.02f}, {0.43, 0.2, 0.13}, metal, 5);
  // gripper: wrist, palm, two fingers
  add({0.05f, 0.03f, 0.03f}, {0.78, 0, 0.37}, dark, 6);
  add({0.02f, 0.08f, 0.03f}, {0.71, 0, 0.37}, dark, 7);
  add({0.04f, 0.01f, 0.015f}, {0.65, 0.03, 0.37}, metal, 8);
  add({0.04f, 0.01f, 0.015f}, {0.65, -0.03, 0.37}, metal, 9);
  AddLights(&w, shadows);
  return w;
}

// (b) 50 spheres of 1000 triangles in a 10 x 5 grid on a ground plane
RenderWorld SpheresScene(bool shadows) {
  RenderWorld w;
  auto sphere = Sphere(0.08f, 25, 21);
  w.instances.push_back(Instance(Box({3, 3, 0.01f}), {0, 0, -0.01}, {0.5f, 0.5f, 0.5f, 1}, 1, 1));
  for (int i = 0; i < 50; ++i) {
    double x = -0.4 + 0.2 * (i / 10), y = -0.9 + 0.2 * (i % 10);
    Eigen::Vector4f c(0.2f + 0.015f * i, 0.8f - 0.01f * i, 0.5f, 1);
    w.instances.push_back(Instance(sphere, {x, y, 0.08}, c, 2 + i, 2 + i));
  }
  AddLights(&w, shadows);
  return w;
}

size_t TriangleCount(const RenderWorld& w) {
  size_t n = 0;
  for (const auto& i : w.instances) n += i.mesh->faces.size();
  return n;
}

CameraParams CameraFor(int size, const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  // partsim camera: x forward, y left, z up
  Eigen::Vector3d x = (target - eye).normalized();
  Eigen::Vector3d y = Eigen::Vector3d::UnitZ().cross(x).normalized();
  Eigen::Matrix3d R;
  R << x, y, x.cross(y);
  partsim::Pose X_WC(eye, Eigen::Quaterniond(R));
  return partsim::MakeCameraParams(size, size, partsim::IntrinsicsFromFovy(size, size, 1.0), 0.05,
                                   20.0, X_WC);
}

// ---------------------------------------------------------------------------------------------

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// seconds on the wall clock, or of CPU time of the whole process (llvmpipe renders on worker
// threads), which other jobs on the machine disturb less
bool g_cpu_time = false;
double Now() {
  if (!g_cpu_time) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// frames per second of `render` over at least `seconds` (after one warm-up frame)
template <typename F>
double Fps(F&& render, double seconds) {
  render();
  double start = Now();
  int frames = 0;
  double elapsed = 0;
  do {
    render();
    ++frames;
    elapsed = Now() - start;
  } while (elapsed < seconds);
  return frames / elapsed;
}

// --shadow-modes (see the file's comment)
int ShadowModes(int reps, double seconds) {
  struct Mode {
    const char* name;
    bool shadows, reuse, moving;
    int map_size;
  };
  const Mode modes[] = {{"off", false, true, false, 2048},
                        {"redrawn", true, false, false, 2048},
                        {"kept", true, true, false, 2048},
                        {"kept, auto", true, true, false, 0},
                        {"moving", true, true, true, 0}};
  const int n = static_cast<int>(std::size(modes));
  std::vector<std::unique_ptr<partsim::RenderBackend>> backends;
  for (const Mode& m : modes) {
    partsim::RasterOptions options;
    options.shadow_map_size = m.map_size;
    options.reuse_shadow_maps = m.reuse;
    backends.push_back(partsim::MakeRasterBackend(options));
  }
  std::printf("device: %s; shadow maps, partsim c+d; %d repetitions of >= %.2f s (%s) per run\n",
              backends[0]->Device().c_str(), reps, seconds,
              g_cpu_time ? "process CPU time" : "wall clock");
  std::printf("%-16s %5s |", "scene", "size");
  for (const Mode& m : modes) std::printf(" %11s", m.name);
  std::printf(" | ratios to off\n");
  const unsigned kColorDepth = partsim::kColor | partsim::kPosition;
  for (int scene = 0; scene < 2; ++scene) {
    RenderWorld plain = scene == 0 ? CabinetScene(false) : SpheresScene(false);
    RenderWorld shadowed = scene == 0 ? CabinetScene(true) : SpheresScene(true);
    RenderWorld moving = shadowed;
    moving.instances.push_back(
        Instance(Box({0.05f, 0.05f, 0.05f}), {0.6, 0, 0.4}, {0.9f, 0.9f, 0.9f, 1}, 99, 99));
    Eigen::Vector3d eye =
        scene == 0 ? Eigen::Vector3d(1.8, 0.9, 1.2) : Eigen::Vector3d(1.6, 0, 1.3);
    Eigen::Vector3d target = scene == 0 ? Eigen::Vector3d(0.2, 0, 0.25) : Eigen::Vector3d::Zero();
    for (int size : {128, 512}) {
      CameraParams cam = CameraFor(size, eye, target);
      partsim::Picture pic;
      int step = 0;
      std::vector<std::vector<double>> fps(n), ratio(n);
      for (int r = 0; r < reps; ++r) {
        std::vector<double> f(n);
        for (int k = 0; k < n; ++k) {
          const int i = (r + k) % n;
          const Mode& m = modes[i];
          RenderWorld& world = m.moving ? moving : m.shadows ? shadowed : plain;
          f[i] = Fps(
              [&] {
                if (m.moving) world.instances.back().X_WV(1, 3) = 0.002 * (++step % 100);
                backends[i]->Render(world, cam, &pic, kColorDepth);
              },
              seconds);
        }
        for (int i = 0; i < n; ++i) {
          fps[i].push_back(f[i]);
          ratio[i].push_back(f[i] / f[0]);
        }
      }
      std::printf("%-16s %5d |", scene == 0 ? "cabinet+gripper" : "50 spheres", size);
      for (int i = 0; i < n; ++i) std::printf(" %11.1f", Median(fps[i]));
      std::printf(" |");
      for (int i = 1; i < n; ++i) std::printf(" %6.3f", Median(ratio[i]));
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  for (int i = 1; i < n; ++i) {
    partsim::RenderCounters c = backends[i]->Counters();
    std::printf("%s: %llu pictures, %llu shadow maps drawn, %llu kept\n", modes[i].name,
                static_cast<unsigned long long>(c.pictures),
                static_cast<unsigned long long>(c.shadow_layers_drawn),
                static_cast<unsigned long long>(c.shadow_layers_reused));
  }
  return 0;
}

// --batch (see the file's comment)
int BatchModes(int reps, double seconds) {
  auto backend = partsim::MakeRasterBackend();
  std::printf(
      "device: %s; partsim c+d, pictures alone or in a batch; %d repetitions of >= %.2f s "
      "(%s) per run\n",
      backend->Device().c_str(), reps, seconds, g_cpu_time ? "process CPU time" : "wall clock");
  std::printf("%-16s %5s | %9s %9s %9s | %8s %8s\n", "scene", "size", "bare", "alone", "batch",
              "batch/al", "batch/bare");
  const unsigned kColorDepth = partsim::kColor | partsim::kPosition;
  for (int scene = 0; scene < 2; ++scene) {
    RenderWorld world = scene == 0 ? CabinetScene(false) : SpheresScene(false);
    Eigen::Vector3d eye =
        scene == 0 ? Eigen::Vector3d(1.8, 0.9, 1.2) : Eigen::Vector3d(1.6, 0, 1.3);
    Eigen::Vector3d target = scene == 0 ? Eigen::Vector3d(0.2, 0, 0.25) : Eigen::Vector3d::Zero();
    BareRenderer bare(world, false);
    for (int size : {32, 128, 512}) {
      CameraParams cam = CameraFor(size, eye, target);
      partsim::Picture pic;
      std::vector<float> color, depth;
      std::vector<double> fps[3], ratio[2];
      for (int r = 0; r < reps; ++r) {
        double f[3] = {0, 0, 0};
        for (int k = 0; k < 3; ++k) {
          switch ((r + k) % 3) {
            case 0:
              f[0] = Fps([&] { bare.Render(world, cam, &color, &depth); }, seconds);
              break;
            case 1:
              f[1] = Fps([&] { backend->Render(world, cam, &pic, kColorDepth); }, seconds);
              break;
            case 2: {
              partsim::RenderBatch batch(*backend);
              f[2] = Fps([&] { backend->Render(world, cam, &pic, kColorDepth); }, seconds);
              break;
            }
          }
        }
        for (int k = 0; k < 3; ++k) fps[k].push_back(f[k]);
        ratio[0].push_back(f[2] / f[1]);
        ratio[1].push_back(f[2] / f[0]);
      }
      std::printf("%-16s %5d | %9.1f %9.1f %9.1f | %8.3f %8.3f\n",
                  scene == 0 ? "cabinet+gripper" : "50 spheres", size, Median(fps[0]),
                  Median(fps[1]), Median(fps[2]), Median(ratio[0]), Median(ratio[1]));
      std::fflush(stdout);
    }
  }
  return 0;
}

// --camera-set (see the file's comment)
int CameraSetModes(int reps, double seconds) {
  auto backend = partsim::MakeRasterBackend();
  std::printf(
      "device: %s; a set of 4 cameras around the scene, one Render each (in a batch) or one "
      "RenderMany; pictures per second; %d repetitions of >= %.2f s (%s) per run\n",
      backend->Device().c_str(), reps, seconds, g_cpu_time ? "process CPU time" : "wall clock");
  std::printf("%-16s %5s %4s | %9s %9s | %8s\n", "scene", "size", "out", "one each", "many",
              "many/one");
  for (int scene = 0; scene < 2; ++scene) {
    RenderWorld world = scene == 0 ? CabinetScene(true) : SpheresScene(true);
    const Eigen::Vector3d target =
        scene == 0 ? Eigen::Vector3d(0.2, 0, 0.25) : Eigen::Vector3d::Zero();
    for (int size : {128, 512}) {
      std::vector<CameraParams> cams;
      for (int k = 0; k < 4; ++k) {
        const double a = 0.4 + 1.2 * k;  // around the scene
        cams.push_back(CameraFor(
            size, target + Eigen::Vector3d(2 * std::cos(a), 2 * std::sin(a), 1.2), target));
      }
      std::vector<partsim::Picture> pics(cams.size());
      std::vector<partsim::Picture*> out;
      for (partsim::Picture& p : pics) out.push_back(&p);
      for (unsigned outputs :
           {unsigned{partsim::kColor | partsim::kPosition}, unsigned{partsim::kAllOutputs}}) {
        std::vector<double> fps[2], ratio;
        for (int r = 0; r < reps; ++r) {
          double f[2] = {0, 0};
          for (int k = 0; k < 2; ++k) {
            partsim::RenderBatch batch(*backend);
            if ((r + k) % 2 == 0) {
              f[0] = 4 * Fps(
                             [&] {
                               for (size_t i = 0; i < cams.size(); ++i)
                                 backend->Render(world, cams[i], out[i], outputs);
                             },
                             seconds);
            } else {
              f[1] = 4 * Fps([&] { backend->RenderMany(world, cams, out, outputs); }, seconds);
            }
          }
          for (int k = 0; k < 2; ++k) fps[k].push_back(f[k]);
          ratio.push_back(f[1] / f[0]);
        }
        std::printf("%-16s %5d %4s | %9.1f %9.1f | %8.3f\n",
                    scene == 0 ? "cabinet+gripper" : "50 spheres", size,
                    outputs == partsim::kAllOutputs ? "all" : "c+d", Median(fps[0]), Median(fps[1]),
                    Median(ratio));
        std::fflush(stdout);
      }
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 7;
  double seconds = 0.5;
  bool shadows = false, shadow_modes = false, batch_modes = false, camera_set = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) {
      reps = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else if (!std::strcmp(argv[i], "--shadows")) {
      shadows = true;
    } else if (!std::strcmp(argv[i], "--cpu-time")) {
      g_cpu_time = true;
    } else if (!std::strcmp(argv[i], "--shadow-modes")) {
      shadow_modes = true;
    } else if (!std::strcmp(argv[i], "--batch")) {
      batch_modes = true;
    } else if (!std::strcmp(argv[i], "--camera-set")) {
      camera_set = true;
    } else {
      std::fprintf(stderr,
                   "usage: %s [--reps N] [--seconds S] [--shadows] [--cpu-time] "
                   "[--shadow-modes] [--batch] [--camera-set]\n",
                   argv[0]);
      return 2;
    }
  }
  if (shadow_modes) return ShadowModes(reps, seconds);
  if (batch_modes) return BatchModes(reps, seconds);
  if (camera_set) return CameraSetModes(reps, seconds);

  struct Case {
    const char* name;
    RenderWorld world;
    Eigen::Vector3d eye, target;
  };
  std::vector<Case> cases;
  cases.push_back({"cabinet+gripper", CabinetScene(shadows), {1.8, 0.9, 1.2}, {0.2, 0, 0.25}});
  cases.push_back({"50 spheres", SpheresScene(shadows), {1.6, 0.0, 1.3}, {0, 0, 0}});

  auto partsim_backend = partsim::MakeRasterBackend();
  const unsigned kColorDepth = partsim::kColor | partsim::kPosition;
  std::printf("device: %s; shadows %s; %d repetitions of >= %.2f s (%s) per run\n",
              partsim_backend->Device().c_str(), shadows ? "on" : "off", reps, seconds,
              g_cpu_time ? "process CPU time" : "wall clock");
  std::printf("%-16s %5s %6s | %9s %9s %9s %9s | %8s %8s %8s %8s\n", "scene", "size", "tris",
              "bare", "bare PBR", "c+d", "all", "c+d/bare", "c+d/PBR", "all/bare", "all/PBR");

  int status = 0;
  std::vector<double> diffs;
  for (Case& c : cases) {
    BareRenderer bare(c.world, false), bare_pbr(c.world, true);
    for (int size : {128, 512}) {
      CameraParams cam = CameraFor(size, c.eye, c.target);
      partsim::Picture pic;
      std::vector<float> color, depth, pbr_color, pbr_depth;

      // the same triangles: both see a surface at the same number of pixels
      // (both partsim paths)
      bare.Render(c.world, cam, &color, &depth);
      for (unsigned outputs : {unsigned{partsim::kAllOutputs}, kColorDepth}) {
        partsim_backend->Render(c.world, cam, &pic, outputs);
        size_t covered_partsim = 0, covered_bare = 0;
        for (size_t i = 0; i < depth.size(); ++i) {
          covered_partsim += pic.position[4 * i + 3] > 0;
          covered_bare += depth[i] < 1.0f;
        }
        if (covered_partsim != covered_bare) {
          std::fprintf(stderr, "%s %d (%s): partsim sees %zu pixels, bare %zu\n", c.name, size,
                       partsim::PictureOutputNames(outputs).c_str(), covered_partsim, covered_bare);
          status = 1;
        }
      }
      // and the PBR program shades like partsim: its colours (rows flipped: the bare programs
      // draw row 0 at the bottom) against partsim's forward path, where both see a surface
      bare_pbr.Render(c.world, cam, &pbr_color, &pbr_depth);
      double diff = 0;
      size_t seen = 0;
      for (int v = 0; v < size; ++v) {
        for (int u = 0; u < size; ++u) {
          size_t i = static_cast<size_t>(v) * size + u;
          size_t j = static_cast<size_t>(size - 1 - v) * size + u;
          if (!(pbr_depth[j] < 1.0f) || !(pic.position[4 * i + 3] > 0)) continue;
          for (int k = 0; k < 3; ++k) diff += std::abs(pbr_color[4 * j + k] - pic.color[4 * i + k]);
          ++seen;
        }
      }
      diff /= 3.0 * std::max<size_t>(seen, 1);
      diffs.push_back(diff);
      if (!(diff < 0.01)) {
        std::fprintf(stderr,
                     "%s %d: the PBR bare program's colours differ from partsim's by %.4f\n",
                     c.name, size, diff);
        status = 1;
      }

      // four runs, rotating which goes first
      std::vector<double> fps[4], ratio[4];
      for (int r = 0; r < reps; ++r) {
        double f[4] = {0, 0, 0, 0};
        for (int k = 0; k < 4; ++k) {
          switch ((r + k) % 4) {
            case 0:
              f[0] = Fps([&] { bare.Render(c.world, cam, &color, &depth); }, seconds);
              break;
            case 1:
              f[1] = Fps([&] { bare_pbr.Render(c.world, cam, &pbr_color, &pbr_depth); }, seconds);
              break;
            case 2:
              f[2] =
                  Fps([&] { partsim_backend->Render(c.world, cam, &pic, kColorDepth); }, seconds);
              break;
            case 3:
              f[3] = Fps([&] { partsim_backend->Render(c.world, cam, &pic, partsim::kAllOutputs); },
                         seconds);
              break;
          }
        }
        for (int k = 0; k < 4; ++k) fps[k].push_back(f[k]);
        ratio[0].push_back(f[2] / f[0]);
        ratio[1].push_back(f[2] / f[1]);
        ratio[2].push_back(f[3] / f[0]);
        ratio[3].push_back(f[3] / f[1]);
      }
      std::printf("%-16s %5d %6zu | %9.1f %9.1f %9.1f %9.1f | %8.3f %8.3f %8.3f %8.3f\n", c.name,
                  size, TriangleCount(c.world), Median(fps[0]), Median(fps[1]), Median(fps[2]),
                  Median(fps[3]), Median(ratio[0]), Median(ratio[1]), Median(ratio[2]),
                  Median(ratio[3]));
      std::fflush(stdout);
    }
  }
  std::printf("mean colour difference, bare PBR against partsim c+d, by row:");
  for (double d : diffs) std::printf(" %.4f", d);
  std::printf("\n");
  return status;
}
