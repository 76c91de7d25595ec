// OBJ files per second through partsim's reader (LoadMeshFile) and through assimp's importer
// (the path LoadMeshFile took for OBJ before), on the same files in the same run. The two take
// turns within each repetition, which goes first alternating.
//
// Usage: partsim_mesh_load_bench [--tree DIR] [--objects N] [--reps R]
//   --tree: every .obj under DIR (e.g. ../shared/realdata); default: N generated objects (24),
//   two of each of 12 categories of the paper's mix.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include "assets/obj_reader.h"
#include "partsim/assets/generator.h"
#include "partsim/assets/mesh.h"

namespace fs = std::filesystem;

namespace {

double CpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Rate {
  double files_per_s = 0, cpu_ms_per_file = 0;
  size_t triangles = 0;
};

template <typename Load>
Rate Time(const std::vector<std::string>& files, Load load) {
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = CpuSeconds();
  Rate r;
  for (const std::string& f : files)
    for (const partsim::LoadedMesh& m : load(f)) r.triangles += m.mesh->faces.size();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.files_per_s = static_cast<double>(files.size()) / wall;
  r.cpu_ms_per_file = 1e3 * (CpuSeconds() - c0) / static_cast<double>(files.size());
  return r;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  std::string tree;
  int objects = 24, reps = 5;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--tree") && i + 1 < argc) {
      tree = argv[++i];
    } else if (!std::strcmp(argv[i], "--objects") && i + 1 < argc) {
      objects = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) {
      reps = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: %s [--tree DIR] [--objects N] [--reps R]\n", argv[0]);
      return 2;
    }
  }
  if (objects < 1 || reps < 1) return 2;
  const fs::path scratch =
      fs::temp_directory_path() / ("partsim_mesh_load_bench_" + std::to_string(::getpid()));
  if (tree.empty()) {
    tree = (scratch / "tree").string();
    const char* categories[] = {"Bucket",  "Camera",           "CoffeeMachine", "Eyeglasses",
                                "Faucet",  "Keyboard",         "KitchenPot",    "Lighter",
                                "Stapler", "StorageFurniture", "Table",         "USB"};
    for (int i = 0; i < objects; ++i) {
      const partsim::GeneratedObject o = partsim::GenerateObject(categories[i % 12], i, 2026);
      partsim::WriteObject(o, tree + "/" + o.anno_id);
    }
  }
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(tree))
    if (e.is_regular_file() && e.path().extension() == ".obj") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "no .obj file under '%s'\n", tree.c_str());
    return 2;
  }
  size_t bytes = 0;
  for (const std::string& f : files) bytes += fs::file_size(f);
  std::printf("%zu OBJ files under %s, %.1f kB on average; %d repetitions\n", files.size(),
              tree.c_str(), 1e-3 * static_cast<double>(bytes) / static_cast<double>(files.size()),
              reps);

  auto ours = [](const std::string& f) { return partsim::LoadMeshFile(f); };
  auto assimp = [](const std::string& f) {
    return partsim::internal::LoadMeshFileWithAssimp(f, Eigen::Vector3d::Ones());
  };
  std::vector<double> ours_rate, assimp_rate, ours_cpu, assimp_cpu, ratio;
  for (int r = 0; r < reps; ++r) {
    Rate a, b;
    if (r % 2 == 0) {
      a = Time(files, ours);
      b = Time(files, assimp);
    } else {
      b = Time(files, assimp);
      a = Time(files, ours);
    }
    if (a.triangles != b.triangles) {
      std::fprintf(stderr, "the readers disagree: %zu triangles against %zu\n", a.triangles,
                   b.triangles);
      return 1;
    }
    std::printf("rep %d: partsim %.0f files/s (%.3f cpu ms), assimp %.0f files/s (%.3f cpu ms)\n",
                r + 1, a.files_per_s, a.cpu_ms_per_file, b.files_per_s, b.cpu_ms_per_file);
    ours_rate.push_back(a.files_per_s);
    assimp_rate.push_back(b.files_per_s);
    ours_cpu.push_back(a.cpu_ms_per_file);
    assimp_cpu.push_back(b.cpu_ms_per_file);
    ratio.push_back(a.files_per_s / b.files_per_s);
  }
  std::printf(
      "medians: partsim %.0f files/s (%.3f cpu ms/file), assimp %.0f files/s (%.3f cpu "
      "ms/file); partsim / assimp %.1f (median of the repetitions' ratios)\n",
      Median(ours_rate), Median(ours_cpu), Median(assimp_rate), Median(assimp_cpu), Median(ratio));
  fs::remove_all(scratch);
  return 0;
}
