// Capacity: scenes of many bodies built through partsim's API and stepped, against raw MuJoCo
// (the same version, linked the same way) loading the same bodies from one MJCF string and
// stepping as often. Median of the repetitions (partsim and raw taking turns); one line per
// size with the build time, the time per step, the warnings the scene gave and the ratios.
//
// Usage: partsim_capacity_bench [--scenario ground|grid|chain] [--sizes 300,1000] [--reps N]
//                               [--steps S] [--integrator implicitfast|implicit|euler|rk4]
//   ground  N free 4 cm boxes resting on the ground under gravity (4 contacts each), in
//           rows 6 cm apart (the default)
//   grid    N free 10 cm boxes 0.3 m apart in zero gravity (no contacts: the scene's size alone)
//   chain   one fixed-root chain of N capsule links on revolute joints, in zero gravity
// The default integrator is partsim's default (implicitfast).
#include <mujoco/mujoco.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
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

struct Options {
  std::string scenario = "ground";
  partsim::Integrator integrator = partsim::SceneConfig().integrator;
  int steps = 200;
};

const char* MjIntegrator(partsim::Integrator i) {
  switch (i) {
    case partsim::Integrator::kEuler:
      return "Euler";
    case partsim::Integrator::kRK4:
      return "RK4";
    case partsim::Integrator::kImplicit:
      return "implicit";
    case partsim::Integrator::kImplicitFast:
      return "implicitfast";
  }
  return "implicitfast";
}

Eigen::Vector3d At(const std::string& scenario, int i) {
  if (scenario == "ground") {
    const int side = 40;
    return Eigen::Vector3d(0.06 * (i % side), 0.06 * (i / side), 0.02);
  }
  return Eigen::Vector3d(0.3 * (i % 10), 0.3 * (i / 10 % 10), 0.3 * (i / 100));
}

double Half(const std::string& scenario) { return scenario == "ground" ? 0.02 : 0.05; }

struct Result {
  double build = 0;     ///< s: adding the bodies and the first step (which compiles)
  double per_step = 0;  ///< s per step over the steps after the first
  size_t warnings = 0;
};

Result RunPartsim(int n, const Options& o) {
  partsim::SceneConfig cfg;
  cfg.integrator = o.integrator;
  if (o.scenario != "ground") cfg.gravity = Eigen::Vector3d::Zero();
  auto t0 = Clock::now();
  partsim::Scene scene(cfg);
  if (o.scenario == "chain") {
    partsim::ArticulationDesc chain;
    chain.name = "chain";
    chain.fix_root = true;
    for (int i = 0; i < n; ++i) {
      partsim::LinkDesc l;
      l.name = "l" + std::to_string(i);
      l.parent = i - 1;
      partsim::CollisionShape s;
      s.type = partsim::ShapeType::kCapsule;
      s.radius = 0.01;
      s.half_length = 0.04;
      l.collisions.push_back(s);
      if (i > 0) {
        l.joint.name = "j" + std::to_string(i);
        l.joint.type = partsim::JointType::kRevolute;
        l.joint.lower = -0.5;
        l.joint.upper = 0.5;
        l.joint.pose_in_parent = partsim::Pose(Eigen::Vector3d(0.1, 0, 0));
      }
      chain.links.push_back(l);
    }
    scene.AddArticulation(chain);
  } else {
    if (o.scenario == "ground") scene.AddGround(0.0);
    for (int i = 0; i < n; ++i) {
      partsim::ActorDesc d;
      d.name = "b" + std::to_string(i);
      d.pose = partsim::Pose(At(o.scenario, i));
      partsim::CollisionShape s;
      s.type = partsim::ShapeType::kBox;
      s.half_size = Eigen::Vector3d::Constant(Half(o.scenario));
      d.collisions.push_back(s);
      scene.AddActor(d);
    }
  }
  scene.Step(1);
  Result r;
  r.build = Seconds(t0);
  t0 = Clock::now();
  scene.Step(o.steps);
  r.per_step = Seconds(t0) / o.steps;
  r.warnings = scene.GetWarnings().size();
  return r;
}

// A chain of n capsule links on hinges, built through MuJoCo's model-editing API: MuJoCo's own
// XML parser stops at 100 nested elements (it refuses a 500-link chain as MJCF text).
mjSpec* RawChain(int n, const Options& o) {
  mjSpec* spec = mj_makeSpec();
  spec->compiler.degree = 0;
  spec->option.gravity[2] = 0;
  spec->option.integrator = o.integrator == partsim::Integrator::kEuler      ? mjINT_EULER
                            : o.integrator == partsim::Integrator::kRK4      ? mjINT_RK4
                            : o.integrator == partsim::Integrator::kImplicit ? mjINT_IMPLICIT
                                                                             : mjINT_IMPLICITFAST;
  mjsBody* parent = mjs_findBody(spec, "world");
  for (int i = 0; i < n; ++i) {
    mjsBody* body = mjs_addBody(parent, nullptr);
    body->pos[0] = i == 0 ? 0.0 : 0.1;
    if (i > 0) {
      mjsJoint* j = mjs_addJoint(body, nullptr);
      j->type = mjJNT_HINGE;
      j->axis[0] = 1;
      j->axis[1] = j->axis[2] = 0;
      j->limited = mjLIMITED_TRUE;
      j->range[0] = -0.5;
      j->range[1] = 0.5;
    }
    mjsGeom* g = mjs_addGeom(body, nullptr);
    g->type = mjGEOM_CAPSULE;
    g->size[0] = 0.01;
    g->size[1] = 0.04;
    g->quat[0] = g->quat[2] = std::sqrt(0.5);  // along x
    g->quat[1] = g->quat[3] = 0;
    parent = body;
  }
  return spec;
}

// raw MuJoCo: the same bodies in one MJCF string (the chain through the model-editing API),
// parsed, compiled and stepped
Result RunRaw(int n, const Options& o) {
  auto t0 = Clock::now();
  std::ostringstream xml;
  xml << "<mujoco><option timestep=\"0.002\" integrator=\"" << MjIntegrator(o.integrator) << "\""
      << (o.scenario == "ground" ? "" : " gravity=\"0 0 0\"") << "/><worldbody>";
  if (o.scenario != "chain") {
    if (o.scenario == "ground") xml << "<geom type=\"plane\" size=\"0 0 1\"/>";
    const double h = Half(o.scenario);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p = At(o.scenario, i);
      xml << "<body pos=\"" << p.x() << " " << p.y() << " " << p.z()
          << "\"><freejoint/><geom type=\"box\" size=\"" << h << " " << h << " " << h
          << "\"/></body>";
    }
  }
  xml << "</worldbody></mujoco>";
  char err[1000] = "";
  mjSpec* spec = o.scenario == "chain"
                     ? RawChain(n, o)
                     : mj_parseXMLString(xml.str().c_str(), nullptr, err, sizeof(err));
  mjModel* m = spec ? mj_compile(spec, nullptr) : nullptr;
  if (!m) {
    std::fprintf(stderr, "raw MuJoCo could not load %d bodies: %s\n", n,
                 spec ? mjs_getError(spec) : err);
    if (spec) mj_deleteSpec(spec);
    return {-1, -1, 0};
  }
  mj_deleteSpec(spec);
  mjData* d = mj_makeData(m);
  mj_step(m, d);
  Result r;
  r.build = Seconds(t0);
  t0 = Clock::now();
  for (int i = 0; i < o.steps; ++i) mj_step(m, d);
  r.per_step = Seconds(t0) / o.steps;
  for (int k = 0; k < mjNWARNING; ++k) r.warnings += d->warning[k].number > 0 ? 1 : 0;
  mj_deleteData(d);
  mj_deleteModel(m);
  return r;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 3;
  std::vector<int> sizes;
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--reps" && i + 1 < argc) {
      reps = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--steps" && i + 1 < argc) {
      o.steps = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--sizes" && i + 1 < argc) {
      std::stringstream in(argv[++i]);
      std::string t;
      while (std::getline(in, t, ',')) sizes.push_back(std::atoi(t.c_str()));
    } else if (a == "--scenario" && i + 1 < argc) {
      o.scenario = argv[++i];
    } else if (a == "--integrator" && i + 1 < argc) {
      const std::string v = argv[++i];
      o.integrator = v == "euler"      ? partsim::Integrator::kEuler
                     : v == "rk4"      ? partsim::Integrator::kRK4
                     : v == "implicit" ? partsim::Integrator::kImplicit
                                       : partsim::Integrator::kImplicitFast;
    } else {
      std::fprintf(stderr,
                   "usage: partsim_capacity_bench [--scenario ground|grid|chain] [--sizes A,B] "
                   "[--reps N] [--steps S] [--integrator implicitfast|implicit|euler|rk4]\n");
      return 2;
    }
  }
  if (o.scenario != "ground" && o.scenario != "grid" && o.scenario != "chain") {
    std::fprintf(stderr, "unknown scenario '%s'\n", o.scenario.c_str());
    return 2;
  }
  if (sizes.empty())
    sizes = o.scenario == "chain" ? std::vector<int>{100, 500} : std::vector<int>{300, 1000};
  std::printf("MuJoCo %s, scenario %s, integrator %s, %d steps, %d repetitions, medians\n",
              mj_versionString(), o.scenario.c_str(), MjIntegrator(o.integrator), o.steps, reps);
  std::printf("%6s %10s %10s %10s %10s %9s %9s %8s %8s\n", "N", "build (s)", "raw build", "ms/step",
              "raw ms", "steps/s", "warnings", "build x", "step x");
  for (int n : sizes) {
    std::vector<double> build, step, raw_build, raw_step;
    size_t warnings = 0;
    for (int r = 0; r < reps; ++r) {  // taking turns
      const Result p = RunPartsim(n, o), q = RunRaw(n, o);
      build.push_back(p.build);
      step.push_back(p.per_step);
      raw_build.push_back(q.build);
      raw_step.push_back(q.per_step);
      warnings = std::max(warnings, p.warnings);
    }
    const double b = Median(build), s = Median(step), rb = Median(raw_build), rs = Median(raw_step);
    std::printf("%6d %10.3f %10.3f %10.3f %10.3f %9.0f %9zu %8.2f %8.2f\n", n, b, rb, 1e3 * s,
                1e3 * rs, 1.0 / s, warnings, b / rb, s / rs);
    std::fflush(stdout);
  }
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  std::printf("peak memory of the process: %ld MB\n", u.ru_maxrss / 1024);
  return 0;
}
