// The object that info, simulate and render work on: a URDF file, a PartNet-Mobility folder, an
// MJCF file or the built-in cabinet, loaded into a scene of its own.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "arg_parser.h"
#include "partsim/physics/mjcf.h"
#include "partsim/physics/scene.h"

namespace partsim::tools {

/// Which object to load, and how, from the command line.
struct ObjectArgs {
  /// URDF file, PartNet-Mobility folder or MJCF file; "" for the built-in cabinet
  std::string file;
  bool fix_root = true;
};

/// Declares OBJECT (one at most), --fix-root and --free-root to `parser`, filling `args`.
void AddObjectArgs(ArgParser* parser, ObjectArgs* args);

/// A scene holding the articulation that the command works on.
struct LoadedObject {
  std::unique_ptr<Scene> scene;
  /// The articulation; for an MJCF model, the one of most dofs among its trees, or an empty
  /// handle (GetScene() null) when it has none.
  Articulation art;
  std::string source;             ///< the file name, or "built-in cabinet"
  std::optional<MjcfModel> mjcf;  ///< an MJCF file's model
};

/// Loads the object of `args` into a new scene made with `config` (an MJCF file's scene takes
/// the file's own options instead, saying so on stderr). Throws (a runtime failure) naming the
/// file when it is missing or invalid.
LoadedObject LoadObject(const ObjectArgs& args, const SceneConfig& config);

/// The unit of a joint's position: "m", "rad", or "" for a fixed joint.
const char* JointUnit(JointType type);

}  // namespace partsim::tools
