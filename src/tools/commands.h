// The sub-commands of the `partsim` program, one file each, and what several of them share.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "partsim/core/pose.h"

namespace partsim {
class Scene;
}

namespace partsim::tools {

/// `partsim info ...`: the links, joints, mass and dof of an object (`args`: the arguments
/// after "info"). Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunInfoCommand(const std::vector<std::string>& args);

/// `partsim simulate ...`: steps an object and writes its joint trajectory (arguments after
/// "simulate"). Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunSimulateCommand(const std::vector<std::string>& args);

/// `partsim render ...`: images, depth, normals, segmentation and point clouds of an object from
/// views around it (arguments after "render"). Returns the exit code (0 success, 1 failure, 2 bad
/// command line).
int RunRenderCommand(const std::vector<std::string>& args);

/// `partsim assets ...`: generate procedural PartNet-Mobility objects. `argv` holds the
/// arguments after "assets". Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunAssetsCommand(int argc, char** argv);

/// `partsim tasks ...`: the drawer and door tasks with the heuristic solvers (arguments after
/// "tasks"). Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunTasksCommand(int argc, char** argv);

/// `partsim serve ...`: a scene stepped in real time behind a rosbridge v2 WebSocket server
/// (arguments after "serve"). Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunServeCommand(int argc, char** argv);

/// `partsim view ...`: the browser viewer of an asset, simulated in real time (arguments after
/// "view"). Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunViewCommand(int argc, char** argv);

/// `partsim annotate ...`: the mobility annotation tool in the browser (arguments after
/// "annotate"). Returns the exit code (0 success, 1 failure, 2 bad command line).
int RunAnnotateCommand(int argc, char** argv);

/// What `partsim serve` and `partsim view` simulate: `scene_file` (a URDF file or a
/// PartNet-Mobility folder placed at `where` with its root fixed, or a scene file's objects at
/// their poses), or the built-in cabinet at `where` when it is "". Throws partsim::Error naming
/// the file at fault.
void AddServedObjects(Scene* scene, const std::string& scene_file, const Pose& where);

/// `partsim vision ...`: the perception benchmark's tools (evaluate-detection,
/// evaluate-motion); `argv` holds the arguments after "vision". Returns the exit code (0
/// success, 1 failure, 2 bad command line).
int RunVisionCommand(int argc, char** argv);

/// `partsim learn ...`: SAC on the door and drawer tasks (train, evaluate, table, curves). Runs
/// `python3 -m partsim.learn` with the arguments after "learn"; returns only when that cannot
/// start (exit code 1).
int RunLearnCommand(int argc, char** argv);
/// Runs `python3 -m MODULE ARGS...` with the partsim package that goes with this program (an
/// exec: returns 1 only when the interpreter cannot start; `what` names the command then).
int RunPythonModule(const char* module, const char* what, int argc, char** argv);

/// Removes the files of `dir` that an earlier run of the same command wrote: names starting with
/// one of `prefixes` and ending with the matching entry of `suffixes` ("color_" + ".png"), so
/// that a run with fewer views or frames leaves no stale ones beside its own. Other files stay.
/// Returns how many were removed.
int ClearOwnedOutputs(const std::string& dir,
                      const std::vector<std::pair<std::string, std::string>>& names);

}  // namespace partsim::tools

namespace partsim {

/// `partsim assets check DIR ...` (arguments after "check"); returns the exit code.
int RunQualityCommand(int argc, char** argv);

/// `partsim assets decompose MESH --out DIR [--concavity C] [--max-pieces N] [--min-pieces N]
/// [--max-hull-vertices N] [--name BASENAME]`: decomposes MESH, prints the piece count, coverage,
/// max surface distance, excess and time, and writes the pieces (WriteConvexPieces; basename:
/// the mesh's file stem). As in main(), `argv[0]` is the command's name ("decompose") and the
/// arguments follow. Returns 0 on success, 2 on bad arguments, 1 on failure (message on stderr).
int RunDecomposeCommand(int argc, char** argv);

}  // namespace partsim
