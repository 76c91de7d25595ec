// What the viewer sends of a scene: its structure (bodies with visuals and collision shapes,
// articulations with joints, cameras) as scene.json, the meshes as the "PSMH" binary, and
// snapshots of what moves (body poses, joint positions, contacts). Snapshots are taken on the
// scene's thread; everything they hold is immutable afterwards, so the network thread reads them
// freely.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "partsim/physics/description.h"

namespace partsim {
class Scene;
}

namespace partsim::internal {

/// One body the page draws: an actor (articulation_id < 0) or a link.
struct ContentBody {
  int actor_id = -1;
  int articulation_id = -1;  ///< the scene's id of the link's articulation
  int link_index = -1;
};

/// One articulation: its scene id, and its joints with a dof by name.
struct ContentArticulation {
  int scene_id = -1;
  std::string name;
  std::vector<std::string> dof_joints;       ///< joints with a dof, in qpos order
  std::map<std::string, int> joint_by_name;  ///< every joint -> its index (child link index)
};

/// The structure of a scene at one moment: scene.json without its poses, and the tables that
/// map the page's ids back to the scene.
struct SceneContent {
  long long version = 0;  ///< scene_version: 1 for the first snapshot, +1 for each later one
  std::vector<ContentBody> bodies;
  std::vector<ContentArticulation> articulations;
  std::vector<std::shared_ptr<const MeshData>> meshes;  ///< /api/mesh/K.bin
  std::vector<std::string> textures;                    ///< /api/texture/K.png: image paths
  nlohmann::json json;                                  ///< scene.json without "poses"
};

/// Snapshots the structure of `scene` (on its thread).
std::shared_ptr<SceneContent> MakeSceneContent(Scene& scene, long long version);

/// What moves, at one moment.
struct MotionSnapshot {
  long long version = 0;      ///< the SceneContent it belongs to
  long long step = 0;         ///< steps taken (served: the SimServer's clock; else time / timestep)
  double time = 0.0;          ///< simulated time (s)
  std::vector<double> poses;  ///< 7 per body: x, y, z, qw, qx, qy, qz (m)
  std::vector<std::vector<double>> qpos;  ///< per articulation (dof), m or rad
  std::vector<std::vector<double>> qvel;  ///< per articulation (dof), m/s or rad/s
  bool has_contacts = false;              ///< contacts were read (somebody subscribes)
  std::vector<double> contact_points;     ///< 3 per point, world (m)
  std::vector<double> contact_normals;    ///< 3 per point, world, unit
  std::vector<double> contact_forces;     ///< normal force per point (N)
};

/// Reads poses and joint states of the bodies and articulations of `content` (and the
/// contacts when `contacts`), on the scene's thread.
std::shared_ptr<MotionSnapshot> TakeMotionSnapshot(Scene& scene, const SceneContent& content,
                                                   bool contacts);

/// Whether body `i` moved between two pose lists (7 numbers a body) by more than the
/// viewer's tolerance (1e-5 m in position, 1e-5 in a quaternion component).
bool BodyMoved(const std::vector<double>& a, const std::vector<double>& b, size_t i);

/// The "PSMH" binary of a mesh (docs/viewer.md): little-endian header, float32 positions,
/// normals and uvs when the mesh has one per vertex, uint32 triangle indices.
std::string EncodeMesh(const MeshData& mesh);

/// JSON text of numbers with 7 significant digits (poses and joint states of messages sent many
/// times a second: a third of the size of full precision).
void AppendNumbers(std::string* out, const double* values, size_t n);

}  // namespace partsim::internal
