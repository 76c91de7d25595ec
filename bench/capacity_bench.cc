// Capacity: N primitive actors added one by one to a partsim scene, then the first step (which
// compiles them) and 100 more, against raw MuJoCo loading the same bodies from one MJCF string
// and stepping as often. Median of the repetitions; prints one line per N and the ratio.
//
// Usage: partsim_capacity_bench [--reps N] [--sizes 100,300,1000] [--integrator euler|implicit]
// The boxes lie on a grid in zero gravity, 0.3 m apart (no contacts): the cost measured is the
// scene's size, not the contact solver's.
#include <mujoco/mujoco.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "partsim/physics/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

Eigen::Vector3d At(int i) {
  return Eigen::Vector3d(0.3 * (i % 10), 0.3 * (i / 10 % 10), 0.3 * (i / 100));
}

// partsim: add one by one, then step; returns (add seconds, first step, 100 steps)
std::vector<double> RunPartsim(int n, bool implicit) {
  partsim::SceneConfig cfg;
  cfg.gravity = Eigen::Vector3d::Zero();
  cfg.integrator = implicit ? partsim::Integrator::kImplicit : partsim::Integrator::kEuler;
  partsim::Scene scene(cfg);
  auto t0 = Clock::now();
  for (int i = 0; i < n; ++i) {
    partsim::ActorDesc d;
    d.name = "b" + std::to_string(i);
    d.pose = partsim::Pose(At(i));
    partsim::CollisionShape s;
    s.type = partsim::ShapeType::kBox;
    s.half_size = Eigen::Vector3d::Constant(0.05);
    d.collisions.push_back(s);
    scene.AddActor(d);
  }
  const double add = Seconds(t0);
  t0 = Clock::now();
  scene.Step(1);
  const double first = Seconds(t0);
  t0 = Clock::now();
  scene.Step(100);
  return {add, first, Seconds(t0)};
}

// raw MuJoCo: the same bodies in one MJCF string, loaded once
std::vector<double> RunRaw(int n, bool implicit) {
  auto t0 = Clock::now();
  std::ostringstream xml;
  xml << "<mujoco><option gravity=\"0 0 0\" integrator=\"" << (implicit ? "implicit" : "Euler")
      << "\"/><worldbody>";
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = At(i);
    xml << "<body pos=\"" << p.x() << " " << p.y() << " " << p.z()
        << "\"><freejoint/><geom type=\"box\" size=\"0.05 0.05 0.05\"/></body>";
  }
  xml << "</worldbody></mujoco>";
  const std::string path = "/tmp/partsim_capacity_bench_" + std::to_string(getpid()) + ".xml";
  FILE* f = std::fopen(path.c_str(), "w");
  std::fputs(xml.str().c_str(), f);
  std::fclose(f);
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof(err));
  std::remove(path.c_str());
  if (!m) {
    std::fprintf(stderr, "raw MuJoCo could not load %d bodies: %s\n", n, err);
    return {-1, -1, -1};
  }
  mjData* d = mj_makeData(m);
  mj_step(m, d);
  const double first = Seconds(t0);  // building and loading, and one step
  t0 = Clock::now();
  for (int i = 0; i < 100; ++i) mj_step(m, d);
  const double steps = Seconds(t0);
  mj_deleteData(d);
  mj_deleteModel(m);
  return {0.0, first, steps};
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 3;
  std::vector<int> sizes = {100, 300, 1000};
  bool implicit = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--reps" && i + 1 < argc) {
      reps = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--sizes" && i + 1 < argc) {
      sizes.clear();
      std::stringstream in(argv[++i]);
      std::string t;
      while (std::getline(in, t, ',')) sizes.push_back(std::atoi(t.c_str()));
    } else if (a == "--integrator" && i + 1 < argc) {
      implicit = std::string(argv[++i]) == "implicit";
    } else {
      std::fprintf(stderr,
                   "usage: partsim_capacity_bench [--reps N] [--sizes A,B] "
                   "[--integrator euler|implicit]\n");
      return 2;
    }
  }
  std::printf("integrator %s, %d repetitions, medians\n", implicit ? "implicit" : "euler", reps);
  std::printf("%6s %10s %12s %12s %12s %12s %10s %10s\n", "N", "add (s)", "+1st step", "raw load",
              "100 steps", "raw 100", "load x", "step x");
  for (int n : sizes) {
    std::vector<double> add, first, steps, raw_first, raw_steps;
    for (int r = 0; r < reps; ++r) {  // interleaved
      std::vector<double> p = RunPartsim(n, implicit), q = RunRaw(n, implicit);
      add.push_back(p[0]);
      first.push_back(p[0] + p[1]);
      steps.push_back(p[2]);
      raw_first.push_back(q[1]);
      raw_steps.push_back(q[2]);
    }
    const double a = Median(add), f = Median(first), s = Median(steps), rf = Median(raw_first),
                 rs = Median(raw_steps);
    std::printf("%6d %10.3f %12.3f %12.3f %12.3f %12.3f %10.2f %10.2f\n", n, a, f, rf, s, rs,
                f / rf, s / rs);
    std::fflush(stdout);
  }
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  std::printf("peak memory of the process: %ld MB\n", u.ru_maxrss / 1024);
  return 0;
}
