// Scene files: a JSON list of objects (URDF files or PartNet-Mobility folders) with their poses,
// and the one entry point that adds what a path names to a scene (a URDF, a PartNet-Mobility
// folder or a scene file), as `partsim serve SCENE` takes it.
//
// Format (every field but "path" optional; numbers in metres and radians):
//
//   {"objects": [
//     {"path": "cabinet_a/",                  // URDF file or PartNet-Mobility folder
//      "name": "left_cabinet",                 // articulation name, unique in the scene
//      "pose": {"position": [x, y, z],         // X_WO: the object's frame in the world
//               "orientation": [w, x, y, z]},  // unit quaternion; or "rpy": [r, p, y]
//      "fix_root": true,                       // root welded to the world, else free
//      "scale": 1.0}]}                         // uniform scale, > 0
//
// "rpy" follows URDF: rotations about the fixed x, y, z axes, R = Rz(y) Ry(p) Rx(r).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// One entry of a scene file.
struct SceneObjectSpec {
  std::string name;  ///< articulation name; empty: the asset's own name (made unique)
  std::string path;  ///< URDF file or PartNet-Mobility folder, resolved against the scene file
  Pose pose;         ///< X_WO: the object's frame in the world (unit quaternion)
  std::optional<bool> fix_root;  ///< unset: the caller's default (AddSceneObjects' fix_root)
  double scale = 1.0;            ///< uniform scale on geometry and origins, > 0
};

/// A parsed scene file.
struct SceneFileSpec {
  std::string path;  ///< the scene file itself
  std::vector<SceneObjectSpec> objects;
};

/// Reads a scene file (format above). Relative paths resolve against the scene file's folder.
/// Checks the JSON only (types, finite numbers, unit quaternions, positive scales, names unique
/// within the file, entries that are not scene files); it does not open the objects. Throws
/// partsim::Error naming the file, the entry index and the field at fault, e.g.
/// "scene file s.json: objects[1].pose.orientation: quaternion has norm 2 (must be 1)".
SceneFileSpec ReadSceneFile(const std::string& path);

/// Adds to `scene` what `path` names:
/// - a `.urdf` file, or a PartNet-Mobility folder (holding mobility.urdf and mobility_v2.json,
///   loaded z-up by PartNetMobilityLoader): one articulation at `default_pose` (X_WO), its root
///   fixed when `fix_root`;
/// - a `.json` scene file: each entry (itself a URDF or a PartNet-Mobility folder) at its pose,
///   `fix_root` being the default of entries without "fix_root";
/// - an MJCF `.xml` file (root element <mujoco>): the whole model at `default_pose` (LoadMjcf,
///   partsim/physics/mjcf.h), returning the articulations made of its trees.
/// The pose places the object's frame: a URDF whose root hangs from a "world" link keeps that
/// offset (root pose = pose * offset), and such a URDF's own joint decides whether its root is
/// fixed. Articulations get the entry's "name" when given (it must not be taken in the scene yet),
/// else the asset's own name, suffixed "_2", "_3"... when already taken.
/// All or nothing: every object is read before any is added, and on an error the scene is left as
/// it was (it keeps stepping, earlier objects remain). Returns the articulations added, in order.
/// Throws partsim::Error naming the path (and for scene files the entry and field) and the
/// cause: missing file, unknown extension, bad JSON, wrong field type, zero or non-unit
/// quaternion, non-finite number, nested scene file, or the loader's own error.
std::vector<Articulation> AddSceneObjects(Scene* scene, const std::string& path,
                                          const Pose& default_pose = Pose(), bool fix_root = true);

}  // namespace partsim
