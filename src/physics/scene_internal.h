// Internals of Scene: the description entries and the two compiled stages (stages.h: the model
// and the data), with what keeps them in step. Not part of the public API.
#pragma once

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "partsim/physics/observer.h"
#include "partsim/physics/scene.h"
#include "physics/stages.h"

namespace partsim {
namespace internal {

/// Scene::Impl: description, compiled model and data.
struct SceneImpl {
  SceneConfig config;

  // description
  struct ActorEntry {
    int id;
    ActorDesc desc;
    uint32_t render_id = 0;       ///< entity id in segmentation images
    uint32_t visual_id_base = 0;  ///< visual i has id visual_id_base + i
    /// Actors made of an MJCF model's bodies (MjcfEntry): the model's id, the MuJoCo body
    /// (with the prefix; "world" for the geoms of its worldbody) and its geoms, in the order of
    /// desc.collisions. The compiler adds nothing for them: they come with the model.
    int mjcf = -1;
    std::string mj_body;
    std::vector<std::string> mj_geoms;
  };
  struct ArticulationEntry {
    int id;
    /// The description; its drives' targets are the targets the articulation starts with (the
    /// current ones are in the data).
    ArticulationDesc desc;
    uint32_t render_id_base = 0;           ///< link i has entity id render_id_base + i
    std::vector<uint32_t> visual_id_base;  ///< per link: visual j has id base + j
    /// Articulations made of an MJCF model's tree: the model's id and, per link, its MuJoCo
    /// body, joint ("" for none) and geoms (desc order). A body with several joints is a chain of
    /// links, one per joint, the last holding its shapes. The compiler adds the drives alone.
    int mjcf = -1;
    std::vector<std::string> mj_link_body, mj_link_joint;
    std::vector<std::vector<std::string>> mj_link_geoms;
  };
  /// An MJCF model loaded into the scene (partsim/physics/mjcf.h). Its specification, parsed
  /// from the file and never changed after, is attached (copied) into the scene's at each
  /// compile, its element names prefixed.
  struct MjcfEntry {
    int id;
    std::string name, path, prefix;
    Pose pose;
    std::shared_ptr<mjSpec> spec;
    std::vector<int> actors, articulations;  ///< entities made of its bodies
    std::vector<std::string> bodies_without_handle;
  };
  std::vector<MjcfEntry> mjcf_models;
  int next_mjcf_id = 0;
  MjcfEntry& GetMjcf(int id);
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
  /// Bytes of MuJoCo's arena (contacts, constraint rows and its scratch stack) once a step or
  /// a compile ran out of it: doubled each time, kept across recompiles and clones; 0 leaves
  /// the size to the compiler (BuildSpec).
  long long arena_capacity = 0;
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

  // the compiled stages
  Model model;
  bool dirty = true;  ///< the description changed since the model was compiled
  Data data;
  std::vector<Warning> warnings;

  mjModel* m() const { return model.mj.get(); }
  mjData* d() const { return data.mj.get(); }

  // description lookups; throw partsim::Error for removed entities
  ActorEntry& GetActor(int id);
  ArticulationEntry& GetArticulation(int id);
  const CompiledActor& Compiled(const ActorEntry& a);
  const CompiledArticulation& Compiled(const ArticulationEntry& a);
  /// The state of an articulation beside MuJoCo's (drive targets, kinematic joint state).
  ArticulationData& State(const ArticulationEntry& a);

  /// Compiles when the description changed, carrying over the state by name.
  void EnsureCompiled();
  /// Runs mj_forward if the state changed since the last one.
  void EnsureForward();
  /// Places the links of kinematic articulations from their qpos.
  void UpdateKinematicArticulation(ArticulationEntry& a);
  void Step(int n);
  /// Recompiles (state kept) with an arena twice the size it has, with a warning saying `why`;
  /// when MuJoCo cannot allocate that, the scene stays as it was and partsim::Error says so.
  void GrowArena(const std::string& why);
  /// Runs forward kinematics and body velocities if the state changed.
  void EnsureKinematics();
  /// After a change of the state: derived quantities are stale. Refused (partsim::Error) on a
  /// thread other than the one holding the scene.
  void Invalidate() {
    CheckUser();
    data.Invalidate();
  }
};

/// The model specification of the whole scene (MuJoCo's mjSpec, built through its model-editing
/// API), or null with *error set; `mesh_users` receives the first geom of each mesh asset
/// (DescribeMjNames). Ids are resolved after compiling (BuildTables).
MjSpecPtr BuildSpec(const SceneImpl& scene, std::string* error,
                    std::map<std::string, std::string>* mesh_users = nullptr);
/// The MJCF text of a specification (mj_saveXMLString), for reading.
std::string SaveMjcf(mjSpec* spec);
/// A MuJoCo message with the names partsim generated (r0_l3, r0_j3, a2_g0, mesh4, ...) replaced
/// by the user's (link, joint and actor names, mesh files), and MuJoCo's positions dropped.
std::string DescribeMjNames(const SceneImpl& scene, const std::string& text,
                            const std::map<std::string, std::string>& mesh_users);
/// Fills the tables of `model` (its MuJoCo model compiled from BuildSpec(scene)) and its drive
/// gains from the scene's description.
void BuildTables(const SceneImpl& scene, Model& model);
/// A drive as the engine applies it over steps of `dt` (DriveStep).
CompiledDrive CompileDrive(const DriveDesc& drive, double dt);
/// The step over which joint drives are backward Euler (DriveVelocityGain, DriveArmature): the
/// implicit integrators' timestep; 0, the plain gains, for the explicit integrators.
inline double DriveStep(const SceneConfig& config) {
  return config.integrator == Integrator::kImplicit ||
                 config.integrator == Integrator::kImplicitFast
             ? config.timestep
             : 0.0;
}

/// MuJoCo's capsules and cylinders lie along z, partsim's along x: a MuJoCo geom's frame is the
/// partsim shape's frame times this rotation (z onto x).
inline const Eigen::Quaterniond kZToX{Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY())};
/// The distance (m) below which two shapes placed exactly touching push on each other: MuJoCo
/// applies contact force only below a pair's margin, and a body set down at distance 0 would fall
/// for a step. Each shape's margin carries half of it.
constexpr double kTouchSkin = 1e-7;
/// Writes a dynamic actor's velocity damping into its free joint's dofs (compiled model).
void SyncActorDamping(Model& model, const ActorDesc& desc, const CompiledActor& compiled);

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
