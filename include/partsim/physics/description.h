// Stage 1 of a world: the editable description that builders, the URDF loader and the asset
// generator produce. Nothing here touches MuJoCo; the compiler (compiler.h) turns a description
// into an mjModel plus partsim's tables.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "partsim/core/constants.h"
#include "partsim/core/pose.h"

namespace partsim {

/// Contact material. MuJoCo has one Coulomb coefficient per contact: partsim uses
/// `static_friction` for it (the larger of the two bodies' values wins), keeps
/// `dynamic_friction` for reference, and maps `restitution` (0..1) to the damping ratio of the
/// contact's spring-damper (0 gives a critically damped, inelastic contact).
struct PhysicalMaterial {
  double static_friction = 0.5;   ///< dimensionless, >= 0
  double dynamic_friction = 0.5;  ///< dimensionless, >= 0
  double restitution = 0.0;       ///< dimensionless, in [0, 1]
};

/// A triangle mesh in metres, in the frame of the shape that holds it.
struct MeshData {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> faces;    ///< triangles, counter-clockwise seen from outside
  std::vector<Eigen::Vector3f> normals;  ///< per vertex; may be empty
  std::vector<Eigen::Vector2f> uvs;      ///< per vertex texture coordinates; may be empty
  std::string source;                    ///< file it came from ("" when built in memory)
  std::string name;                      ///< sub-mesh or node name in its file ("" if none)
};

/// Geometric primitive or mesh. Sizes follow SAPIEN's conventions: a box has half-sizes; capsules
/// and cylinders have `radius` and `half_length` along the shape's local x axis.
enum class ShapeType { kBox, kSphere, kCapsule, kCylinder, kConvexMesh, kPlane };

const char* ShapeTypeName(ShapeType t);

/// A collision shape of an actor or link. A kConvexMesh collides as the convex hull of its
/// vertices.
struct CollisionShape {
  ShapeType type = ShapeType::kBox;
  Pose pose;                                                   ///< X_BS: shape S in body B
  Eigen::Vector3d half_size = Eigen::Vector3d::Constant(0.5);  ///< box half extents (m)
  double radius = 0.5;                                         ///< sphere, capsule, cylinder (m)
  double half_length = 0.5;                  ///< capsule, cylinder, along local x (m)
  std::shared_ptr<const MeshData> mesh;      ///< kConvexMesh: vertices already scaled
  std::optional<PhysicalMaterial> material;  ///< unset: the scene's default material
  double density = 1000.0;                   ///< kg/m^3, > 0
  std::string name;
  /// SAPIEN's collision groups g0..g3: shapes A and B collide when (A.g0 & B.g1 or A.g1 & B.g0)
  /// and not (A.g2 & B.g2 and A.g3 == B.g3). The default collides with everything.
  std::array<uint32_t, 4> collision_groups = {1u, 0xFFFFFFFFu, 0u, 0u};
};

/// Texture and surface parameters for rendering.
struct RenderMaterial {
  Eigen::Vector4f base_color = Eigen::Vector4f(0.8f, 0.8f, 0.8f, 1.0f);  ///< linear RGBA in [0, 1]
  float roughness = 0.8f;
  float metallic = 0.0f;
  std::string diffuse_texture;  ///< absolute path of an image, "" for none
};

/// A visual shape: what cameras see. It plays no part in physics.
struct VisualShape {
  ShapeType type = ShapeType::kBox;
  Pose pose;  ///< X_BV: visual V in body B
  Eigen::Vector3d half_size = Eigen::Vector3d::Constant(0.5);
  double radius = 0.5;
  double half_length = 0.5;
  std::shared_ptr<const MeshData> mesh;  ///< mesh visuals, vertices already scaled
  RenderMaterial material;
  std::string name;  ///< e.g. the part name "handle-15" of a PartNet-Mobility object
};

/// Explicit mass properties. When a body has none, they follow from its collision shapes'
/// volumes and densities.
struct Inertial {
  double mass = 1.0;      ///< kg, > 0
  Pose cmass_local_pose;  ///< centre of mass and principal axes in B
  Eigen::Vector3d inertia = Eigen::Vector3d::Constant(1e-3);  ///< principal moments (kg m^2), > 0
};

/// Shapes and mass properties shared by actors and links.
struct BodyDesc {
  std::string name;
  std::string semantic_label;  ///< part label (e.g. "drawer", "handle"), "" if none
  /// Name of the part in the PartNet hierarchy (mobility_v2.json's "name", e.g. "cabinet_door"),
  /// "" if none.
  std::string partnet_name;
  std::vector<CollisionShape> collisions;
  std::vector<VisualShape> visuals;
  std::optional<Inertial> inertial;
};

/// How an actor moves: static (never), kinematic (moved by the user, pushes others, unaffected
/// by forces) or dynamic (moved by physics).
enum class ActorType { kStatic, kKinematic, kDynamic };

const char* ActorTypeName(ActorType t);

/// A free rigid body (or a static or kinematic one).
struct ActorDesc : BodyDesc {
  ActorType type = ActorType::kDynamic;
  Pose pose;  ///< X_WA at creation
  /// Velocity damping of a dynamic actor (1/s, >= 0), as PhysX's: dv/dt = -linear_damping v and
  /// dw/dt = -angular_damping w, integrated implicitly (stable at any value and step).
  double linear_damping = 0.0;
  double angular_damping = 0.0;
};

/// Joint types. Revolute, continuous and screw joints rotate about the x axis of the joint frame;
/// prismatic joints slide along it. A screw joint translates `pitch` metres along x per radian.
enum class JointType { kFixed, kRevolute, kContinuous, kPrismatic, kScrew };

const char* JointTypeName(JointType t);

/// A PD drive on a joint: force = stiffness (target - q) + damping (velocity_target - qdot),
/// clamped to +-force_limit.
struct DriveDesc {
  double stiffness = 0.0;     ///< N/m or N m/rad, >= 0
  double damping = 0.0;       ///< N s/m or N m s/rad, >= 0
  double force_limit = kInf;  ///< N or N m, > 0
  /// Position target the drive starts with, m or rad. The current target is state, in the
  /// scene's data (Joint/Articulation::SetDriveTarget); a description does not follow it.
  double target = 0.0;
  double velocity_target = 0.0;  ///< velocity target it starts with, m/s or rad/s
};

/// Drives stepped by backward Euler, as PhysX's are: over a step `dt` the drive force is
/// stiffness (target - q') + damping (velocity_target - qdot') at the step's end, q' = q + dt
/// qdot'. That is stiffness (target - q) + damping velocity_target - c qdot' with the velocity gain
/// c = damping + stiffness dt; the engine applies it with qdot in place of qdot' and adds c dt to
/// the joint's inertia (armature), which makes up the difference, c (qdot' - qdot), in the step,
/// constraint solving included. Stable at any gains and step, where a spring taken at q diverges
/// once dt sqrt(stiffness / inertia) > 2 (a stiff drive on a light link at dt = 0.01 s). dt = 0
/// (explicit integrators) gives the plain gains.
double DriveVelocityGain(const DriveDesc& drive, double dt);
/// The inertia (kg or kg m^2) that a backward-Euler drive adds to its joint: dt * velocity gain.
double DriveArmature(const DriveDesc& drive, double dt);

/// The joint that connects a link to its parent. The joint frame J is fixed to the parent at
/// `pose_in_parent` (X_PJ) and to the child at `pose_in_child` (X_CJ); at q = 0 the two coincide.
struct JointDesc {
  std::string name;
  JointType type = JointType::kFixed;
  Pose pose_in_parent;
  Pose pose_in_child;
  double lower = -kInf;   ///< lower limit (m or rad); -inf when unlimited
  double upper = kInf;    ///< upper limit (m or rad); +inf when unlimited
  double friction = 0.0;  ///< dry friction (N or N m), >= 0
  double damping = 0.0;   ///< viscous damping (N s/m or N m s/rad), >= 0
  double armature = 0.0;  ///< added rotor inertia (kg or kg m^2), >= 0
  double pitch = 0.0;     ///< screw joints: metres of translation per radian
  /// Largest effort the joint's actuator gives (N or N m, > 0; URDF <limit effort>): effort
  /// controllers clamp to it. inf: none given.
  double effort_limit = kInf;
  DriveDesc drive;
};

/// A link of an articulation: a body and the joint to its parent (ignored for the root).
struct LinkDesc : BodyDesc {
  int parent = -1;  ///< index of the parent link in ArticulationDesc::links; -1 for the root
  JointDesc joint;
};

/// A coupled joint (URDF mimic): q[joint] = multiplier * q[source] + offset. The coupled joint
/// stays a degree of freedom of its own (its own qpos entry and drive), as in SAPIEN; the engine
/// holds the relation with an equality constraint. A source may not itself be coupled.
struct JointCoupling {
  std::string joint;
  std::string source;
  double multiplier = 1.0;
  double offset = 0.0;
};

/// A tree of links connected by joints, with a single root (links[0] or the one with parent -1).
struct ArticulationDesc {
  std::string name;
  std::vector<LinkDesc> links;  ///< parents come before their children
  bool fix_root = true;         ///< root welded to the world, else free (6 extra dof)
  bool kinematic = false;       ///< link poses follow qpos by forward kinematics
  Pose root_pose;               ///< X_WR at creation
  std::vector<JointCoupling> couplings;
  /// Pairs of link names that never collide with each other (an SRDF's <disable_collisions>,
  /// Articulation::DisableCollision). Links joined by a joint never collide in any case.
  std::vector<std::pair<std::string, std::string>> disabled_collisions;
};

/// Checks a description; throws partsim::Error naming the element at fault. `where` prefixes
/// every message (e.g. a file name).
void Validate(const ActorDesc& actor, const std::string& where = "");
void Validate(const ArticulationDesc& art, const std::string& where = "");
void Validate(const PhysicalMaterial& material, const std::string& where = "");

/// Scales every rotation of the description (root and actor poses, joint frames, shape, visual
/// and inertial poses) to a unit quaternion. Validate accepts any non-zero quaternion as a
/// rotation; the scene stores descriptions normalised so that composing their poses cannot scale
/// positions.
void NormalizeRotations(ActorDesc* actor);
void NormalizeRotations(ArticulationDesc* articulation);

}  // namespace partsim
