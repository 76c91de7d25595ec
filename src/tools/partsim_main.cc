// The `partsim` command-line program: inspect a URDF articulation or a PartNet-Mobility object
// (`info`), simulate it and write its joint trajectory (`simulate`), or render it from a few
// views (`render`). With no file, all use the built-in cabinet of MakeCabinetUrdf(). Exit codes: 0
// success, 1 failure while running (missing or bad file), 2 bad command line.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.h"
#include "partsim/assets/default_objects.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/image_io.h"

namespace {

constexpr char kVersion[] = "0.1.0";

constexpr char kUsage[] = R"(partsim: simulate robots and articulated objects (doors, drawers, ...)

usage:
  partsim info [OBJECT] [--fix-root | --free-root] [--json]
  partsim simulate [OBJECT] --steps N [options]
  partsim render [OBJECT] --out DIR [options]
  partsim assets generate --out DIR [options]   (see partsim assets --help)
  partsim tasks demo|evaluate [options]         (see partsim tasks --help)
  partsim serve [SCENE] [options]               (see partsim serve --help)
  partsim --help | --version

OBJECT is a URDF file or a PartNet-Mobility folder (mobility.urdf with mobility_v2.json,
semantics.txt, meta.json, as `partsim assets generate` writes them); a folder's mobility.urdf
given alone loads as its folder does, with the part labels of semantics.txt.

info       prints the links (name, parent, mass), the joints (name, type, parent -> child,
           limits in rad or m), the total mass and the number of degrees of freedom.
  --json             print the same as JSON
  --fix-root         weld the root link to the world (default)
  --free-root        let the root link move freely (6 more dof, not counted in DOF)

simulate   steps the articulation and writes its joint trajectory: time, then the position
           and the velocity of every joint with a dof.
  --steps N                  number of steps (required with a file; 1000 for the demo)
  --dt SECONDS               timestep (default 0.002)
  --out FILE                 trajectory file; '-' writes it to standard output
  --format csv|json          trajectory format (default: from the --out extension, else csv)
  --drive-stiffness K        PD drive stiffness on every joint (N/m or N m/rad)
  --drive-damping D          PD drive damping on every joint (N s/m or N m s/rad)
  --target Q1,Q2,...         drive targets, one per dof (m or rad; needs --drive-stiffness)
  --gravity X,Y,Z            gravity in m/s^2 (default 0,0,-9.81)
  --fix-root | --free-root   as for info (default --fix-root)

render     places the object on a ground under lights and renders it from N views around it,
           looking at its centre. Writes into DIR, per view K: color_K.png (8-bit sRGB),
           depth_K.png (16-bit, millimetres, 0 = nothing), depth_preview_K.png (8-bit grey
           for viewing: near bright, far dark, nothing black), normal_K.png (camera frame,
           (n + 1) / 2), segmentation_K.png (one colour per actor or link) and cloud_K.ply
           (binary point cloud in the world frame with colours and ids); plus
           segmentation.json (id -> actor / link name, part label, colour) and cameras.json
           (K, extrinsics and pose per view, the object's world bounds).
  --out DIR                      output folder (required; created if missing; the files an
                                 earlier render wrote there are removed first)
  --backend rasterizer|pathtracer   renderer (default rasterizer)
  --views N                      number of views (default 4)
  --width W --height H           image size in pixels (default 640 x 480)
  --spp N                        path tracer samples per pixel (default 64)
  --fix-root | --free-root       as for info (default --fix-root)

With no OBJECT, all commands use the built-in cabinet (a drawer and a door); `simulate` then runs
a demo that drives the drawer and the door open and prints their final positions.
Exit codes: 0 success, 1 runtime failure (missing or invalid file), 2 bad command line.
)";

/// A bad command line: the message names the flag or argument at fault; exit code 2.
class UsageError : public std::runtime_error {
 public:
  explicit UsageError(const std::string& what) : std::runtime_error(what) {}
};

/// Parsed command line.
struct Args {
  std::string command;  // "info", "simulate" or "render"
  std::string file;     // URDF file or PartNet-Mobility folder; "" for the built-in cabinet
  bool fix_root = true;
  bool json = false;
  std::optional<long> steps;
  double dt = 0.002;
  std::string out;
  std::string format;
  std::optional<double> stiffness;
  std::optional<double> damping;
  std::optional<std::vector<double>> target;
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);
  // render
  std::string backend = "rasterizer";
  int views = 4;
  int width = 640;
  int height = 480;
  std::optional<int> spp;
};

// ---------------------------------------------------------------------------------------------
// command line

double ParseNumber(const std::string& flag, const std::string& text) {
  const char* s = text.c_str();
  char* end = nullptr;
  errno = 0;
  double v = std::strtod(s, &end);
  if (text.empty() || end == s || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
    throw UsageError(flag + " expects a number, got '" + text + "'");
  }
  return v;
}

std::vector<double> ParseList(const std::string& flag, const std::string& text) {
  std::vector<double> values;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ',')) values.push_back(ParseNumber(flag, item));
  if (values.empty() || (!text.empty() && text.back() == ',')) {
    throw UsageError(flag + " expects comma-separated numbers, got '" + text + "'");
  }
  return values;
}

Args ParseArgs(const std::vector<std::string>& argv) {
  Args args;
  args.command = argv[0];
  const std::string prefix = "partsim " + args.command + ": ";
  bool simulate = args.command == "simulate";
  bool render = args.command == "render";
  // a positive integer flag value at most `max`
  auto count = [&](const std::string& flag, const std::string& v, int max) {
    char* end = nullptr;
    errno = 0;
    long n = std::strtol(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0' || errno == ERANGE || n < 1 || n > max) {
      throw UsageError(prefix + flag + " expects an integer in [1, " + std::to_string(max) +
                       "], got '" + v + "'");
    }
    return static_cast<int>(n);
  };
  for (size_t i = 1; i < argv.size(); ++i) {
    std::string arg = argv[i];
    // positional: the URDF file or PartNet-Mobility folder
    if (arg.empty() || arg[0] != '-' || arg == "-") {
      if (!args.file.empty()) {
        throw UsageError(prefix + "unexpected extra argument '" + arg + "' (one file at most)");
      }
      args.file = arg;
      continue;
    }
    // flags, as "--flag value" or "--flag=value"
    std::string flag = arg, inline_value;
    bool has_inline = false;
    if (size_t eq = arg.find('='); eq != std::string::npos) {
      flag = arg.substr(0, eq);
      inline_value = arg.substr(eq + 1);
      has_inline = true;
    }
    auto value = [&]() -> std::string {
      if (has_inline) return inline_value;
      if (i + 1 >= argv.size()) throw UsageError(prefix + flag + " needs a value");
      return argv[++i];
    };
    auto no_value = [&]() {
      if (has_inline) throw UsageError(prefix + flag + " takes no value");
    };
    if (flag == "--fix-root") {
      no_value();
      args.fix_root = true;
    } else if (flag == "--free-root") {
      no_value();
      args.fix_root = false;
    } else if (flag == "--json" && !simulate && !render) {
      no_value();
      args.json = true;
    } else if (flag == "--steps" && simulate) {
      std::string v = value();
      char* end = nullptr;
      errno = 0;
      long n = std::strtol(v.c_str(), &end, 10);
      if (v.empty() || *end != '\0' || errno == ERANGE || n < 0) {
        throw UsageError(prefix + "--steps expects a non-negative integer, got '" + v + "'");
      }
      args.steps = n;
    } else if (flag == "--dt" && simulate) {
      args.dt = ParseNumber(prefix + "--dt", value());
      if (args.dt <= 0) throw UsageError(prefix + "--dt must be > 0");
    } else if (flag == "--out" && (simulate || render)) {
      args.out = value();
      if (args.out.empty())
        throw UsageError(prefix + "--out needs a " + (render ? "folder" : "file") + " name");
    } else if (flag == "--backend" && render) {
      // "null" renders nothing; it is left out of the help, for tests
      args.backend = value();
      if (args.backend != "rasterizer" && args.backend != "pathtracer" && args.backend != "null") {
        throw UsageError(prefix + "--backend must be rasterizer or pathtracer, got '" +
                         args.backend + "'" +
                         partsim::tools::DidYouMean(args.backend, {"rasterizer", "pathtracer"}));
      }
    } else if (flag == "--views" && render) {
      args.views = count(flag, value(), 360);
    } else if (flag == "--width" && render) {
      args.width = count(flag, value(), 16384);
    } else if (flag == "--height" && render) {
      args.height = count(flag, value(), 16384);
    } else if (flag == "--spp" && render) {
      args.spp = count(flag, value(), 1 << 20);
    } else if (flag == "--format" && simulate) {
      args.format = value();
      if (args.format != "csv" && args.format != "json") {
        throw UsageError(prefix + "--format must be csv or json, got '" + args.format + "'" +
                         partsim::tools::DidYouMean(args.format, {"csv", "json"}));
      }
    } else if (flag == "--drive-stiffness" && simulate) {
      args.stiffness = ParseNumber(prefix + "--drive-stiffness", value());
      if (*args.stiffness < 0) throw UsageError(prefix + "--drive-stiffness must be >= 0");
    } else if (flag == "--drive-damping" && simulate) {
      args.damping = ParseNumber(prefix + "--drive-damping", value());
      if (*args.damping < 0) throw UsageError(prefix + "--drive-damping must be >= 0");
    } else if (flag == "--target" && simulate) {
      args.target = ParseList(prefix + "--target", value());
    } else if (flag == "--gravity" && simulate) {
      std::vector<double> g = ParseList(prefix + "--gravity", value());
      if (g.size() != 3) {
        throw UsageError(prefix + "--gravity expects 3 numbers X,Y,Z, got " +
                         std::to_string(g.size()));
      }
      args.gravity = Eigen::Vector3d(g[0], g[1], g[2]);
    } else {
      std::vector<std::string> flags = {"--fix-root", "--free-root"};
      if (simulate) {
        flags.insert(flags.end(), {"--steps", "--dt", "--out", "--format", "--drive-stiffness",
                                   "--drive-damping", "--target", "--gravity"});
      } else if (render) {
        flags.insert(flags.end(),
                     {"--out", "--backend", "--views", "--width", "--height", "--spp"});
      } else {
        flags.push_back("--json");
      }
      throw UsageError(prefix + "unknown option '" + arg + "'" +
                       partsim::tools::DidYouMean(flag, flags) + " (see partsim --help)");
    }
  }
  if (simulate && !args.file.empty() && !args.steps) {
    throw UsageError(prefix + "--steps N is required when simulating a file");
  }
  if (render && args.out.empty()) throw UsageError(prefix + "--out DIR is required");
  if (render && args.spp && args.backend != "pathtracer") {
    throw UsageError(prefix + "--spp applies to --backend pathtracer only");
  }
  if (simulate && args.target && !args.stiffness) {
    throw UsageError(prefix +
                     "--target needs --drive-stiffness (a drive without stiffness "
                     "does not track positions)");
  }
  return args;
}

// ---------------------------------------------------------------------------------------------
// loading

/// A scene holding the one articulation that the command works on.
struct Loaded {
  std::unique_ptr<partsim::Scene> scene;
  partsim::Articulation art;
  std::string source;  // file name, or "built-in cabinet"
};

// The built-in cabinet's part labels, in the PartNet-Mobility vocabulary of semantics.txt that
// generated objects and the tasks use.
void LabelCabinetParts(partsim::ArticulationDesc* desc) {
  for (partsim::LinkDesc& link : desc->links) {
    if (link.name == "body")
      link.semantic_label = "furniture_body";
    else if (link.name.rfind("drawer_", 0) == 0)
      link.semantic_label = "drawer";
    else if (link.name.rfind("door_", 0) == 0)
      link.semantic_label = "rotation_door";
  }
}

// The PartNet-Mobility folder that `file` names: the folder itself, or the folder of a
// mobility.urdf that has the dataset's annotation files beside it; "" for any other file.
std::string PartNetFolder(const std::string& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path path(file);
  if (fs::is_directory(path, ec)) return file;
  if (path.filename() != "mobility.urdf") return "";
  const fs::path folder = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  for (const char* annotation : {"mobility_v2.json", "semantics.txt", "meta.json"})
    if (fs::is_regular_file(folder / annotation, ec)) return folder.string();
  return "";
}

Loaded Load(const Args& args, const partsim::SceneConfig& config) {
  Loaded out;
  out.scene = std::make_unique<partsim::Scene>(config);
  partsim::UrdfLoader loader = out.scene->CreateUrdfLoader();
  loader.fix_root_link = args.fix_root;
  if (args.file.empty()) {
    std::cerr << "partsim: no file given, using the built-in cabinet (a drawer and a door)\n";
    partsim::ArticulationDesc desc = loader.Parse(partsim::MakeCabinetUrdf(), ".");
    LabelCabinetParts(&desc);
    out.art = out.scene->AddArticulation(desc);
    out.source = "built-in cabinet";
    return out;
  }
  // a PartNet-Mobility object loads through the dataset's loader, whichever of the folder
  // and its mobility.urdf is named: same articulation, with the labels of semantics.txt
  if (const std::string folder = PartNetFolder(args.file); !folder.empty()) {
    if (folder != args.file) {
      std::cerr << "partsim: " << args.file << " belongs to a PartNet-Mobility folder; loading "
                << folder << " (part labels from semantics.txt)\n";
    }
    partsim::PartNetMobilityLoader partnet(out.scene.get());
    partnet.urdf = loader;
    out.art = partnet.Load(folder);
    out.source = args.file;
    return out;
  }
  // a missing file is reported with the system's reason
  std::ifstream probe(args.file);
  if (!probe) {
    throw std::runtime_error("cannot open '" + args.file + "': " + std::strerror(errno));
  }
  out.art = loader.Load(args.file);
  out.source = args.file;
  return out;
}

std::string LimitText(double v) {
  if (std::isinf(v)) return v < 0 ? "-inf" : "inf";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

nlohmann::ordered_json LimitJson(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nullptr;
}

const char* Unit(partsim::JointType t) {
  return t == partsim::JointType::kPrismatic ? "m" : t == partsim::JointType::kFixed ? "" : "rad";
}

// ---------------------------------------------------------------------------------------------
// info

int RunInfo(const Args& args) {
  Loaded l = Load(args, partsim::SceneConfig());
  const partsim::ArticulationDesc& desc = l.art.GetDesc();
  std::vector<partsim::Link> links = l.art.GetLinks();
  double total = 0.0;
  for (const partsim::Link& link : links) total += link.GetMass();

  if (args.json) {
    nlohmann::ordered_json j;
    j["source"] = l.source;
    j["name"] = desc.name;
    j["fix_root"] = args.fix_root;
    j["links"] = nlohmann::ordered_json::array();
    for (const partsim::Link& link : links) {
      int p = link.GetParentIndex();
      j["links"].push_back({{"name", link.GetName()},
                            {"parent", p < 0 ? nlohmann::ordered_json(nullptr)
                                             : nlohmann::ordered_json(links[p].GetName())},
                            {"mass", link.GetMass()}});
    }
    j["joints"] = nlohmann::ordered_json::array();
    for (const partsim::Joint& joint : l.art.GetJoints()) {
      Eigen::Vector2d lim = joint.GetLimits();
      j["joints"].push_back({{"name", joint.GetName()},
                             {"type", partsim::JointTypeName(joint.GetType())},
                             {"parent", joint.GetParentLink().GetName()},
                             {"child", joint.GetChildLink().GetName()},
                             {"dof", joint.GetDof()},
                             {"lower", LimitJson(lim[0])},
                             {"upper", LimitJson(lim[1])},
                             {"unit", Unit(joint.GetType())}});
    }
    j["total_mass"] = total;
    j["dof"] = l.art.Dof();
    std::cout << j.dump(2) << "\n";
    return 0;
  }

  std::printf("articulation '%s' from %s (%s root)\n", desc.name.c_str(), l.source.c_str(),
              args.fix_root ? "fixed" : "free");
  std::printf("\nlinks (%zu):\n", links.size());
  std::printf("  %-24s %-24s %12s\n", "name", "parent", "mass [kg]");
  for (const partsim::Link& link : links) {
    int p = link.GetParentIndex();
    std::printf(
        "  %-24s %-24s %12.4f\n", link.GetName().c_str(),
        p < 0 ? (args.fix_root ? "(world, fixed)" : "(world, free)") : links[p].GetName().c_str(),
        link.GetMass());
  }
  std::vector<partsim::Joint> joints = l.art.GetJoints();
  std::printf("\njoints (%zu):\n", joints.size());
  std::printf("  %-24s %-11s %-40s %s\n", "name", "type", "parent -> child", "limits");
  for (const partsim::Joint& joint : joints) {
    std::string link_pair =
        joint.GetParentLink().GetName() + " -> " + joint.GetChildLink().GetName();
    std::string limits = "-";
    if (joint.GetDof() > 0 || joint.GetType() != partsim::JointType::kFixed) {
      Eigen::Vector2d lim = joint.GetLimits();
      limits = "[" + LimitText(lim[0]) + ", " + LimitText(lim[1]) + "] " + Unit(joint.GetType());
    }
    std::printf("  %-24s %-11s %-40s %s\n", joint.GetName().c_str(),
                partsim::JointTypeName(joint.GetType()), link_pair.c_str(), limits.c_str());
  }
  std::printf("\ntotal mass: %.4f kg\n", total);
  std::printf("DOF: %d%s\n", l.art.Dof(), args.fix_root ? "" : " (+6 of the free root)");
  return 0;
}

// ---------------------------------------------------------------------------------------------
// simulate

/// Joint trajectory: one row per recorded instant.
struct Trajectory {
  std::vector<std::string> joints;
  std::vector<double> time;
  std::vector<Eigen::VectorXd> qpos, qvel;
  void Record(double t, const partsim::Articulation& art) {
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

int RunSimulate(const Args& args) {
  partsim::SceneConfig config;
  config.timestep = args.dt;
  config.gravity = args.gravity;
  Loaded l = Load(args, config);
  partsim::Articulation& art = l.art;
  const bool demo = args.file.empty();
  const long steps = args.steps.value_or(1000);
  std::vector<partsim::Joint> active = art.GetActiveJoints();
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
  for (const partsim::Joint& j : active) tr.joints.push_back(j.GetName());
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
      WriteJson(out, tr, args.dt);
    else
      WriteCsv(out, tr);
    if (!to_stdout && !file) throw std::runtime_error("error while writing '" + args.out + "'");
  }

  // summary (on stderr when the trajectory went to stdout)
  FILE* s = to_stdout ? stderr : stdout;
  std::fprintf(s, "simulated %ld steps of %g s (%.4g s) in %.3f s: %.0f steps/s\n", steps, args.dt,
               steps * args.dt, wall, wall > 0 ? steps / wall : 0.0);
  if (record && !to_stdout) {
    std::fprintf(s, "trajectory: %zu rows written to %s\n", tr.time.size(), args.out.c_str());
  }
  for (const partsim::Warning& w : l.scene->GetWarnings()) {
    std::fprintf(stderr, "warning at t = %g s: %s\n", w.time, w.message.c_str());
  }
  Eigen::VectorXd q = art.GetQpos();
  std::fprintf(s, "final qpos:\n");
  for (int k = 0; k < dof; ++k) {
    std::fprintf(s, "  %-24s %10.4f %s\n", active[k].GetName().c_str(), q[k],
                 Unit(active[k].GetType()));
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// render

/// World bounding box of the visuals of entities in `ids` (from the render world); false when
/// they have none.
bool VisualBounds(const partsim::RenderWorld& world, const std::vector<uint32_t>& ids,
                  Eigen::Vector3d* lo, Eigen::Vector3d* hi) {
  bool any = false;
  for (const partsim::RenderInstance& inst : world.instances) {
    if (std::find(ids.begin(), ids.end(), inst.entity_id) == ids.end() || !inst.mesh) continue;
    for (const Eigen::Vector3f& v : inst.mesh->vertices) {
      Eigen::Vector3d p = (inst.X_WV * v.cast<double>().homogeneous()).head<3>();
      *lo = any ? lo->cwiseMin(p) : p;
      *hi = any ? hi->cwiseMax(p) : p;
      any = true;
    }
  }
  return any;
}

std::string ViewFile(const std::filesystem::path& dir, const char* stem, int k, const char* ext) {
  return (dir / (std::string(stem) + "_" + std::to_string(k) + ext)).string();
}

/// Writes `depth` (width x height, metres along the view axis, 0 where nothing is seen) as an
/// 8-bit grey PNG for viewing: linear from 255 at the nearest surface seen to 48 at the farthest,
/// and 0 where nothing is seen. (The metric 16-bit depth PNG holds millimetres, a few thousand of
/// 65535, which viewers show black.)
void WriteDepthPreviewPng(const std::string& path, int width, int height,
                          const std::vector<float>& depth) {
  constexpr float kNear = 255.0f, kFar = 48.0f;
  float lo = std::numeric_limits<float>::infinity(), hi = 0.0f;
  for (float d : depth) {
    if (d > 0) {
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  std::vector<uint8_t> grey(depth.size(), 0);
  for (size_t i = 0; i < depth.size(); ++i) {
    if (!(depth[i] > 0)) continue;
    const float t = hi > lo ? (depth[i] - lo) / (hi - lo) : 0.0f;
    grey[i] = static_cast<uint8_t>(std::lround(kNear + t * (kFar - kNear)));
  }
  partsim::WritePng(path, width, height, 1, grey.data());
}

void WriteJsonFile(const std::filesystem::path& path, const nlohmann::ordered_json& j) {
  std::ofstream out(path);
  out << j.dump(2) << "\n";
  if (!out) throw std::runtime_error("cannot write '" + path.string() + "'");
}

int RunRender(const Args& args) {
  Loaded l = Load(args, partsim::SceneConfig());
  partsim::Scene& scene = *l.scene;
  std::filesystem::path dir(args.out);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw std::runtime_error("cannot create the output folder '" + args.out +
                             "': " + (ec ? ec.message() : "not a folder"));
  }
  // what an earlier render wrote here goes first, so that no stale view is left beside this
  // run's (other files in the folder stay)
  partsim::tools::ClearOwnedOutputs(args.out, {{"color_", ".png"},
                                               {"depth_", ".png"},
                                               {"depth_preview_", ".png"},
                                               {"normal_", ".png"},
                                               {"segmentation_", ".png"},
                                               {"cloud_", ".ply"},
                                               {"segmentation", ".json"},
                                               {"cameras", ".json"}});

  // the backend first: a renderer that cannot start fails before any work
  if (args.backend == "pathtracer") {
    partsim::PathTracerOptions options;
    options.samples_per_pixel = args.spp.value_or(64);
    scene.SetRenderBackend(partsim::MakePathTracerBackend(options));
  } else {
    scene.SetRenderBackend(args.backend);
  }
  partsim::RenderBackend& backend = scene.GetRenderBackend();

  // the object's extent, from its visuals (else from its link origins)
  std::vector<uint32_t> ids;
  for (const partsim::RenderEntityInfo& e : scene.GetRenderEntities())
    if (e.articulation_id == l.art.GetId()) ids.push_back(e.id);
  scene.UpdateRender();
  Eigen::Vector3d lo, hi;
  if (!VisualBounds(scene.GetRenderWorld(), ids, &lo, &hi)) {
    std::cerr << "partsim render: the object has no visuals; framing its link origins\n";
    lo = hi = l.art.GetLink(0).GetPose().p;
    for (const partsim::Link& link : l.art.GetLinks()) {
      lo = lo.cwiseMin(link.GetPose().p);
      hi = hi.cwiseMax(link.GetPose().p);
    }
    lo -= Eigen::Vector3d::Constant(0.25);
    hi += Eigen::Vector3d::Constant(0.25);
  }
  Eigen::Vector3d centre = 0.5 * (lo + hi);
  double radius = std::max(0.5 * (hi - lo).norm(), 1e-3);

  // ground under the object, a key light with shadows, a fill light and some ambient
  scene.AddGround(lo.z());
  scene.AddDirectionalLight(Eigen::Vector3d(-0.4, 0.3, -1.0), Eigen::Vector3f(2.5f, 2.4f, 2.3f),
                            true);
  scene.AddDirectionalLight(Eigen::Vector3d(0.5, -0.6, -0.4), Eigen::Vector3f(0.6f, 0.6f, 0.7f));
  scene.SetAmbientLight(Eigen::Vector3f(0.25f, 0.25f, 0.25f));

  // cameras on a circle around the centre, 25 degrees above it, the whole object in view
  const double fovy = 0.8;
  const double pi = 3.14159265358979323846;
  std::vector<partsim::Camera> cameras;
  for (int k = 0; k < args.views; ++k) {
    partsim::Camera cam =
        scene.AddCamera("view_" + std::to_string(k), args.width, args.height, fovy, 0.01, 100.0);
    double half_fov = 0.5 * std::min(cam.GetFovx(), cam.GetFovy());
    double distance = 1.1 * radius / std::sin(half_fov);
    double azimuth = pi / 6 + 2 * pi * k / args.views, elevation = 25 * pi / 180;
    Eigen::Vector3d dir(std::cos(azimuth) * std::cos(elevation),
                        std::sin(azimuth) * std::cos(elevation), std::sin(elevation));
    cam.SetLocalPose(partsim::CameraLookAt(centre + distance * dir, centre));
    cameras.push_back(cam);
  }
  scene.UpdateRender();
  std::printf("rendering %s: %d views of %d x %d with %s on %s\n", l.source.c_str(), args.views,
              args.width, args.height, backend.Name().c_str(), backend.Device().c_str());

  // pictures and their files
  nlohmann::ordered_json views = nlohmann::ordered_json::array();
  for (int k = 0; k < args.views; ++k) {
    partsim::Camera& cam = cameras[k];
    auto start = std::chrono::steady_clock::now();
    cam.TakePicture();
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const partsim::Picture& picture = cam.GetPictureData();
    partsim::WriteColorPng(ViewFile(dir, "color", k, ".png"), picture);
    partsim::WriteDepthPng(ViewFile(dir, "depth", k, ".png"), picture);
    WriteDepthPreviewPng(ViewFile(dir, "depth_preview", k, ".png"), args.width, args.height,
                         partsim::DepthImage(picture));
    partsim::WriteNormalPng(ViewFile(dir, "normal", k, ".png"), picture);
    partsim::WriteSegmentationPng(ViewFile(dir, "segmentation", k, ".png"), picture, 1);
    partsim::PointCloud cloud = partsim::MakePointCloud(cam, partsim::PointCloudFrame::kWorld);
    partsim::WritePly(ViewFile(dir, "cloud", k, ".ply"), cloud, true);
    std::printf("view %d: %zu points, %.3f s\n", k, cloud.Size(), seconds);

    nlohmann::ordered_json v;
    v["index"] = k;
    v["width"] = args.width;
    v["height"] = args.height;
    Eigen::Matrix3d K = cam.GetIntrinsicMatrix();
    Eigen::Matrix<double, 3, 4> Rt = cam.GetExtrinsicMatrix();
    v["K"] = {
        {K(0, 0), K(0, 1), K(0, 2)}, {K(1, 0), K(1, 1), K(1, 2)}, {K(2, 0), K(2, 1), K(2, 2)}};
    v["extrinsic"] = nlohmann::ordered_json::array();
    for (int r = 0; r < 3; ++r) v["extrinsic"].push_back({Rt(r, 0), Rt(r, 1), Rt(r, 2), Rt(r, 3)});
    partsim::Pose X_WC = cam.GetPose();
    v["pose"] = {{"p", {X_WC.p.x(), X_WC.p.y(), X_WC.p.z()}},
                 {"q", {X_WC.q.w(), X_WC.q.x(), X_WC.q.y(), X_WC.q.z()}}};
    v["points"] = cloud.Size();
    views.push_back(v);
  }

  // what the ids and colours of segmentation images name
  nlohmann::ordered_json legend;
  legend["source"] = l.source;
  legend["channel"] = "segmentation_K.png colours actors and links (entity ids)";
  legend["entities"] = nlohmann::ordered_json::array();
  for (const partsim::RenderEntityInfo& e : scene.GetRenderEntities()) {
    std::array<uint8_t, 3> c = partsim::SegmentationColor(e.id);
    nlohmann::ordered_json j;
    j["id"] = e.id;
    j["kind"] = e.is_link ? "link" : "actor";
    j["name"] = e.name;
    if (e.is_link) j["articulation"] = e.articulation_name;
    j["semantic_label"] = e.semantic_label;
    j["color"] = {c[0], c[1], c[2]};
    legend["entities"].push_back(j);
  }
  legend["visuals"] = nlohmann::ordered_json::array();
  for (const partsim::RenderVisualInfo& v : scene.GetRenderVisuals())
    legend["visuals"].push_back({{"id", v.id}, {"entity_id", v.entity_id}, {"name", v.name}});
  WriteJsonFile(dir / "segmentation.json", legend);
  nlohmann::ordered_json cams;
  cams["backend"] = backend.Name();
  cams["device"] = backend.Device();
  cams["convention"] =
      "K and extrinsic [R|t] in OpenCV's camera frame (x right, y down, z forward); pose X_WC "
      "with x forward, y left, z up; quaternion w, x, y, z";
  cams["views"] = views;
  cams["object_bounds"] = {{"min", {lo.x(), lo.y(), lo.z()}},
                           {"max", {hi.x(), hi.y(), hi.z()}},
                           {"note",
                            "world frame, m: box of the object's visuals (of its link origins, "
                            "0.25 m wider, when it has none)"}};
  WriteJsonFile(dir / "cameras.json", cams);
  std::printf("wrote %d views to %s\n", args.views, args.out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::fprintf(stderr, "%s", kUsage);
    return 2;
  }
  const std::string& command = args[0];
  if (command == "--help" || command == "-h" || command == "help") {
    std::printf("%s", kUsage);
    return 0;
  }
  if (command == "--version") {
    int v = mj_version();
    std::printf("partsim %s (MuJoCo %d.%d.%d)\n", kVersion, v / 100, (v / 10) % 10, v % 10);
    return 0;
  }
  if (command == "assets") return partsim::tools::RunAssetsCommand(argc - 2, argv + 2);
  if (command == "tasks") return partsim::tools::RunTasksCommand(argc - 2, argv + 2);
  if (command == "serve") return partsim::tools::RunServeCommand(argc - 2, argv + 2);
  if (command != "info" && command != "simulate" && command != "render") {
    const std::string hint = partsim::tools::DidYouMean(
        command, {"info", "simulate", "render", "assets", "tasks", "serve", "--help", "--version"});
    std::fprintf(stderr,
                 "partsim: unknown %s '%s'%s (expected info, simulate, render, assets, tasks or "
                 "serve; see partsim --help)\n",
                 command[0] == '-' ? "option" : "command", command.c_str(), hint.c_str());
    return 2;
  }
  try {
    for (const std::string& a : args) {
      if (a == "--help" || a == "-h") {
        std::printf("%s", kUsage);
        return 0;
      }
    }
    Args parsed = ParseArgs(args);
    if (parsed.command == "info") return RunInfo(parsed);
    if (parsed.command == "simulate") return RunSimulate(parsed);
    return RunRender(parsed);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partsim %s: %s\n", command.c_str(), e.what());
    return 1;
  }
}
