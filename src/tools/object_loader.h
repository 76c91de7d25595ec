// The object that info, simulate and render work on: a URDF file, a PartNet-Mobility folder or
// the built-in cabinet, loaded into a scene of its own.
#pragma once

#include <memory>
#include <string>

#include "arg_parser.h"
#include "partsim/physics/scene.h"

namespace partsim::tools {

/// Which object to load, and how, from the command line.
struct ObjectArgs {
  std::string file;  ///< URDF file or PartNet-Mobility folder; "" for the built-in cabinet
  bool fix_root = true;
};

/// Declares OBJECT (one at most), --fix-root and --free-root to `parser`, filling `args`.
void AddObjectArgs(ArgParser* parser, ObjectArgs* args);

/// A scene holding the one articulation that the command works on.
struct LoadedObject {
  std::unique_ptr<Scene> scene;
  Articulation art;
  std::string source;  ///< the file name, or "built-in cabinet"
};

/// Loads the object of `args` into a new scene made with `config`. Throws (a runtime failure)
/// naming the file when it is missing or invalid.
LoadedObject LoadObject(const ObjectArgs& args, const SceneConfig& config);

/// The unit of a joint's position: "m", "rad", or "" for a fixed joint.
const char* JointUnit(JointType type);

}  // namespace partsim::tools
