// Internals of Scene: the description entries, the compiled tables that map partsim entities to
// MuJoCo ids, and the mutable data. Not part of the public API.
#pragma once

#include <mujoco/mujoco.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "partsim/physics/kinematics.h"
#include "partsim/physics/observer.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace internal {

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

/// Compiled form of one joint of an articulation (the joint above link i).
struct CompiledJoint {
  int mj_joint = -1;  ///< main MuJoCo joint (hinge or slide), -1 for fixed
  int qposadr = -1;
  int dofadr = -1;
  int dof_index = -1;            ///< index in the articulation's qpos, -1 when fixed
  int actuator = -1;             ///< drive actuator
  int screw_slide_qposadr = -1;  ///< screw joints: the coupled slide joint
  int screw_slide_dofadr = -1;
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
  std::vector<int> link_body;         ///< MuJoCo body per link
  std::vector<int> link_mocap;        ///< kinematic articulations: mocap id per link
  std::vector<CompiledJoint> joints;  ///< per link (entry 0 unused)
  std::vector<int> dof_links;         ///< partsim dof -> link index
  std::vector<CompiledCoupling> couplings;
  /// kinematic articulations: the forward kinematics that places their links
  std::optional<KinematicModel> kinematics;
  int root_qposadr = -1;  ///< free root joint
  int root_dofadr = -1;
  /// MuJoCo dofs of the articulation's joints (free root excluded), ascending.
  std::vector<int> mj_dofs;
  /// Maps partsim joint velocities to the MuJoCo dofs above: qvel_mj = G qvel.
  Eigen::MatrixXd G;
};

/// Scene::Impl: description, compiled model and data.
struct SceneImpl {
  SceneConfig config;

  // description
  struct ActorEntry {
    int id;
    ActorDesc desc;
    uint32_t render_id = 0;       ///< entity id in segmentation images
    uint32_t visual_id_base = 0;  ///< visual i has id visual_id_base + i
  };
  struct ArticulationEntry {
    int id;
    ArticulationDesc desc;
    // kinematic articulations keep their joint state here
    Eigen::VectorXd kin_qpos;
    Eigen::VectorXd kin_qvel;
    uint32_t render_id_base = 0;           ///< link i has entity id render_id_base + i
    std::vector<uint32_t> visual_id_base;  ///< per link: visual j has id base + j
  };
  std::vector<ActorEntry> actors;
  std::vector<ArticulationEntry> articulations;

  // the thread that holds the scene (Scene::Use), if any
  std::recursive_mutex use_mutex;
  std::atomic<std::thread::id> user{};
  int use_depth = 0;  ///< nested Uses of the holding thread (guarded by use_mutex)
  /// Throws partsim::Error when a thread other than the caller holds the scene.
  void CheckUser() const;
  /// ids of actors, articulations, links and cameras (NewEntityId), scene-wide; 0 is no entity
  /// (background in segmentation pictures)
  int next_id = 1;
  /// Contacts MuJoCo's buffers hold (nconmax): grown by Step when a step fills them, kept
  /// across recompiles and clones; the compiler never goes below kBaseContacts.
  int contact_capacity = 0;
  /// MuJoCo's scratch stack (nstack, numbers) when a step ran out of it: doubled by Step, kept
  /// across recompiles and clones; 0 leaves the compiler's estimate.
  long long stack_capacity = 0;
  /// Actors added since the last compile: they join the model at the next compile (any use
  /// that needs the model), so that adding n actors one by one compiles once, not n times.
  /// A compile that fails takes them back out (see EnsureCompiled).
  std::vector<int> uncompiled_actors;
  bool IsUncompiled(int actor_id) const {
    return std::find(uncompiled_actors.begin(), uncompiled_actors.end(), actor_id) !=
           uncompiled_actors.end();
  }
  uint32_t next_visual_id = 1;

  /// bumped whenever actors or articulations change (GetDescriptionVersion)
  uint64_t description_version = 0;
  /// State of the subsystems that observe the scene (the renderer's cameras, lights and
  /// backend), by key; physics only owns and clones them (partsim/physics/observer.h).
  std::map<std::string, std::unique_ptr<SceneAttachment>> attachments;

  // model
  mjModel* m = nullptr;
  std::string mjcf;
  bool dirty = true;
  std::map<int, CompiledActor> compiled_actors;                ///< by actor id
  std::map<int, CompiledArticulation> compiled_articulations;  ///< by articulation id
  std::vector<GeomOwner> geom_owner;                           ///< per MuJoCo geom

  // data
  mjData* d = nullptr;
  bool forward_valid = false;     ///< mj_forward quantities in d match qpos/qvel
  bool kinematics_valid = false;  ///< poses and velocities of bodies in d match qpos/qvel
  bool xfrc_dirty = false;        ///< xfrc_applied holds forces to clear after the step
  std::vector<Warning> warnings;
  std::vector<double> pending_ctrl;  ///< scratch

  ~SceneImpl();

  // description lookups; throw partsim::Error for removed entities
  ActorEntry& GetActor(int id);
  ArticulationEntry& GetArticulation(int id);
  const CompiledActor& Compiled(const ActorEntry& a);
  const CompiledArticulation& Compiled(const ArticulationEntry& a);

  /// Compiles when the description changed, carrying over the state by name.
  void EnsureCompiled();
  /// Runs mj_forward if the state changed since the last one.
  void EnsureForward();
  /// Writes drive controls into d->ctrl.
  void ApplyDrives();
  /// Places the links of kinematic articulations from their qpos.
  void UpdateKinematicArticulation(ArticulationEntry& a);
  void Step(int n);
  /// Recompiles (state kept) with room for `contacts` contacts and a stack of `stack` numbers,
  /// with a warning saying `why`; when MuJoCo cannot allocate that, the scene stays as it was
  /// and partsim::Error says so.
  void GrowBuffers(int contacts, long long stack, const std::string& why);
  /// Runs forward kinematics and body velocities if the state changed.
  void EnsureKinematics();
  /// After a change of the state: derived quantities are stale. Refused (partsim::Error) on a
  /// thread other than the one holding the scene.
  void Invalidate() {
    CheckUser();
    forward_valid = kinematics_valid = false;
  }
};

/// Writes MJCF for the whole scene and fills the compiled tables (ids resolved after loading).
std::string GenerateMjcf(const SceneImpl& scene);
/// A MuJoCo message with the names partsim generated (r0_l3, r0_j3, a2_g0, mesh4, ...) replaced
/// by the user's (link, joint and actor names, mesh files), and MuJoCo's positions in the
/// generated MJCF dropped.
std::string DescribeMjNames(const SceneImpl& scene, const std::string& text);
/// Fills compiled tables from a loaded model.
void BuildTables(SceneImpl& scene);
/// The step over which joint drives are backward Euler (DriveVelocityGain, DriveArmature): the
/// implicit integrator's timestep; 0, the plain gains, for the explicit integrators.
inline double DriveStep(const SceneConfig& config) {
  return config.integrator == Integrator::kImplicit ? config.timestep : 0.0;
}

/// Contacts a fresh scene's buffers hold (SceneImpl::contact_capacity grows from there).
constexpr int kBaseContacts = 256;
/// Writes a dynamic actor's velocity damping into its free joint's dofs (compiled model).
void SyncActorDamping(SceneImpl& scene, const ActorDesc& desc, const CompiledActor& compiled);

/// Name of MuJoCo elements generated for partsim entities.
std::string ActorBodyName(int actor_id);
std::string LinkBodyName(int articulation_id, int link);
std::string JointMjName(int articulation_id, int link);
std::string ScrewSlideMjName(int articulation_id, int link);
std::string ActuatorMjName(int articulation_id, int link);

/// Damping ratio of a contact spring-damper with the given coefficient of restitution.
double RestitutionToDampingRatio(double restitution);

}  // namespace internal

struct Scene::Impl : internal::SceneImpl {};

}  // namespace partsim
