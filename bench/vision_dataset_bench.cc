// Detection dataset benchmark (issue 16, "Speed"): views per second of `partsim vision
// detection-dataset` (vision::GenerateDataset: render, then write RGB, depth PNG and NPY, the
// part-instance PNG, the point cloud NPZ, the RLE masks and views.json) against the bare
// rasterizer rate measured on the same objects, on the same machine, in the same run.
//
// The objects: a tree generated with partsim's generator (GenerateObject / WriteObject), a
// systematic sample of the paper's category mix (object i is the category holding model
// (i + 1/2) * 2346 / N in the order of the paper's table, counted by its #M), in a temporary
// folder.
//
// Runs per repetition, rotating which goes first:
//   raster C+P+S  partsim's rasterizer (RenderBackend::Render, read-back included) asked for
//                 Color + Position + Segmentation, the outputs a dataset view takes, at one
//                 camera per object like a dataset view's (one object's scene, its lights);
//                 objects in turn, one warm-up picture each (mesh upload) not counted
//   bare GL       a bare OpenGL program on the same triangles (one Lambert term, colour RGBA
//                 float + depth read back), partsim_render_bench's "bare" column
//   dataset j1    GenerateDataset --views V --size S --jobs 1 into a fresh folder
//   dataset j2    the same with --jobs 2
// A dataset run's views/s is summary.views / summary.seconds ("all": the folder scan, every
// object's parse for the split, the split files at the end included); "render" leaves out the
// time of a merge-only run into the finished folder (the scan, the parse and the split files
// without rendering), i.e. it counts the workers' time only. The projection for the paper's
// 2,346 objects x 20 views is 46,920 / render rate + the merge-only time scaled by objects.
//
// After the table: the phases of the dataset runs (GenerateDataset's DatasetSummary::phases),
// wall and thread CPU ms per view summed over the workers, to tell a shared bottleneck (wall grows
// with --jobs, CPU does not) from work that is simply slow.
//
// Usage: partsim_vision_dataset_bench [--objects N] [--views V] [--size S] [--reps R]
//                                     [--seconds T] [--jobs J1,J2,...] [--tree DIR] [--keep]
//                                     [--processes P]
// (--tree: the objects of an existing tree, e.g. ../shared/realdata, instead of generated ones;
// --processes P: each dataset run is P processes at once, each rendering its shard i/P with
// --jobs J workers, then a merge-only run, as a scheduler would split the work; "all" is then
// views / (the processes' wall time + the merge's), "render" leaves out the merge-only time, and
// CPU counts the processes')
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bare_renderer.h"
#include "partsim/assets/generator.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/core/constants.h"
#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/scene_render.h"
#include "partsim/vision/dataset.h"

namespace {

namespace fs = std::filesystem;
using partsim::CameraParams;
using partsim::kPi;
using partsim::MeshData;
using partsim::RenderInstance;
using partsim::RenderWorld;

constexpr int kPaperObjects = 2346;
constexpr int kPaperViews = 20;

double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// CPU seconds of the whole process (every thread: the workers and llvmpipe's), which other jobs
// on a shared machine disturb less than the wall clock
double CpuNow() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The tree: object i of N is the category that holds model (i + 1/2) * 2346 / N when the
// paper's models are counted in the order of its table.
std::vector<std::string> MakeTree(const std::string& dir, int objects, std::uint64_t seed) {
  const std::vector<std::string> categories = partsim::GeneratorCategories();
  std::vector<int> cumulative;
  int total = 0;
  for (const std::string& c : categories)
    cumulative.push_back(total += partsim::PaperModelCount(c));
  std::map<std::string, int> next_index;
  std::vector<std::string> picked;
  for (int i = 0; i < objects; ++i) {
    const double model = (i + 0.5) * total / objects;
    size_t c = 0;
    while (c + 1 < categories.size() && cumulative[c] <= model) ++c;
    const partsim::GeneratedObject o =
        partsim::GenerateObject(categories[c], next_index[categories[c]]++, seed);
    partsim::WriteObject(o, dir + "/" + o.anno_id);
    picked.push_back(categories[c]);
  }
  return picked;
}

// One object's render world and a camera like a dataset view's: the scene GenerateDataset
// builds (its lights), joints at rest, the camera in front of the object at 35 degrees of
// elevation, 1.15 times the distance that keeps the bounding sphere in a 35 degree frame.
struct ObjectView {
  RenderWorld world;
  CameraParams camera;
};

ObjectView MakeObjectView(const std::string& folder, int size) {
  partsim::Scene scene;
  partsim::PartNetMobilityLoader loader(&scene);
  const partsim::PartNetMobilityObject object = loader.Parse(folder);
  partsim::Articulation art = scene.AddArticulation(object.articulation);
  const Eigen::Vector3d front = art.GetRootPose().q * -Eigen::Vector3d::UnitX();
  SetAmbientLight(scene, Eigen::Vector3f::Constant(0.35f));
  AddDirectionalLight(scene, (-front - Eigen::Vector3d(0, 0, 1.5)).normalized(),
                      Eigen::Vector3f::Constant(2.2f), false);
  UpdateRender(scene);
  ObjectView out;
  out.world = GetRenderWorld(scene);
  Eigen::AlignedBox3d box;
  for (const RenderInstance& inst : out.world.instances)
    for (const Eigen::Vector3f& v : inst.mesh->vertices)
      box.extend((inst.X_WV * v.cast<double>().homogeneous()).head<3>());
  const double fovy = 35.0 * kPi / 180.0;
  const double radius = std::max(0.5 * box.diagonal().norm(), 1e-3);
  const double azimuth = std::atan2(front.y(), front.x()), elevation = 35.0 * kPi / 180.0;
  const Eigen::Vector3d dir(std::cos(elevation) * std::cos(azimuth),
                            std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  const Eigen::Vector3d centre = box.center();
  const double distance = 1.15 * radius / std::sin(0.5 * fovy);
  out.camera =
      partsim::MakeCameraParams(size, size, partsim::IntrinsicsFromFovy(size, size, fovy), 0.01,
                                100.0, partsim::CameraLookAt(centre + distance * dir, centre));
  return out;
}

// ---------------------------------------------------------------------------------------------

struct Rates {
  double per_second = 0;  // pictures per wall-clock second
  double cpu_ms = 0;      // process CPU milliseconds per picture
};

// Pictures per second over the objects in turn: per object one warm-up picture (mesh upload),
// then pictures for `seconds` / objects.
template <typename Prepare, typename Draw>
Rates Rate(size_t objects, double seconds, Prepare&& prepare, Draw&& draw) {
  long frames = 0;
  double elapsed = 0, cpu = 0;
  for (size_t i = 0; i < objects; ++i) {
    prepare(i);
    draw(i);
    const double start = Now(), cpu_start = CpuNow();
    double t = 0;
    do {
      draw(i);
      ++frames;
      t = Now() - start;
    } while (t < seconds / static_cast<double>(objects));
    elapsed += t;
    cpu += CpuNow() - cpu_start;
  }
  return {static_cast<double>(frames) / elapsed, 1000 * cpu / static_cast<double>(frames)};
}

struct DatasetRun {
  double all = 0;     // views / summary.seconds
  double render = 0;  // views / (summary.seconds - merge-only seconds)
  double merge = 0;   // merge-only seconds
  double cpu_ms = 0;  // process CPU milliseconds per view, the merge-only run's left out
  long views = 0;
  std::vector<partsim::vision::DatasetPhase> phases;  // one process's (not for --processes)
};

partsim::vision::DatasetOptions Options(const std::string& tree, const std::string& out, int views,
                                        int size, int jobs) {
  partsim::vision::DatasetOptions o;
  o.dataset_root = tree;
  o.out = out;
  o.views = views;
  o.size = size;
  o.seed = 1;
  o.jobs = jobs;
  o.progress = false;
  return o;
}

double ChildrenCpu() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// The run split into `processes` processes of this program, shard i of them each
// (--shard-worker), started at once; then a merge-only run here.
DatasetRun RunShardedDataset(const std::string& tree, const std::string& out, int views, int size,
                             int jobs, int processes) {
  fs::remove_all(out);
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  std::vector<pid_t> pids;
  const double cpu0 = ChildrenCpu();
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < processes; ++i) {
    const std::string shard = std::to_string(i) + "/" + std::to_string(processes);
    const std::vector<std::string> args = {self,
                                           "--shard-worker",
                                           shard,
                                           "--tree",
                                           tree,
                                           "--out",
                                           out,
                                           "--views",
                                           std::to_string(views),
                                           "--size",
                                           std::to_string(size),
                                           "--jobs",
                                           std::to_string(jobs)};
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = 0;
    if (posix_spawn(&pid, self.c_str(), nullptr, nullptr, argv.data(), environ) != 0)
      throw partsim::Error("could not start a shard process");
    pids.push_back(pid);
  }
  for (pid_t pid : pids) {
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
      throw partsim::Error("a shard process failed");
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = ChildrenCpu() - cpu0;
  partsim::vision::DatasetOptions o = Options(tree, out, views, size, jobs);
  o.merge_only = true;
  const partsim::vision::DatasetSummary m = partsim::vision::GenerateDataset(o);
  fs::remove_all(out);
  DatasetRun r;
  r.views = static_cast<long>(m.objects) * views;
  r.merge = m.seconds;
  r.cpu_ms = 1000 * cpu / static_cast<double>(r.views);
  r.all = static_cast<double>(r.views) / (wall + m.seconds);
  r.render = static_cast<double>(r.views) / wall;
  return r;
}

DatasetRun RunDataset(const std::string& tree, const std::string& out, int views, int size,
                      int jobs, int processes) {
  if (processes > 1) return RunShardedDataset(tree, out, views, size, jobs, processes);
  fs::remove_all(out);
  partsim::vision::DatasetOptions o = Options(tree, out, views, size, jobs);
  const double cpu0 = CpuNow();
  const partsim::vision::DatasetSummary s = partsim::vision::GenerateDataset(o);
  const double cpu1 = CpuNow();
  if (s.failed > 0)
    throw partsim::Error("dataset run failed: " + (s.errors.empty() ? "" : s.errors.front()));
  o.merge_only = true;
  const partsim::vision::DatasetSummary m = partsim::vision::GenerateDataset(o);
  const double cpu2 = CpuNow();
  fs::remove_all(out);
  DatasetRun r;
  r.views = s.views;
  r.merge = m.seconds;
  r.cpu_ms = 1000 * ((cpu1 - cpu0) - (cpu2 - cpu1)) / static_cast<double>(s.views);
  r.all = static_cast<double>(s.views) / s.seconds;
  r.render = static_cast<double>(s.views) / std::max(s.seconds - m.seconds, 1e-9);
  r.phases = s.phases;
  return r;
}

std::string Minutes(double seconds) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f min", seconds / 60.0);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  int objects = 12, views = 20, size = 512, reps = 3, processes = 1;
  std::string shard_worker, out_dir;  // the hidden --shard-worker mode (RunShardedDataset)
  std::vector<int> jobs = {1, 2};
  double seconds = 4.0;
  bool keep = false;
  std::string tree;  // an existing tree instead of a generated one
  for (int i = 1; i < argc; ++i) {
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", argv[i]);
        std::exit(2);
      }
      return argv[++i];
    };
    if (!std::strcmp(argv[i], "--objects")) {
      objects = std::atoi(next());
    } else if (!std::strcmp(argv[i], "--views")) {
      views = std::atoi(next());
    } else if (!std::strcmp(argv[i], "--size")) {
      size = std::atoi(next());
    } else if (!std::strcmp(argv[i], "--reps")) {
      reps = std::atoi(next());
    } else if (!std::strcmp(argv[i], "--seconds")) {
      seconds = std::atof(next());
    } else if (!std::strcmp(argv[i], "--jobs")) {
      jobs.clear();
      for (const char* p = next(); *p;) {
        char* end = nullptr;
        jobs.push_back(static_cast<int>(std::strtol(p, &end, 10)));
        if (jobs.back() < 1 || end == p || (*end != ',' && *end != '\0')) {
          std::fprintf(stderr, "--jobs takes a list like 1,2\n");
          return 2;
        }
        p = *end == ',' ? end + 1 : end;
      }
    } else if (!std::strcmp(argv[i], "--tree")) {
      tree = next();
    } else if (!std::strcmp(argv[i], "--keep")) {
      keep = true;
    } else if (!std::strcmp(argv[i], "--processes")) {
      processes = std::atoi(next());
    } else if (!std::strcmp(argv[i], "--shard-worker")) {
      shard_worker = next();
    } else if (!std::strcmp(argv[i], "--out")) {
      out_dir = next();
    } else {
      std::fprintf(stderr,
                   "usage: %s [--objects N] [--views V] [--size S] [--reps R] [--seconds T] "
                   "[--jobs J1,J2,...] [--tree DIR] [--keep] [--processes P]\n",
                   argv[0]);
      return 2;
    }
  }
  if (!shard_worker.empty()) {
    partsim::vision::DatasetOptions o = Options(tree, out_dir, views, size, jobs.front());
    if (std::sscanf(shard_worker.c_str(), "%d/%d", &o.shard_index, &o.shard_count) != 2) return 2;
    const partsim::vision::DatasetSummary s = partsim::vision::GenerateDataset(o);
    return s.failed > 0 ? 1 : 0;
  }
  if (objects < 1 || views < 1 || size < 16 || reps < 1 || processes < 1) {
    std::fprintf(stderr, "bad arguments\n");
    return 2;
  }

  const std::string root =
      (fs::temp_directory_path() / ("partsim_vision_dataset_bench_" + std::to_string(::getpid())))
          .string();
  fs::remove_all(root);
  const std::string out = root + "/out";
  std::vector<std::string> folders;
  if (tree.empty()) {
    tree = root + "/tree";
    const std::vector<std::string> picked = MakeTree(tree, objects, 1);
    std::map<std::string, int> mix;
    for (const std::string& c : picked) ++mix[c];
    std::printf("objects: %d generated (", objects);
    bool first = true;
    for (const auto& [c, n] : mix)
      std::printf("%s%s %d", first ? "" : ", ", c.c_str(), n), first = false;
    std::printf(")\n");
  }
  // the objects' scenes, one camera each (every folder holding a mobility.urdf, as the dataset
  // finds them)
  for (const auto& e : fs::recursive_directory_iterator(tree))
    if (e.is_regular_file() && e.path().filename() == "mobility.urdf")
      folders.push_back(e.path().parent_path().string());
  std::sort(folders.begin(), folders.end());
  objects = static_cast<int>(folders.size());
  if (objects == 0) {
    std::fprintf(stderr, "no object (a folder with mobility.urdf) under '%s'\n", tree.c_str());
    return 2;
  }
  std::printf("tree: %s, %d objects\n", tree.c_str(), objects);
  std::vector<ObjectView> scenes;
  size_t triangles = 0;
  for (const std::string& f : folders) {
    scenes.push_back(MakeObjectView(f, size));
    for (const RenderInstance& inst : scenes.back().world.instances)
      triangles += inst.mesh->faces.size();
  }
  auto backend = partsim::MakeRasterBackend();
  partsim_bench::BareRenderer bare;
  std::vector<float> bare_color, bare_depth;  // what it reads back
  const unsigned kDatasetOutputs = partsim::kColor | partsim::kPosition | partsim::kSegmentation;
  std::printf("device: %s; %zu triangles per object on average; %d x %d, %d views per object\n",
              backend->Device().c_str(), triangles / scenes.size(), size, size, views);
  if (processes > 1)
    std::printf("each dataset run: %d processes at once, shard i/%d each, then a merge-only run\n",
                processes, processes);
  std::printf("%d repetitions; rasterizer rates over >= %.1f s each; hardware threads %u\n", reps,
              seconds, std::thread::hardware_concurrency());
  std::fflush(stdout);

  partsim::Picture pic;
  const size_t runs = 2 + jobs.size();  // raster, bare GL, one dataset run per --jobs value
  std::vector<double> raster, raster_cpu, bare_rate, bare_cpu;
  std::vector<std::vector<double>> j_all(jobs.size()), j_render(jobs.size()), j_cpu(jobs.size()),
      j_merge(jobs.size());
  // per --jobs value: each phase's wall and CPU ms per view (load: per object), summed over the
  // workers, one entry per repetition
  std::vector<std::map<std::string, std::pair<std::vector<double>, std::vector<double>>>> j_phases(
      jobs.size());
  long views_per_run = 0;
  for (int r = 0; r < reps; ++r) {
    for (size_t k = 0; k < runs; ++k) {
      const size_t run = (static_cast<size_t>(r) + k) % runs;
      if (run == 0) {
        const Rates rate = Rate(
            scenes.size(), seconds, [](size_t) {},
            [&](size_t i) {
              backend->Render(scenes[i].world, scenes[i].camera, &pic, kDatasetOutputs);
            });
        raster.push_back(rate.per_second);
        raster_cpu.push_back(rate.cpu_ms);
      } else if (run == 1) {
        const Rates rate = Rate(
            scenes.size(), seconds, [&](size_t i) { bare.Load(scenes[i].world); },
            [&](size_t i) {
              bare.Render(scenes[i].world, scenes[i].camera, &bare_color, &bare_depth);
            });
        bare_rate.push_back(rate.per_second);
        bare_cpu.push_back(rate.cpu_ms);
      } else {
        const size_t j = run - 2;
        const DatasetRun d = RunDataset(tree, out, views, size, jobs[j], processes);
        j_all[j].push_back(d.all);
        j_render[j].push_back(d.render);
        j_cpu[j].push_back(d.cpu_ms);
        j_merge[j].push_back(d.merge);
        views_per_run = d.views;
        for (const partsim::vision::DatasetPhase& p : d.phases) {
          if (p.count == 0) continue;
          auto& [wall, cpu] = j_phases[j][p.name];
          wall.push_back(1000 * p.wall_seconds / static_cast<double>(p.count));
          cpu.push_back(1000 * p.cpu_seconds / static_cast<double>(p.count));
        }
      }
    }
    std::printf("rep %d: raster C+P+S %.1f/s (%.1f cpu ms), bare GL %.1f/s (%.1f cpu ms)", r + 1,
                raster.back(), raster_cpu.back(), bare_rate.back(), bare_cpu.back());
    for (size_t j = 0; j < jobs.size(); ++j)
      std::printf(", dataset j%d %.2f views/s (render %.2f, %.1f cpu ms)", jobs[j], j_all[j].back(),
                  j_render[j].back(), j_cpu[j].back());
    std::printf("\n");
    std::fflush(stdout);
  }

  const double raster_m = Median(raster), bare_m = Median(bare_rate);
  const double raster_cpu_m = Median(raster_cpu), bare_cpu_m = Median(bare_cpu);
  std::printf("\nmedians over %d repetitions (%ld views per dataset run)\n", reps, views_per_run);
  std::printf("  raster C+P+S (partsim, read-back)  %8.1f pictures/s  %6.1f cpu ms/picture\n",
              raster_m, raster_cpu_m);
  std::printf("  bare GL (Lambert, colour + depth)  %8.1f pictures/s  %6.1f cpu ms/picture\n",
              bare_m, bare_cpu_m);
  std::printf("%-9s %8s %8s %8s | %8s %8s %8s | %8s | %s\n", "dataset", "views/s", "render",
              "cpu ms", "/raster", "/bare GL", "cpu/rast", "merge s", "2,346 x 20 views");
  for (size_t j = 0; j < jobs.size(); ++j) {
    const double all = Median(j_all[j]), render = Median(j_render[j]), cpu = Median(j_cpu[j]);
    const double merge = Median(j_merge[j]);
    // the rendering at the measured rate, the start (scan, parse) and the split files scaled
    // by the number of objects
    const double projected = kPaperObjects * kPaperViews / render + merge * kPaperObjects / objects;
    const std::string name = (processes > 1 ? std::to_string(processes) + " x " : std::string()) +
                             "--jobs " + std::to_string(jobs[j]);
    std::printf("%-9s %8.2f %8.2f %8.1f | %8.3f %8.3f %8.3f | %8.2f | %s\n", name.c_str(), all,
                render, cpu, render / raster_m, render / bare_m, raster_cpu_m / cpu, merge,
                Minutes(projected).c_str());
  }
  std::printf(
      "(render: views/s without the merge-only run's time; /raster, /bare GL: render "
      "rate over theirs; cpu/rast: raster CPU per picture over dataset CPU per view)\n");
  // where the workers' time goes: a phase whose wall time per view grows with the workers while
  // its CPU time does not waits for something they share (a lock, the GPU's driver, the disk)
  if (processes <= 1) {
    std::printf("\nphases, ms per view (load: per object), wall / thread CPU, medians:\n%-9s",
                "dataset");
    const char* names[] = {"load", "render", "convert", "write"};
    for (const char* n : names) std::printf(" %17s", n);
    std::printf("\n");
    for (size_t j = 0; j < jobs.size(); ++j) {
      std::printf("%-9s", ("--jobs " + std::to_string(jobs[j])).c_str());
      for (const char* n : names) {
        auto it = j_phases[j].find(n);
        if (it == j_phases[j].end()) {
          std::printf(" %17s", "-");
        } else {
          char cell[64];
          std::snprintf(cell, sizeof(cell), "%.2f / %.2f", Median(it->second.first),
                        Median(it->second.second));
          std::printf(" %17s", cell);
        }
      }
      std::printf("\n");
    }
  }
  if (!keep)
    fs::remove_all(root);
  else
    std::printf("kept %s\n", root.c_str());
  return 0;
}
