// MuJoCo models (MJCF files) in a partsim scene. A model loaded with LoadMjcf joins the scene as
// MuJoCo defines it: its bodies, joints, geoms, tendons, equality constraints, actuators and
// sensors are MuJoCo's own (attached to the scene's model through MuJoCo's model-editing API),
// and partsim gives its bodies the handles of the rest of the scene: each kinematic tree becomes
// an articulation, each free or static body an actor, so that poses, joint states, drives,
// contacts and cameras work on them as on any other entity.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// Handle to an MJCF model loaded into a scene. Cheap to copy; valid while the scene lives.
class MjcfModel {
 public:
  MjcfModel() = default;
  MjcfModel(Scene* scene, int id) : scene_(scene), id_(id) {}

  int GetId() const { return id_; }
  /// The model's name (<mujoco model=...>, else the file's stem).
  const std::string& GetName() const;
  /// The file it was loaded from.
  const std::string& GetPath() const;
  /// What its MuJoCo element names start with in the scene's model ("NAME/"): the scene's
  /// GetMjModel() holds its elements as PREFIX + the name in the file.
  const std::string& GetPrefix() const;

  /// The articulations (one per kinematic tree) and actors (free, static and mocap bodies, and
  /// the geoms of its worldbody as one static actor) made of its bodies.
  std::vector<Articulation> GetArticulations() const;
  std::vector<Actor> GetActors() const;
  /// Bodies simulated and drawn by MuJoCo that have no partsim handle: trees with a ball joint.
  std::vector<std::string> GetBodiesWithoutHandle() const;

  /// The model's actuators, as MuJoCo defines them (names without the prefix), and their
  /// controls (MuJoCo's ctrl, kept across steps and recompiles until set again).
  std::vector<std::string> GetActuatorNames() const;
  Eigen::VectorXd GetCtrl() const;
  void SetCtrl(const Eigen::VectorXd& ctrl);
  /// Sets one actuator's control by name; throws partsim::Error naming an unknown one.
  void SetCtrl(const std::string& actuator, double value);
  /// The model's joints (names without the prefix) and its slice of MuJoCo's qpos and qvel,
  /// in the order MuJoCo holds them.
  std::vector<std::string> GetJointNames() const;
  Eigen::VectorXd GetQpos() const;
  void SetQpos(const Eigen::VectorXd& qpos);
  Eigen::VectorXd GetQvel() const;
  void SetQvel(const Eigen::VectorXd& qvel);
  /// The model's tendons (names without the prefix) and their lengths now.
  std::vector<std::string> GetTendonNames() const;
  Eigen::VectorXd GetTendonLengths() const;
  /// The MuJoCo id of one of its elements in the scene's model (mjOBJ_BODY, mjOBJ_JOINT, ... as
  /// an int); -1 when it has none of that name.
  int MjId(int mj_object_type, const std::string& name) const;

  Scene* GetScene() const { return scene_; }

 private:
  Scene* scene_ = nullptr;
  int id_ = -1;
};

/// Loads an MJCF file into the scene at `pose` (the frame its worldbody is placed in). <include>,
/// <replicate>, <attach> with <model> assets and relative asset paths work as in MuJoCo; the
/// scene's options (timestep, gravity, integrator) are kept, the file's are not used (see
/// SceneConfigFromMjcf). Bad MJCF throws partsim::Error with MuJoCo's message (file and line);
/// the scene is then as it was.
MjcfModel LoadMjcf(Scene& scene, const std::string& path, const Pose& pose = Pose());
/// The models loaded into a scene.
std::vector<MjcfModel> GetMjcfModels(const Scene& scene);
/// The options of an MJCF file as a SceneConfig (timestep, gravity, integrator, solver
/// iterations), for a scene made to run that file as MuJoCo would.
SceneConfig SceneConfigFromMjcf(const std::string& path);
/// Whether a file is MJCF: a .xml whose root element is <mujoco>.
bool IsMjcfFile(const std::string& path);

}  // namespace partsim
