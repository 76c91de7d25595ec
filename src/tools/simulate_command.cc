// `partsim simulate [OBJECT]`: steps an object and writes its joint trajectory (time, then the
// position and the velocity of every joint with a dof) as CSV or JSON. With no OBJECT, a demo
// drives the built-in cabinet's drawer and door open.
#include <Eigen/Core>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "object_loader.h"

namespace partsim::tools {

namespace {

struct SimulateArgs {
  ObjectArgs object;
  std::optional<long> steps;
  double dt = 0.002;
  std::string out;
  std::string format;  // "csv", "json", or "" for the --out extension's
  std::optional<double> stiffness;
  std::optional<double> damping;
  std::optional<std::vector<double>> target;
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);
};

SimulateArgs Parse(const std::vector<std::string>& args) {
  SimulateArgs a;
  ArgParser p("partsim simulate", "partsim --help");
  AddObjectArgs(&p, &a.object);
  p.Option("--steps", [&](const FlagValue& v) {
    a.steps = static_cast<long>(v.Integer(0, std::numeric_limits<long>::max()));
  });
  p.Option("--dt", [&](const FlagValue& v) { a.dt = v.Number(0, false, kInf); });
  p.Option("--out", [&](const FlagValue& v) { a.out = v.NonEmpty("a file name"); });
  p.Option("--format", [&](const FlagValue& v) { a.format = v.Choice({"csv", "json"}); });
  p.Option("--drive-stiffness", [&](const FlagValue& v) { a.stiffness = v.Number(0, true, kInf); });
  p.Option("--drive-damping", [&](const FlagValue& v) { a.damping = v.Number(0, true, kInf); });
  p.Option("--target", [&](const FlagValue& v) { a.target = v.Numbers(); });
  p.Option("--gravity", [&](const FlagValue& v) {
    std::vector<double> g = v.Numbers();
    if (g.size() != 3) v.Fail("--gravity expects 3 numbers X,Y,Z, got " + std::to_string(g.size()));
    a.gravity = Eigen::Vector3d(g[0], g[1], g[2]);
  });
  p.Parse(args);
  if (!a.object.file.empty() && !a.steps) p.Fail("--steps N is required when simulating a file");
  if (a.target && !a.stiffness)
    p.Fail("--target needs --drive-stiffness (a drive without stiffness does not track positions)");
  return a;
}

/// Joint trajectory: one row per recorded instant.
struct Trajectory {
  std::vector<std::string> joints;
  std::vector<double> time;
  std::vector<Eigen::VectorXd> qpos, qvel;
  void Record(double t, const Articulation& art) {
    time.push_back(t);
    qpos.push_back(art.GetQpos());
    qvel.push_back(art.GetQvel());
  }
};

void WriteCsv(std::ostream& out, const Trajectory& tr) {
  out << "time";
  for (const std::string& j : tr.joints) out << ",qpos:" << j;
  for (const std::string& j : tr.joints) out << ",qvel:" << j;
  out << "\n";
  char buf[32];
  for (size_t r = 0; r < tr.time.size(); ++r) {
    std::snprintf(buf, sizeof(buf), "%.9g", tr.time[r]);
    out << buf;
    for (const Eigen::VectorXd* v : {&tr.qpos[r], &tr.qvel[r]}) {
      for (int k = 0; k < v->size(); ++k) {
        std::snprintf(buf, sizeof(buf), ",%.9g", (*v)[k]);
        out << buf;
      }
    }
    out << "\n";
  }
}

void WriteJson(std::ostream& out, const Trajectory& tr, double dt) {
  nlohmann::ordered_json j;
  j["joints"] = tr.joints;
  j["dt"] = dt;
  j["time"] = tr.time;
  j["qpos"] = nlohmann::ordered_json::array();
  j["qvel"] = nlohmann::ordered_json::array();
  for (size_t r = 0; r < tr.time.size(); ++r) {
    j["qpos"].push_back(
        std::vector<double>(tr.qpos[r].data(), tr.qpos[r].data() + tr.qpos[r].size()));
    j["qvel"].push_back(
        std::vector<double>(tr.qvel[r].data(), tr.qvel[r].data() + tr.qvel[r].size()));
  }
  out << j.dump() << "\n";
}

int Simulate(const SimulateArgs& args) {
  SceneConfig config;
  config.timestep = args.dt;
  config.gravity = args.gravity;
  LoadedObject l = LoadObject(args.object, config);
  if (!l.art.GetScene())
    throw std::runtime_error(l.source + ": the MJCF model has no kinematic tree to record (" +
                             std::to_string(l.mjcf->GetActors().size()) +
                             " actors); partsim view shows it");
  Articulation& art = l.art;
  const double dt = l.scene->GetTimestep();  // an MJCF file's own
  const bool demo = args.object.file.empty();
  const long steps = args.steps.value_or(1000);
  std::vector<Joint> active = art.GetActiveJoints();
  const int dof = art.Dof();

  // drives: the user's, else the demo's (drawer and door driven open)
  if (args.stiffness || args.damping) {
    art.SetDriveProperty(args.stiffness.value_or(0.0), args.damping.value_or(0.0));
  } else if (demo) {
    art.FindJointByName("drawer_0_joint").SetDriveProperty(200.0, 80.0);
    art.FindJointByName("door_0_joint").SetDriveProperty(20.0, 8.0);
  }
  if (args.target) {
    if (static_cast<int>(args.target->size()) != dof) {
      throw UsageError("partsim simulate: --target has " + std::to_string(args.target->size()) +
                       " values but the articulation has " + std::to_string(dof) + " dof");
    }
    art.SetDriveTarget(Eigen::Map<const Eigen::VectorXd>(args.target->data(), dof));
  } else if (demo) {
    art.FindJointByName("drawer_0_joint").SetDriveTarget(0.3);
    art.FindJointByName("door_0_joint").SetDriveTarget(1.2);
  }

  // step and record
  Trajectory tr;
  for (const Joint& j : active) tr.joints.push_back(j.GetName());
  const bool record = !args.out.empty();
  if (record) tr.Record(l.scene->GetTime(), art);
  auto start = std::chrono::steady_clock::now();
  for (long k = 0; k < steps; ++k) {
    l.scene->Step();
    if (record) tr.Record(l.scene->GetTime(), art);
  }
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // trajectory output
  bool to_stdout = args.out == "-";
  if (record) {
    std::string format = args.format;
    if (format.empty()) {
      bool json_ext =
          args.out.size() >= 5 && args.out.compare(args.out.size() - 5, 5, ".json") == 0;
      format = json_ext ? "json" : "csv";
    }
    std::ofstream file;
    if (!to_stdout) {
      file.open(args.out);
      if (!file) {
        throw std::runtime_error("cannot write '" + args.out + "': " + std::strerror(errno));
      }
    }
    std::ostream& out = to_stdout ? std::cout : file;
    if (format == "json")
      WriteJson(out, tr, dt);
    else
      WriteCsv(out, tr);
    if (!to_stdout && !file) throw std::runtime_error("error while writing '" + args.out + "'");
  }

  // summary (on stderr when the trajectory went to stdout)
  FILE* s = to_stdout ? stderr : stdout;
  std::fprintf(s, "simulated %ld steps of %g s (%.4g s) in %.3f s: %.0f steps/s\n", steps, dt,
               steps * dt, wall, wall > 0 ? steps / wall : 0.0);
  if (record && !to_stdout) {
    std::fprintf(s, "trajectory: %zu rows written to %s\n", tr.time.size(), args.out.c_str());
  }
  for (const Warning& w : l.scene->GetWarnings()) {
    std::fprintf(stderr, "warning at t = %g s: %s\n", w.time, w.message.c_str());
  }
  Eigen::VectorXd q = art.GetQpos();
  std::fprintf(s, "final qpos:\n");
  for (int k = 0; k < dof; ++k) {
    std::fprintf(s, "  %-24s %10.4f %s\n", active[k].GetName().c_str(), q[k],
                 JointUnit(active[k].GetType()));
  }
  return 0;
}

}  // namespace

int RunSimulateCommand(const std::vector<std::string>& args) {
  return RunWithExitCode("partsim simulate", "", [&] { return Simulate(Parse(args)); });
}

}  // namespace partsim::tools
