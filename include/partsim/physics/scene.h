// The Scene owns the three stages of a world: the description (what was added), the compiled
// model (mjModel plus partsim's tables) and the data (mjData plus drive targets). Actor,
// Articulation, Link and Joint are light handles that index into them.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/core/pose.h"
#include "partsim/physics/description.h"

struct mjModel_;
struct mjData_;

namespace partsim {

class Scene;
class Shape;
class ActorBuilder;
class ArticulationBuilder;

/// Numerical integrator of the scene (MuJoCo's). kImplicitFast, the default, integrates joint
/// damping and the drives' velocity terms implicitly, as kImplicit does, and leaves out the
/// Coriolis and centripetal derivatives that make kImplicit's matrix dense and unsymmetric: what
/// MuJoCo recommends for new models.
enum class Integrator { kEuler, kImplicit, kRK4, kImplicitFast };

/// Scene-wide settings.
struct SceneConfig {
  double timestep = 1.0 / 500.0;                           ///< seconds, > 0
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);  ///< m/s^2, world frame
  PhysicalMaterial default_material;
  int solver_iterations = 50;  ///< constraint solver iterations, >= 1
  /// the implicit ones handle stiff PD damping
  Integrator integrator = Integrator::kImplicitFast;
  /// m, >= rest_offset: each shape's distance within which contacts are found (SAPIEN's and
  /// PhysX's contact offset; a pair adds up its two shapes'). Contacts found farther than the
  /// rest offset are reported with zero force. MuJoCo's margin + gap.
  double contact_offset = 0.0;
  /// m, >= 0: each shape's distance at which bodies rest on it (SAPIEN's rest offset; a pair
  /// adds up its two shapes'). MuJoCo's margin.
  double rest_offset = 0.0;
  /// in (0, 0.9999]: the share of the force a contact needs that it gives at the moment of
  /// touching (MuJoCo's solimp dmin; dmax is max(0.95, this)). MuJoCo's own 0.9 lets a body
  /// sink about 0.1 mm into what it rests on and gives 97% of the support at first touch; at
  /// partsim's 0.999 contacts are nearly hard, as PhysX's are (a body set down on another is
  /// held within 1e-3 of its weight from the first step).
  double contact_impedance = 0.999;
};

/// Handle to an actor. Cheap to copy; valid until the actor is removed.
class Actor {
 public:
  Actor() = default;
  Actor(Scene* scene, int id) : scene_(scene), id_(id) {}

  /// Scene-wide id, unique among actors, articulations and links; also the actor's entity id in
  /// segmentation pictures.
  int GetId() const { return id_; }
  const std::string& GetName() const;
  void SetName(const std::string& name);
  ActorType GetType() const;
  /// X_WA: the actor's frame in the world.
  Pose GetPose() const;
  /// Teleports the actor. A static actor is moved in the model: meant for placing it before
  /// simulating (what rests on it is not carried along).
  void SetPose(const Pose& pose);
  /// World-frame linear velocity of the actor's origin (m/s).
  Eigen::Vector3d GetVelocity() const;
  /// World-frame angular velocity (rad/s).
  Eigen::Vector3d GetAngularVelocity() const;
  void SetVelocity(const Eigen::Vector3d& v);
  void SetAngularVelocity(const Eigen::Vector3d& w);
  /// Mass (kg) as compiled.
  double GetMass() const;
  /// Principal moments of inertia (kg m^2) as compiled: given, or computed by MuJoCo from the
  /// shapes (meshes from their convex hulls).
  Eigen::Vector3d GetInertia() const;
  /// X_WC: the centre of mass frame (principal axes) in the world.
  Pose GetCMassPose() const;
  /// Velocity damping (1/s, >= 0) of a dynamic actor, as PhysX's: the linear velocity decays as
  /// dv/dt = -linear v, the angular as dw/dt = -angular w (about each body axis, with the body's
  /// inertia about that axis). Integrated implicitly. Static and kinematic actors refuse.
  void SetDamping(double linear, double angular);
  double GetLinearDamping() const;
  double GetAngularDamping() const;
  /// Adds a world-frame force (N) at a world point (m) for the next step.
  void AddForceAtPoint(const Eigen::Vector3d& force, const Eigen::Vector3d& point);
  /// Adds a world-frame force (N) at the centre of mass and a torque (N m) for the next step.
  void AddForceTorque(const Eigen::Vector3d& force, const Eigen::Vector3d& torque);
  /// One handle per collision shape, in the order of GetDesc().collisions.
  std::vector<Shape> GetCollisionShapes() const;
  const ActorDesc& GetDesc() const;
  Scene* GetScene() const { return scene_; }
  bool operator==(const Actor& o) const { return scene_ == o.scene_ && id_ == o.id_; }

 private:
  Scene* scene_ = nullptr;
  int id_ = -1;
};

/// Handle to a link of an articulation.
class Link {
 public:
  Link() = default;
  Link(Scene* scene, int articulation_id, int index)
      : scene_(scene), articulation_id_(articulation_id), index_(index) {}

  const std::string& GetName() const;
  /// Index of the link in its articulation (0 is the root).
  int GetIndex() const { return index_; }
  int GetArticulationId() const { return articulation_id_; }
  /// Scene-wide id of the link, unique among actors, articulations and links: its entity id in
  /// segmentation pictures (an actor's is Actor::GetId()).
  int GetId() const;
  /// Index of the parent link, -1 for the root.
  int GetParentIndex() const;
  /// X_WL: the link frame in the world.
  Pose GetPose() const;
  /// X_WC: the centre of mass frame (principal axes) in the world.
  Pose GetCMassPose() const;
  Eigen::Vector3d GetVelocity() const;         ///< world-frame, at the link origin (m/s)
  Eigen::Vector3d GetAngularVelocity() const;  ///< world-frame (rad/s)
  double GetMass() const;                      ///< kg
  Eigen::Vector3d GetInertia() const;          ///< principal moments (kg m^2)
  void AddForceAtPoint(const Eigen::Vector3d& force, const Eigen::Vector3d& point);
  /// One handle per collision shape, in the order of GetDesc().collisions.
  std::vector<Shape> GetCollisionShapes() const;
  const LinkDesc& GetDesc() const;
  Scene* GetScene() const { return scene_; }

 private:
  Scene* scene_ = nullptr;
  int articulation_id_ = -1;
  int index_ = -1;
};

/// Handle to one collision shape of an actor or a link (SAPIEN's CollisionShape); its
/// description is GetDesc().
class Shape {
 public:
  Shape() = default;
  /// Shape `index` of an actor (articulation_id < 0) or of link `link_index` of an articulation.
  Shape(Scene* scene, int actor_id, int articulation_id, int link_index, int index)
      : scene_(scene),
        actor_id_(actor_id),
        articulation_id_(articulation_id),
        link_index_(link_index),
        index_(index) {}

  /// Index in the body's collisions.
  int GetIndex() const { return index_; }
  /// The actor or link the shape belongs to (the other one is an empty handle).
  Actor GetActor() const;
  Link GetLink() const;
  const CollisionShape& GetDesc() const;
  /// SAPIEN's collision groups g0..g3 (see CollisionShape::collision_groups).
  std::array<uint32_t, 4> GetCollisionGroups() const;
  /// Changes the groups; the state of the scene is kept.
  void SetCollisionGroups(const std::array<uint32_t, 4>& groups);

 private:
  CollisionShape& Desc() const;
  Scene* scene_ = nullptr;
  int actor_id_ = -1;
  int articulation_id_ = -1;
  int link_index_ = -1;
  int index_ = -1;
};

/// Handle to the joint between a link and its parent (joint index == child link index).
class Joint {
 public:
  Joint() = default;
  Joint(Scene* scene, int articulation_id, int index)
      : scene_(scene), articulation_id_(articulation_id), index_(index) {}

  const std::string& GetName() const;
  JointType GetType() const;
  int GetIndex() const { return index_; }
  /// Degrees of freedom of this joint: 0 when fixed, else 1 (a coupled joint, URDF mimic,
  /// included).
  int GetDof() const;
  /// Index of this joint's dof in the articulation's qpos, -1 if it has none.
  int GetDofIndex() const;
  Link GetParentLink() const;
  Link GetChildLink() const;
  Pose GetPoseInParent() const;
  Pose GetPoseInChild() const;
  /// X_WJ: the joint frame in the world (moves with the child).
  Pose GetGlobalPose() const;
  /// Joint axis in world coordinates (the x axis of the joint frame).
  Eigen::Vector3d GetGlobalAxis() const;
  /// Limits (lower, upper); +-inf when unlimited.
  Eigen::Vector2d GetLimits() const;
  void SetLimits(double lower, double upper);
  double GetFriction() const;
  double GetDamping() const;
  double GetArmature() const;
  void SetFriction(double friction);
  void SetDamping(double damping);
  void SetArmature(double armature);
  /// Screw pitch, metres per radian (0 for other joints).
  double GetPitch() const;

  /// PD drive: force = stiffness (target - q) + damping (velocity_target - qdot), clamped to
  /// +-force_limit (inf for no clamp).
  void SetDriveProperty(double stiffness, double damping, double force_limit = kInf);
  void SetDriveTarget(double target);
  void SetDriveVelocityTarget(double velocity);
  double GetDriveTarget() const;
  double GetDriveVelocityTarget() const;
  double GetDriveStiffness() const;
  double GetDriveDamping() const;
  double GetDriveForceLimit() const;
  /// Joint position and velocity (m or rad); the joint must have a dof.
  double GetQpos() const;
  double GetQvel() const;
  const JointDesc& GetDesc() const;

 private:
  Scene* scene_ = nullptr;
  int articulation_id_ = -1;
  int index_ = -1;
};

/// Handle to an articulation. Joint-space vectors have one entry per dof, ordered as
/// GetActiveJoints(); a free root's 6 dof are not included (see GetRootPose).
class Articulation {
 public:
  Articulation() = default;
  Articulation(Scene* scene, int id) : scene_(scene), id_(id) {}

  int GetId() const { return id_; }
  const std::string& GetName() const;
  void SetName(const std::string& name);
  bool IsKinematic() const;
  bool HasFixedRoot() const;
  int Dof() const;
  std::vector<Link> GetLinks() const;
  std::vector<Joint> GetJoints() const;        ///< one per non-root link
  std::vector<Joint> GetActiveJoints() const;  ///< joints with a dof, in qpos order
  Link GetLink(int index) const;
  Joint GetJoint(int index) const;
  /// Finds by name; throws partsim::Error naming the missing name.
  Link FindLinkByName(const std::string& name) const;
  Joint FindJointByName(const std::string& name) const;

  Eigen::VectorXd GetQpos() const;
  /// Sets joint positions (dof). A coupled joint (JointCoupling, URDF mimic) is a dof of its own
  /// that an equality constraint holds to its source: its entry is replaced by multiplier *
  /// qpos[source] + offset, so the coupling holds from the start whatever the entry was, and
  /// GetQpos returns the replaced value.
  void SetQpos(const Eigen::VectorXd& qpos);
  Eigen::VectorXd GetQvel() const;
  /// Sets joint velocities (dof); a coupled joint's entry is replaced by multiplier *
  /// qvel[source], as in SetQpos.
  void SetQvel(const Eigen::VectorXd& qvel);
  /// Joint accelerations of the last step (m/s^2 or rad/s^2).
  Eigen::VectorXd GetQacc() const;
  /// Sets accelerations; they only seed the solver's warm start.
  void SetQacc(const Eigen::VectorXd& qacc);
  /// Generalized forces applied by the user (N or N m); they persist until changed.
  Eigen::VectorXd GetQf() const;
  void SetQf(const Eigen::VectorXd& qf);
  /// dof x 2 matrix of (lower, upper).
  Eigen::MatrixX2d GetQlimits() const;
  void SetQlimits(const Eigen::MatrixX2d& limits);

  Pose GetRootPose() const;
  void SetRootPose(const Pose& pose);
  Eigen::Vector3d GetRootVelocity() const;
  Eigen::Vector3d GetRootAngularVelocity() const;
  void SetRootVelocity(const Eigen::Vector3d& v);
  void SetRootAngularVelocity(const Eigen::Vector3d& w);

  /// Whole-articulation drive targets, one per dof.
  void SetDriveTarget(const Eigen::VectorXd& target);
  void SetDriveVelocityTarget(const Eigen::VectorXd& velocity);
  Eigen::VectorXd GetDriveTarget() const;
  Eigen::VectorXd GetDriveVelocityTarget() const;
  /// Same drive parameters on every active joint.
  void SetDriveProperty(double stiffness, double damping, double force_limit = kInf);

  /// Generalized force that cancels gravity, Coriolis and centrifugal forces, and the external
  /// forces added to the links for the next step (AddForceAtPoint, AddForceTorque), each when
  /// asked, at the current state (apply it with SetQf to hold a pose).
  Eigen::VectorXd ComputePassiveForce(bool gravity = true, bool coriolis_and_centrifugal = true,
                                      bool external = true) const;
  /// Accelerations produced by generalized forces qf at the current state, without contacts,
  /// limits or drives: M^-1 (qf - bias).
  Eigen::VectorXd ComputeForwardDynamics(const Eigen::VectorXd& qf) const;
  /// Generalized forces that produce accelerations qacc at the current state: M qacc + bias.
  Eigen::VectorXd ComputeInverseDynamics(const Eigen::VectorXd& qacc) const;
  /// Joint-space mass matrix (dof x dof).
  Eigen::MatrixXd ComputeManipulatorInertiaMatrix() const;
  /// World-frame Jacobian of link `index` at its origin: 6 x dof, rows (linear; angular).
  Eigen::MatrixXd ComputeLinkJacobian(int index) const;
  /// Stacked link Jacobians, 6 nlinks x dof.
  Eigen::MatrixXd ComputeWorldCartesianJacobian() const;
  /// For each link (nlinks x 6), the spatial force its parent exerts on it through its joint,
  /// from the forward dynamics of the current state: force (N) then torque (N m) about the
  /// joint's origin, both in the joint's frame on the child (the link frame times the joint's
  /// pose in the child), as PhysX's incoming joint force. The root's row is zero.
  Eigen::MatrixXd GetLinkIncomingJointForces() const;

  /// Two links of this articulation never collide with each other from now on (links joined by
  /// a joint never do in any case); the state of the scene is kept.
  void DisableCollision(const Link& a, const Link& b);

  const ArticulationDesc& GetDesc() const;
  Scene* GetScene() const { return scene_; }
  bool operator==(const Articulation& o) const { return scene_ == o.scene_ && id_ == o.id_; }

 private:
  Scene* scene_ = nullptr;
  int id_ = -1;
};

/// One contact point between two bodies.
struct ContactPoint {
  Eigen::Vector3d position;  ///< world (m)
  Eigen::Vector3d normal;    ///< world, pointing from body 1 into body 0
  Eigen::Vector3d impulse;   ///< world, impulse on body 0 over the last step (N s)
  Eigen::Vector3d force;     ///< world, force on body 0 (N)
  double separation = 0.0;   ///< signed distance (m), negative when penetrating
};

/// What a contact touches: an actor or a link, and which of its collision shapes.
struct ContactBody {
  enum class Kind { kActor, kLink };
  Kind kind = Kind::kActor;
  int actor_id = -1;         ///< kActor
  int articulation_id = -1;  ///< kLink
  int link_index = -1;       ///< kLink
  int shape_index = -1;      ///< index in the body's collisions
  std::string name;          ///< actor or link name
};

/// The contact between two shapes, with its points. When one of the two is a static actor (the
/// ground, a wall) and the other is not, the static one is body 1: a box resting on the ground
/// reads an upward normal and impulse.
struct Contact {
  ContactBody body0;
  ContactBody body1;
  std::vector<ContactPoint> points;
};

/// Where a ray first meets a shape (Scene::Raycast).
struct RayHit {
  double distance = 0.0;     ///< along the ray (m)
  Eigen::Vector3d position;  ///< world (m)
  Eigen::Vector3d normal;    ///< world, the surface's outward normal
  /// The actor or link hit, and which of its collision shapes; kind kActor with actor_id -1
  /// for a geom of an MJCF model that belongs to neither.
  ContactBody body;
};

/// Warnings recorded during stepping (numerical trouble); the scene stays usable.
struct Warning {
  double time;
  std::string message;
};

/// A simulated world. Non-copyable; use Clone(). Its cameras, lights and rendering are free
/// functions of the render layer (partsim/render/scene_render.h: AddCamera(scene, ...)), its URDF
/// loader one of the assets layer (partsim/assets/urdf.h: CreateUrdfLoader(scene)).
class Scene {
 public:
  explicit Scene(const SceneConfig& config = SceneConfig());
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  /// Independent copy with the same description and state.
  std::unique_ptr<Scene> Clone() const;

  const SceneConfig& GetConfig() const;
  double GetTimestep() const;
  void SetTimestep(double dt);
  Eigen::Vector3d GetGravity() const;
  void SetGravity(const Eigen::Vector3d& g);
  /// Simulated time (s).
  double GetTime() const;

  ActorBuilder CreateActorBuilder();
  ArticulationBuilder CreateArticulationBuilder();

  /// Adds a static ground plane at z = altitude. Cameras see a square of `render_half_size`
  /// (m) around the origin with `render_material`, or nothing when `render` is false.
  Actor AddGround(double altitude = 0.0, const std::optional<PhysicalMaterial>& material = {},
                  const std::string& name = "ground", bool render = true,
                  const Eigen::Vector2d& render_half_size = Eigen::Vector2d(10, 10),
                  const std::optional<RenderMaterial>& render_material = {});
  /// The material of collision shapes that name none: SceneConfig::default_material, which
  /// this replaces for the shapes already in the scene too (the model is recompiled).
  void SetDefaultMaterial(const PhysicalMaterial& material);
  /// Adds an actor or articulation (validated first); the state of everything else is kept.
  Actor AddActor(const ActorDesc& desc);
  Articulation AddArticulation(const ArticulationDesc& desc);
  void RemoveActor(const Actor& actor);
  void RemoveArticulation(const Articulation& articulation);

  std::vector<Actor> GetActors() const;
  std::vector<Articulation> GetArticulations() const;
  Actor FindActorByName(const std::string& name) const;
  Articulation FindArticulationByName(const std::string& name) const;

  /// Advances by one timestep (or n).
  void Step(int n = 1);
  /// Contacts of the last step.
  std::vector<Contact> GetContacts() const;
  /// The first collision shape a ray from `origin` along `direction` (normalized here) meets
  /// within `distance` (m), at the current state; none when it meets nothing.
  std::optional<RayHit> Raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                double distance) const;
  /// Warnings recorded so far (NaN state reset, etc.).
  const std::vector<Warning>& GetWarnings() const;
  void ClearWarnings();

  /// Whole dynamic state (time, positions, velocities, solver warm start, drive targets,
  /// applied forces), bit-exact.
  std::vector<char> Pack() const;
  /// Restores a state from Pack() of this scene (same actors and articulations).
  void Unpack(const std::vector<char>& state);

  /// The compiled MuJoCo model and data (compiled on demand). Read freely; writing is at your
  /// own risk.
  const mjModel_* GetMjModel() const;
  mjData_* GetMjData() const;
  /// The MJCF text the last compile used (for debugging).
  std::string GetMjcf() const;

  /// A scene is used by one thread at a time. Step (and rendering, and the Python calls that
  /// run without the GIL) hold the scene for their thread while they run: meanwhile another
  /// thread's Step waits its turn, and any other call from another thread that reads or
  /// changes the simulation (poses, velocities, forces, drives, contacts, adding or removing,
  /// pictures), on the scene or on one of its handles, throws partsim::Error instead of
  /// racing; reading the description (names, counts, the configuration) does not. Hold a Use
  /// to keep other threads out across several calls. Re-entrant on its thread.
  class Use {
   public:
    /// Waits until no other thread holds the scene.
    explicit Use(const Scene& scene);
    /// Takes the scene only if no other thread holds it: see owns().
    Use(const Scene& scene, std::try_to_lock_t);
    ~Use();
    Use(const Use&) = delete;
    Use& operator=(const Use&) = delete;
    bool owns() const { return owns_; }

   private:
    const Scene* scene_;
    bool owns_ = false;
  };

  // Internals used by the handles; not part of the stable API.
  struct Impl;
  Impl& impl() const;

 private:
  std::unique_ptr<Impl> impl_;
};

/// Shape, visual and mass methods shared by actor and link builders (CRTP: each returns the
/// derived builder so that calls chain). Shapes and visuals read from mesh files are added by
/// the assets layer (partsim/assets/mesh_builders.h: AddVisualFromFile(builder, ...)).
template <typename Derived>
class BodyBuilder {
 public:
  Derived& SetName(const std::string& name);
  /// Box collision with half sizes (m), material (default: the scene's) and density (kg/m^3).
  Derived& AddBoxCollision(const Pose& pose, const Eigen::Vector3d& half_size,
                           const std::optional<PhysicalMaterial>& material = {},
                           double density = 1000.0);
  Derived& AddSphereCollision(const Pose& pose, double radius,
                              const std::optional<PhysicalMaterial>& material = {},
                              double density = 1000.0);
  /// Capsule along the shape's x axis.
  Derived& AddCapsuleCollision(const Pose& pose, double radius, double half_length,
                               const std::optional<PhysicalMaterial>& material = {},
                               double density = 1000.0);
  /// Cylinder along the shape's x axis.
  Derived& AddCylinderCollision(const Pose& pose, double radius, double half_length,
                                const std::optional<PhysicalMaterial>& material = {},
                                double density = 1000.0);
  /// Visuals with a linear RGBA colour and an optional name (e.g. a part name).
  Derived& AddBoxVisual(const Pose& pose, const Eigen::Vector3d& half_size,
                        const Eigen::Vector4f& color = Eigen::Vector4f(0.8, 0.8, 0.8, 1),
                        const std::string& name = "");
  Derived& AddSphereVisual(const Pose& pose, double radius,
                           const Eigen::Vector4f& color = Eigen::Vector4f(0.8, 0.8, 0.8, 1),
                           const std::string& name = "");
  Derived& AddCapsuleVisual(const Pose& pose, double radius, double half_length,
                            const Eigen::Vector4f& color = Eigen::Vector4f(0.8, 0.8, 0.8, 1),
                            const std::string& name = "");
  Derived& AddCylinderVisual(const Pose& pose, double radius, double half_length,
                             const Eigen::Vector4f& color = Eigen::Vector4f(0.8, 0.8, 0.8, 1),
                             const std::string& name = "");
  /// Number of visuals added so far.
  int GetVisualCount();
  /// Replaces the material of visual `index` (in the order added); throws naming the index
  /// when out of range.
  Derived& SetVisualMaterial(int index, const RenderMaterial& material);
  /// Explicit mass (kg), centre-of-mass pose in the body and principal inertia (kg m^2).
  Derived& SetMassAndInertia(double mass, const Pose& cmass_local_pose,
                             const Eigen::Vector3d& inertia);
  /// SAPIEN's collision groups g0..g3 (see CollisionShape::collision_groups) for every collision
  /// shape of the body, those added before and after this call.
  Derived& SetCollisionGroups(const std::array<uint32_t, 4>& groups);

 protected:
  /// Gives the shapes of `body` the groups of SetCollisionGroups, if it was called.
  void ApplyCollisionGroups(BodyDesc& body) const;

 private:
  BodyDesc& body() { return static_cast<Derived*>(this)->Body(); }
  Derived& self() { return *static_cast<Derived*>(this); }
  std::optional<std::array<uint32_t, 4>> collision_groups_;
};

/// Builds an actor piece by piece (SAPIEN's ActorBuilder).
class ActorBuilder : public BodyBuilder<ActorBuilder> {
 public:
  explicit ActorBuilder(Scene* scene) : scene_(scene) {}

  ActorBuilder& SetInitialPose(const Pose& pose);
  Actor Build(bool kinematic = false);
  Actor BuildKinematic() { return Build(true); }
  Actor BuildStatic();
  const ActorDesc& GetDesc() const { return desc_; }
  BodyDesc& Body() { return desc_; }

 private:
  Scene* scene_;
  ActorDesc desc_;
};

/// Builds one link of an articulation; obtained from ArticulationBuilder::CreateLinkBuilder.
class LinkBuilder : public BodyBuilder<LinkBuilder> {
 public:
  LinkBuilder(ArticulationBuilder* owner, int index) : owner_(owner), index_(index) {}
  int GetIndex() const { return index_; }
  LinkBuilder& SetJointName(const std::string& name);
  /// Joint to the parent: type, limits (lower, upper), frames, friction and damping.
  LinkBuilder& SetJointProperties(JointType type, const Eigen::Vector2d& limits,
                                  const Pose& pose_in_parent, const Pose& pose_in_child,
                                  double friction = 0.0, double damping = 0.0);
  LinkBuilder& SetJointArmature(double armature);
  LinkBuilder& SetScrewPitch(double pitch);
  BodyDesc& Body();

 private:
  friend class ArticulationBuilder;
  LinkDesc& link();
  ArticulationBuilder* owner_;
  int index_;
};

extern template class BodyBuilder<ActorBuilder>;
extern template class BodyBuilder<LinkBuilder>;

/// Builds an articulation link by link (SAPIEN's ArticulationBuilder).
class ArticulationBuilder {
 public:
  explicit ArticulationBuilder(Scene* scene) : scene_(scene) {}
  ArticulationBuilder(const ArticulationBuilder&) = delete;
  ArticulationBuilder(ArticulationBuilder&&) = default;

  ArticulationBuilder& SetName(const std::string& name);
  ArticulationBuilder& SetInitialPose(const Pose& pose);
  /// New link whose parent is `parent` (nullptr for the root). The returned builder stays valid
  /// as long as this ArticulationBuilder.
  LinkBuilder* CreateLinkBuilder(LinkBuilder* parent = nullptr);
  Articulation Build(bool fix_root_link = false);
  Articulation BuildKinematic();
  ArticulationDesc& GetDesc() { return desc_; }

 private:
  friend class LinkBuilder;
  /// The description Build adds: links and joints named, link builders' groups applied.
  ArticulationDesc Finished() const;
  Scene* scene_;
  ArticulationDesc desc_;
  std::vector<std::unique_ptr<LinkBuilder>> link_builders_;
};

}  // namespace partsim
