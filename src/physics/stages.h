// The two compiled stages of a scene, after its description (partsim/physics/description.h):
//
//   description (plain data, SceneImpl::actors and ::articulations)
//     -> Model: what the compiler makes of it and only a recompile or a setter of a model
//        parameter changes (MuJoCo's mjModel, the tables from partsim entities to MuJoCo ids,
//        the drive gains)
//     -> Data: the state a step advances (MuJoCo's mjData, drive targets, the joint state of
//        kinematic articulations) and what is derived from it.
//
// Both own their MuJoCo structures, copy by value (Clone copies the stages) and are read by the
// free functions of dynamics.h, as MuJoCo's own functions take (m, d). Not part of the public
// API.
#pragma once

#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "partsim/physics/kinematics.h"

namespace partsim {
namespace internal {

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
struct MjSpecDeleter {
  void operator()(mjSpec* s) const { mj_deleteSpec(s); }
};
using MjModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using MjSpecPtr = std::unique_ptr<mjSpec, MjSpecDeleter>;
using MjDataPtr = std::unique_ptr<mjData, MjDataDeleter>;

/// Hull vertices MuJoCo keeps of a mesh it collides with (its maxhullvert), for meshes the
/// assets layer has not bounded (kMaxConvexPieceVertices, the same number): shapes put in a
/// description directly and an MJCF file's meshes that set no bound of their own. Qhull costs
/// about n^2.5 in the points on one plane; a flat 10,000-corner piece compiled for a minute.
constexpr int kMaxHullVertices = 2000;

/// Where a MuJoCo geom came from.
struct GeomOwner {
  int actor_id = -1;         ///< owning actor, or -1
  int articulation_id = -1;  ///< owning articulation, or -1
  int link_index = -1;
  int shape_index = -1;
};

/// Compiled form of an actor.
struct CompiledActor {
  int body = -1;
  int mocap = -1;    ///< kinematic actors are MuJoCo mocap bodies
  int qposadr = -1;  ///< dynamic actors have a free joint
  int dofadr = -1;
};

/// A joint's PD drive as the engine applies it: ctrl = stiffness target + damping
/// velocity_target - velocity_gain qvel, with the armature it adds (backward Euler, see
/// DriveVelocityGain in partsim/physics/description.h; velocity_gain 0 and the damping in the
/// actuator's bias for the explicit integrators).
struct CompiledDrive {
  double stiffness = 0.0;
  double damping = 0.0;
  double velocity_gain = 0.0;
  double armature = 0.0;  ///< inertia the drive adds to its dof
};

/// Compiled form of one joint of an articulation (the joint above link i).
struct CompiledJoint {
  int mj_joint = -1;  ///< main MuJoCo joint (hinge or slide), -1 for fixed
  int qposadr = -1;
  int dofadr = -1;
  int dof_index = -1;            ///< index in the articulation's qpos, -1 when fixed
  int actuator = -1;             ///< drive actuator
  int screw_slide_qposadr = -1;  ///< screw joints: the coupled slide joint
  int screw_slide_dofadr = -1;
  CompiledDrive drive;
};

/// A coupled joint (URDF mimic): an ordinary dof that an equality constraint holds to
/// q[dof] = multiplier * q[source_dof] + offset.
struct CompiledCoupling {
  int dof = -1;         ///< partsim dof index of the coupled joint
  int source_dof = -1;  ///< partsim dof index of its source
  double multiplier = 1.0;
  double offset = 0.0;
};

/// Compiled form of an articulation.
struct CompiledArticulation {
  bool kinematic = false;
  std::vector<int> link_body;         ///< MuJoCo body per link
  std::vector<int> link_mocap;        ///< kinematic articulations: mocap id per link
  std::vector<CompiledJoint> joints;  ///< per link (entry 0 unused)
  std::vector<int> dof_links;         ///< partsim dof -> link index (DofLinks)
  std::vector<CompiledCoupling> couplings;
  /// kinematic articulations: the forward kinematics that places their links
  std::optional<KinematicModel> kinematics;
  int root_qposadr = -1;  ///< free root joint
  int root_dofadr = -1;
  /// MuJoCo dofs of the articulation's joints (free root excluded), ascending.
  std::vector<int> mj_dofs;
  /// Maps partsim joint velocities to the MuJoCo dofs above: qvel_mj = G qvel.
  Eigen::MatrixXd G;
  int Dof() const { return static_cast<int>(dof_links.size()); }
  /// The compiled joint of dof k.
  const CompiledJoint& DofJoint(int k) const { return joints[dof_links[k]]; }
};

/// The compiled model: MuJoCo's model and partsim's tables over it.
struct Model {
  MjModelPtr mj;
  /// the specification MuJoCo compiled: never changed after, shared by copies
  std::shared_ptr<mjSpec> spec;
  std::map<int, CompiledActor> actors;                ///< by actor id
  std::map<int, CompiledArticulation> articulations;  ///< by articulation id
  std::vector<GeomOwner> geom_owner;                  ///< per MuJoCo geom

  Model() = default;
  Model(Model&&) = default;
  Model& operator=(Model&&) = default;
  /// A deep copy (mj_copyModel; the tables by value). Throws partsim::Error when MuJoCo cannot
  /// allocate it.
  Model Copy() const;
};

/// The part of the state partsim keeps beside MuJoCo's, per articulation.
struct ArticulationData {
  Eigen::VectorXd drive_target;           ///< per dof, m or rad
  Eigen::VectorXd drive_velocity_target;  ///< per dof, m/s or rad/s
  Eigen::VectorXd kin_qpos;               ///< kinematic articulations: joint positions
  Eigen::VectorXd kin_qvel;               ///< kinematic articulations: joint velocities
};

/// The data: MuJoCo's data, partsim's state beside it and what is known to be up to date.
struct Data {
  MjDataPtr mj;
  std::map<int, ArticulationData> articulations;  ///< by articulation id
  bool forward_valid = false;                     ///< mj_forward quantities match qpos/qvel
  bool kinematics_valid = false;  ///< poses and velocities of bodies match qpos/qvel
  bool xfrc_dirty = false;        ///< xfrc_applied holds forces to clear after the step

  Data() = default;
  Data(Data&&) = default;
  Data& operator=(Data&&) = default;
  /// A deep copy for `model` (a Copy of the model this data belongs to).
  Data CopyFor(const Model& model) const;
  /// After a change of the state: derived quantities are stale.
  void Invalidate() { forward_valid = kinematics_valid = false; }
};

}  // namespace internal
}  // namespace partsim
