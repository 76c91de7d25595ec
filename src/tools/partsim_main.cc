// The `partsim` program: dispatches to its commands (info, simulate, render, assets, tasks,
// serve, view, annotate, vision, learn; one file each), and prints the help and the version. With
// no file, info, simulate and render use the built-in cabinet of MakeCabinetUrdf(). Exit codes: 0
// success, 1 failure while running (missing or bad file), 2 bad command line.
#include <mujoco/mujoco.h>

#include <cstdio>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "partsim/core/version.h"

namespace {

constexpr char kUsage[] = R"(partsim: simulate robots and articulated objects (doors, drawers, ...)

usage:
  partsim info [OBJECT] [--fix-root | --free-root] [--json]
  partsim simulate [OBJECT] --steps N [options]
  partsim render [OBJECT] --out DIR [options]
  partsim assets generate --out DIR [options]   (see partsim assets --help)
  partsim tasks demo|evaluate [options]         (see partsim tasks --help)
  partsim serve [SCENE] [options]               (see partsim serve --help)
  partsim view [OBJECT | SCENE] [options]       (see partsim view --help)
  partsim annotate INPUT --out DIR [options]    (see partsim annotate --help)
  partsim vision detection-dataset|motion-dataset|evaluate-detection|evaluate-motion|show
                 [options]                      (see partsim vision --help)
  partsim learn train|evaluate|sweep|table|curves [options]
                                                (see partsim learn --help)
  partsim --help | --version

assets generate, assets check, vision detection-dataset and motion-dataset, tasks evaluate and
learn evaluate take --shard i/N (one part of the list; merged, one run's bytes), and --ray
auto|ADDRESS to run their parts as tasks on a Ray cluster (docs/distributed.md; `partsim
assets generate --ray --help` for the options).

OBJECT is a URDF file or a PartNet-Mobility folder (mobility.urdf with mobility_v2.json,
semantics.txt, meta.json, as `partsim assets generate` writes them); a folder's mobility.urdf
given alone loads as its folder does, with the part labels of semantics.txt. An MJCF file
(a .xml whose root is <mujoco>) loads whole, with its own options: info describes it,
simulate records its tree of most dof, render draws all its bodies.

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
    std::printf("partsim %s (MuJoCo %s)\n", partsim::Version(), mj_versionString());
    return 0;
  }
  // any list-shaped command given --ray runs through partsim.distributed, which submits its
  // shards as Ray tasks (each one this program without --ray) and merges them
  for (const std::string& a : args)
    if (a == "--ray" || a.rfind("--ray=", 0) == 0)
      return partsim::tools::RunPythonModule("partsim.distributed", "--ray (Ray)", argc - 1,
                                             argv + 1);
  if (command == "assets") return partsim::tools::RunAssetsCommand(argc - 2, argv + 2);
  if (command == "tasks") return partsim::tools::RunTasksCommand(argc - 2, argv + 2);
  if (command == "serve") return partsim::tools::RunServeCommand(argc - 2, argv + 2);
  if (command == "view") return partsim::tools::RunViewCommand(argc - 2, argv + 2);
  if (command == "annotate") return partsim::tools::RunAnnotateCommand(argc - 2, argv + 2);
  if (command == "vision") return partsim::tools::RunVisionCommand(argc - 2, argv + 2);
  if (command == "learn") return partsim::tools::RunLearnCommand(argc - 2, argv + 2);
  if (command != "info" && command != "simulate" && command != "render") {
    const std::string hint = partsim::tools::DidYouMean(
        command, {"info", "simulate", "render", "assets", "tasks", "serve", "view", "annotate",
                  "vision", "learn", "--help", "--version"});
    std::fprintf(stderr,
                 "partsim: unknown %s '%s'%s (expected info, simulate, render, assets, tasks, "
                 "serve, view, annotate, vision or learn; see partsim --help)\n",
                 command[0] == '-' ? "option" : "command", command.c_str(), hint.c_str());
    return 2;
  }
  // info, simulate and render share this program's help
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (partsim::tools::ArgParser::AsksForHelp(rest)) {
    std::printf("%s", kUsage);
    return 0;
  }
  if (command == "info") return partsim::tools::RunInfoCommand(rest);
  if (command == "simulate") return partsim::tools::RunSimulateCommand(rest);
  return partsim::tools::RunRenderCommand(rest);
}
