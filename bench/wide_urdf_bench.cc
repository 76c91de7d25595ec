// Wide and deep URDFs: a generated robot of N revolute links on one root (wide: 2 cm boxes on a
// 3 cm grid, none touching) or in one chain (deep: each link 3 cm from its parent), loaded
// through UrdfLoader::LoadFromString into a fresh scene (which compiles it) and stepped. Each
// size runs in a child process, so that its peak resident memory is its own. Files over
// kMaxUrdfLinks or kMaxUrdfChainDepth are refused: the line gives the time and memory to refuse.
//
// Usage: partsim_wide_urdf_bench [--wide 500,1000,2000,4000,8000] [--deep 250,500,1000,2000]
//                                [--steps 20]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string Urdf(int n, bool deep) {
  std::ostringstream u;
  u << "<robot name='r'><link name='root'/>";
  for (int i = 0; i < n; ++i) {
    u << "<link name='l" << i << "'><inertial><mass value='0.1'/><inertia ixx='1e-4' iyy='1e-4' "
      << "izz='1e-4' ixy='0' ixz='0' iyz='0'/></inertial><collision><geometry><box "
      << "size='0.02 0.02 0.02'/></geometry></collision></link>";
    const std::string parent = deep && i > 0 ? "l" + std::to_string(i - 1) : "root";
    u << "<joint name='j" << i << "' type='revolute'><parent link='" << parent
      << "'/><child link='l" << i << "'/><origin xyz='" << (deep ? 0.03 : 0.03 * (i % 50)) << " "
      << (deep ? 0.0 : 0.03 * (i / 50)) << " 0'/><axis xyz='0 0 1'/><limit lower='-1' upper='1' "
      << "effort='1' velocity='1'/></joint>";
  }
  u << "</robot>";
  return u.str();
}

void Run(int n, bool deep, int steps) {
  const std::string text = Urdf(n, deep);
  partsim::Scene scene;
  partsim::UrdfLoader loader = CreateUrdfLoader(scene);
  auto t0 = Clock::now();
  std::string outcome;
  double load = 0, step = 0;
  try {
    loader.LoadFromString(text);
    load = Seconds(t0);
    auto t1 = Clock::now();
    scene.Step(steps);
    step = Seconds(t1) / steps;
    outcome = "loaded";
  } catch (const partsim::Error& e) {
    load = Seconds(t0);
    outcome = std::string("refused: ") + e.what();
    if (outcome.size() > 60) outcome = outcome.substr(0, 57) + "...";
  }
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  std::printf("| %s | %d | %.2f | %.2f | %.0f | %s |\n", deep ? "deep" : "wide", n, load,
              1e3 * step, usage.ru_maxrss / 1024.0, outcome.c_str());
  std::fflush(stdout);
}

std::vector<int> List(const char* s) {
  std::vector<int> out;
  std::stringstream list(s);
  std::string item;
  while (std::getline(list, item, ',')) out.push_back(std::stoi(item));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> wide = {500, 1000, 2000, 4000, 8000}, deep = {250, 500, 1000, 2000};
  int steps = 20;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i];
    if (arg == "--wide") {
      wide = List(argv[i + 1]);
    } else if (arg == "--deep") {
      deep = List(argv[i + 1]);
    } else if (arg == "--steps") {
      steps = std::stoi(argv[i + 1]);
    } else {
      std::fprintf(stderr, "unknown option %s\n", arg.c_str());
      return 2;
    }
  }
  std::printf(
      "| robot | joints | load [s] | step [ms] | peak RSS [MB] | outcome |\n"
      "|---|---:|---:|---:|---:|---|\n");
  std::fflush(stdout);
  for (bool is_deep : {false, true}) {
    for (int n : is_deep ? deep : wide) {
      // one child per size: its peak memory is its own
      const pid_t pid = fork();
      if (pid == 0) {
        Run(n, is_deep, steps);
        _exit(0);
      }
      int status = 0;
      waitpid(pid, &status, 0);
    }
  }
  return 0;
}
