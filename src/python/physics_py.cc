// Bindings of the physics subsystem: the scene description, SceneConfig, Scene, the builders and
// the Actor / Articulation / Link / Joint handles, contacts and warnings.
//
// Lifetime: Python holds a Scene through a std::shared_ptr; every builder or handle returned from
// a scene (or from another handle) keeps the object it came from alive, so a handle outlives
// `del scene` safely.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.h"
#include "partsim/assets/mesh_builders.h"
#include "partsim/core/check.h"
#include "partsim/physics/description.h"
#include "partsim/physics/mjcf.h"
#include "partsim/physics/scene.h"

namespace partsim::python {
namespace {

using RowMatrixX3f = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;
using RowMatrixX3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
using RowMatrixX2f = Eigen::Matrix<float, Eigen::Dynamic, 2, Eigen::RowMajor>;

// n x k numpy-friendly copy of a vector of fixed-size Eigen vectors, and back.
template <typename Matrix, typename Vec>
Matrix Stack(const std::vector<Vec>& v) {
  Matrix out(static_cast<Eigen::Index>(v.size()), Vec::RowsAtCompileTime);
  for (size_t i = 0; i < v.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = v[i].transpose();
  return out;
}
template <typename Vec, typename Matrix>
std::vector<Vec> Unstack(const Matrix& m) {
  std::vector<Vec> out(static_cast<size_t>(m.rows()));
  for (Eigen::Index i = 0; i < m.rows(); ++i) out[static_cast<size_t>(i)] = m.row(i).transpose();
  return out;
}

// joint type from its name as JointTypeName() spells it ("revolute", "prismatic", ...)
JointType JointTypeFromName(const std::string& name) {
  std::string known;
  for (JointType t : {JointType::kFixed, JointType::kRevolute, JointType::kContinuous,
                      JointType::kPrismatic, JointType::kScrew}) {
    if (name == JointTypeName(t)) return t;
    known += std::string(known.empty() ? "" : ", ") + JointTypeName(t);
  }
  throw Error("type: unknown joint type '" + name + "' (expected one of " + known + ")");
}

constexpr const char* kColorDoc = "color: linear RGBA in [0, 1]";
const Eigen::Vector4f kGrey(0.8f, 0.8f, 0.8f, 1.0f);

// Collision and visual adders shared by ActorBuilder and LinkBuilder (same C++ signatures).
template <typename Builder, typename PyClass>
void BindShapeAdders(PyClass& c) {
  using Mat = std::optional<PhysicalMaterial>;
  const auto ri = py::return_value_policy::reference_internal;
  c.def("add_box_collision", &Builder::AddBoxCollision, py::arg("pose") = Pose(),
        py::arg("half_size") = Eigen::Vector3d::Ones().eval(), py::arg("material") = py::none(),
        py::arg("density") = 1000.0, ri,
        "Adds a box collision shape at `pose` (in the body) with half extents `half_size` (m); "
        "material None uses the scene default; density in kg/m^3. Returns self.")
      .def("add_sphere_collision", &Builder::AddSphereCollision, py::arg("pose") = Pose(),
           py::arg("radius") = 1.0, py::arg("material") = py::none(), py::arg("density") = 1000.0,
           ri, "Adds a sphere collision shape of `radius` (m). Returns self.")
      .def("add_capsule_collision", &Builder::AddCapsuleCollision, py::arg("pose") = Pose(),
           py::arg("radius") = 1.0, py::arg("half_length") = 1.0, py::arg("material") = py::none(),
           py::arg("density") = 1000.0, ri,
           "Adds a capsule along the shape's local x axis: `radius` and `half_length` (m). "
           "Returns self.")
      .def("add_cylinder_collision", &Builder::AddCylinderCollision, py::arg("pose") = Pose(),
           py::arg("radius") = 1.0, py::arg("half_length") = 1.0, py::arg("material") = py::none(),
           py::arg("density") = 1000.0, ri,
           "Adds a cylinder along the shape's local x axis: `radius` and `half_length` (m). "
           "Returns self.")
      .def("add_convex_collision_from_file", &AddConvexCollisionFromFile<Builder>,
           py::arg("filename"), py::arg("pose") = Pose(),
           py::arg("scale") = Eigen::Vector3d::Ones().eval(), py::arg("material") = py::none(),
           py::arg("density") = 1000.0, ri,
           "Adds the convex hull of a mesh file's vertices, multiplied by `scale`. Returns self.")
      .def("add_box_visual", &Builder::AddBoxVisual, py::arg("pose") = Pose(),
           py::arg("half_size") = Eigen::Vector3d::Ones().eval(), py::arg("color") = kGrey,
           py::arg("name") = "", ri,
           (std::string("Adds a box visual with half extents `half_size` (m); ") + kColorDoc +
            ". Returns self.")
               .c_str())
      .def("add_sphere_visual", &Builder::AddSphereVisual, py::arg("pose") = Pose(),
           py::arg("radius") = 1.0, py::arg("color") = kGrey, py::arg("name") = "", ri,
           "Adds a sphere visual of `radius` (m); color is linear RGBA. Returns self.")
      .def("add_capsule_visual", &Builder::AddCapsuleVisual, py::arg("pose") = Pose(),
           py::arg("radius") = 1.0, py::arg("half_length") = 1.0, py::arg("color") = kGrey,
           py::arg("name") = "", ri,
           "Adds a capsule visual along local x; color is linear RGBA. Returns self.")
      .def("add_cylinder_visual", &Builder::AddCylinderVisual, py::arg("pose") = Pose(),
           py::arg("radius") = 1.0, py::arg("half_length") = 1.0, py::arg("color") = kGrey,
           py::arg("name") = "", ri,
           "Adds a cylinder visual along local x; color is linear RGBA. Returns self.")
      .def("add_visual_from_file", &AddVisualFromFile<Builder>, py::arg("filename"),
           py::arg("pose") = Pose(), py::arg("scale") = Eigen::Vector3d::Ones().eval(),
           py::arg("name") = "", ri,
           "Adds every sub-mesh of a mesh file as visuals, multiplied by `scale`. Returns self.")
      .def("get_visual_count", &Builder::GetVisualCount, "Number of visuals added so far.")
      .def("set_visual_material", &Builder::SetVisualMaterial, py::arg("index"),
           py::arg("material"), ri,
           "Replaces the RenderMaterial of visual `index` (in the order added). Returns self.")
      .def("set_mass_and_inertia", &Builder::SetMassAndInertia, py::arg("mass"),
           py::arg("cmass_local_pose"), py::arg("inertia"), ri,
           "Explicit mass (kg), centre-of-mass pose in the body and principal inertia (3,) "
           "(kg m^2). Returns self.")
      .def("set_collision_groups", &Builder::SetCollisionGroups, py::arg("groups"), ri,
           "SAPIEN's collision groups [g0, g1, g2, g3] (uint32) for every collision shape of "
           "the body, added before or after. Returns self.")
      .def(
          "set_collision_groups",
          [](Builder& self, uint32_t group0, uint32_t group1, uint32_t group2,
             uint32_t group3) -> Builder& {
            return self.SetCollisionGroups({group0, group1, group2, group3});
          },
          py::arg("group0"), py::arg("group1"), py::arg("group2"), py::arg("group3"), ri,
          "Same as set_collision_groups([group0, group1, group2, group3]) with the four uint32 "
          "groups as separate arguments. Returns self.");
}

void BindDescription(py::module_& m) {
  py::class_<PhysicalMaterial>(
      m, "PhysicalMaterial",
      "Contact material: static_friction is MuJoCo's Coulomb coefficient (the larger of two "
      "bodies' wins), dynamic_friction is kept for reference, restitution in [0, 1].")
      .def(py::init([](double static_friction, double dynamic_friction, double restitution) {
             return PhysicalMaterial{static_friction, dynamic_friction, restitution};
           }),
           py::arg("static_friction") = 0.5, py::arg("dynamic_friction") = 0.5,
           py::arg("restitution") = 0.0,
           "Material from friction coefficients (dimensionless, >= 0) and restitution in "
           "[0, 1].")
      .def_readwrite("static_friction", &PhysicalMaterial::static_friction,
                     "Coulomb friction coefficient (dimensionless, >= 0) of MuJoCo's contacts; "
                     "of two touching bodies, the larger value wins.")
      .def_readwrite("dynamic_friction", &PhysicalMaterial::dynamic_friction,
                     "Dynamic friction coefficient (dimensionless, >= 0); kept for reference "
                     "only: MuJoCo has one coefficient per contact, static_friction.")
      .def_readwrite("restitution", &PhysicalMaterial::restitution,
                     "Restitution in [0, 1], mapped to the damping ratio of the contact's "
                     "spring-damper; 0 gives a critically damped, inelastic contact.")
      .def("__repr__", [](const PhysicalMaterial& self) {
        return "PhysicalMaterial(" + FormatNumber(self.static_friction) + ", " +
               FormatNumber(self.dynamic_friction) + ", " + FormatNumber(self.restitution) + ")";
      });

  py::class_<MeshData, std::shared_ptr<MeshData>>(
      m, "MeshData", "A triangle mesh in metres, in the frame of the shape that holds it.")
      .def(py::init<>())
      .def_property(
          "vertices", [](const MeshData& self) { return Stack<RowMatrixX3f>(self.vertices); },
          [](MeshData& self, const RowMatrixX3f& v) {
            self.vertices = Unstack<Eigen::Vector3f>(v);
          },
          "Vertices (n, 3) float32, metres.")
      .def_property(
          "faces", [](const MeshData& self) { return Stack<RowMatrixX3i>(self.faces); },
          [](MeshData& self, const RowMatrixX3i& f) { self.faces = Unstack<Eigen::Vector3i>(f); },
          "Triangles (m, 3) int32, counter-clockwise seen from outside.")
      .def_property(
          "normals", [](const MeshData& self) { return Stack<RowMatrixX3f>(self.normals); },
          [](MeshData& self, const RowMatrixX3f& n) { self.normals = Unstack<Eigen::Vector3f>(n); },
          "Per-vertex normals (n, 3) float32; may be empty.")
      .def_property(
          "uvs", [](const MeshData& self) { return Stack<RowMatrixX2f>(self.uvs); },
          [](MeshData& self, const RowMatrixX2f& uv) { self.uvs = Unstack<Eigen::Vector2f>(uv); },
          "Per-vertex texture coordinates (n, 2) float32; may be empty.")
      .def_readwrite("source", &MeshData::source, "File it came from ('' when built in memory).")
      .def_readwrite("name", &MeshData::name, "Sub-mesh or node name in its file.");

  py::enum_<ShapeType>(m, "ShapeType",
                       "Geometric primitive or mesh. A box has half sizes; capsules and "
                       "cylinders have a radius and a half length along the shape's local x "
                       "axis.")
      .value("BOX", ShapeType::kBox)
      .value("SPHERE", ShapeType::kSphere)
      .value("CAPSULE", ShapeType::kCapsule)
      .value("CYLINDER", ShapeType::kCylinder)
      .value("CONVEX_MESH", ShapeType::kConvexMesh)
      .value("PLANE", ShapeType::kPlane);

  py::class_<CollisionShape>(m, "CollisionShape",
                             "Description of a collision shape of an actor or link; a "
                             "CONVEX_MESH collides as the convex hull of its vertices.")
      .def(py::init<>(), "A 1 m box (half extents 0.5 m) at the body origin, density 1000.")
      .def_readwrite("type", &CollisionShape::type,
                     "ShapeType: which of half_size, radius, half_length and mesh apply.")
      .def_readwrite("pose", &CollisionShape::pose, "X_BS: shape S in body B.")
      .def_readwrite("half_size", &CollisionShape::half_size, "Box half extents (3,), metres.")
      .def_readwrite("radius", &CollisionShape::radius, "Sphere, capsule, cylinder radius (m).")
      .def_readwrite("half_length", &CollisionShape::half_length,
                     "Capsule, cylinder half length along local x (m).")
      .def_property(
          "mesh",
          [](const CollisionShape& self) { return std::const_pointer_cast<MeshData>(self.mesh); },
          [](CollisionShape& self, std::shared_ptr<MeshData> mesh) { self.mesh = std::move(mesh); },
          "CONVEX_MESH: the mesh (vertices already scaled), or None.")
      .def_readwrite("material", &CollisionShape::material, "None: the scene's default.")
      .def_readwrite("density", &CollisionShape::density,
                     "Density in kg/m^3 (> 0); gives the body its mass when it has no "
                     "explicit Inertial.")
      .def_readwrite("collision_groups", &CollisionShape::collision_groups,
                     "SAPIEN's [g0, g1, g2, g3]: shapes A and B collide when (A.g0 & B.g1 or "
                     "A.g1 & B.g0) and not (A.g2 & B.g2 and A.g3 == B.g3).")
      .def_readwrite("name", &CollisionShape::name, "Name of the shape ('' if none).");

  py::class_<RenderMaterial>(m, "RenderMaterial", "Texture and surface parameters for rendering.")
      .def(py::init<>())
      .def_readwrite("base_color", &RenderMaterial::base_color, "Linear RGBA (4,) in [0, 1].")
      .def_readwrite("roughness", &RenderMaterial::roughness,
                     "Surface roughness in [0, 1], float32 (0: mirror-like, 1: matte); "
                     "default 0.8.")
      .def_readwrite("metallic", &RenderMaterial::metallic,
                     "Metalness in [0, 1], float32 (0: dielectric, 1: metal); default 0.")
      .def_readwrite("diffuse_texture", &RenderMaterial::diffuse_texture,
                     "Absolute path of an image, '' for none.");

  py::class_<VisualShape>(m, "VisualShape",
                          "Description of a visual shape: what cameras see; it plays no part "
                          "in physics.")
      .def(py::init<>(), "A 1 m grey box (half extents 0.5 m) at the body origin.")
      .def_readwrite("type", &VisualShape::type,
                     "ShapeType; mesh visuals are CONVEX_MESH with `mesh` set.")
      .def_readwrite("pose", &VisualShape::pose, "X_BV: visual V in body B.")
      .def_readwrite("half_size", &VisualShape::half_size, "Box half extents (3,), metres.")
      .def_readwrite("radius", &VisualShape::radius, "Sphere, capsule and cylinder radius (m).")
      .def_readwrite("half_length", &VisualShape::half_length,
                     "Capsule and cylinder half length along the local x axis (m).")
      .def_property(
          "mesh",
          [](const VisualShape& self) { return std::const_pointer_cast<MeshData>(self.mesh); },
          [](VisualShape& self, std::shared_ptr<MeshData> mesh) { self.mesh = std::move(mesh); },
          "Mesh visuals: the mesh (vertices already scaled), or None.")
      .def_readwrite("material", &VisualShape::material,
                     "RenderMaterial: base colour, roughness, metallic and texture.")
      .def_readwrite("name", &VisualShape::name,
                     "Visual name, e.g. the part name 'handle-15' of a PartNet-Mobility object "
                     "('' if none).");

  py::class_<Inertial>(m, "Inertial", "Explicit mass properties of a body.")
      .def(py::init<>())
      .def_readwrite("mass", &Inertial::mass, "Mass in kg, > 0.")
      .def_readwrite("cmass_local_pose", &Inertial::cmass_local_pose,
                     "Centre of mass and principal axes in the body frame.")
      .def_readwrite("inertia", &Inertial::inertia, "Principal moments (3,), kg m^2.");

  py::class_<BodyDesc>(m, "BodyDesc",
                       "Shapes and mass properties shared by actors and links. List attributes "
                       "are copies: assign a whole list to change them.")
      .def(py::init<>())
      .def_readwrite("name", &BodyDesc::name, "Name of the actor or link.")
      .def_readwrite("semantic_label", &BodyDesc::semantic_label,
                     "Part label (e.g. \"drawer\"), \"\" if none.")
      .def_readwrite("partnet_name", &BodyDesc::partnet_name,
                     "Name of the part in the PartNet hierarchy (mobility_v2.json's \"name\", "
                     "e.g. \"cabinet_door\"), \"\" if none.")
      .def_readwrite("collisions", &BodyDesc::collisions,
                     "list of CollisionShape (a copy: assign a whole list to change it).")
      .def_readwrite("visuals", &BodyDesc::visuals,
                     "list of VisualShape (a copy: assign a whole list to change it).")
      .def_readwrite("inertial", &BodyDesc::inertial, "None: from the collision shapes.");

  py::enum_<ActorType>(m, "ActorType",
                       "How an actor moves: STATIC never, KINEMATIC when the user moves it (it "
                       "pushes others and forces do not move it), DYNAMIC by physics.")
      .value("STATIC", ActorType::kStatic)
      .value("KINEMATIC", ActorType::kKinematic)
      .value("DYNAMIC", ActorType::kDynamic);

  py::class_<ActorDesc, BodyDesc>(m, "ActorDesc", "Description of a free rigid body.")
      .def(py::init<>())
      .def_readwrite("type", &ActorDesc::type, "ActorType (default DYNAMIC).")
      .def_readwrite("pose", &ActorDesc::pose, "X_WA at creation.")
      .def_readwrite("linear_damping", &ActorDesc::linear_damping,
                     "Velocity damping (1/s, >= 0): dv/dt = -linear_damping v.")
      .def_readwrite("angular_damping", &ActorDesc::angular_damping,
                     "Angular velocity damping (1/s, >= 0): dw/dt = -angular_damping w.");

  py::enum_<JointType>(m, "JointType",
                       "Joint types; revolute, continuous and screw joints rotate about the joint "
                       "frame's x axis, prismatic joints slide along it.")
      .value("FIXED", JointType::kFixed)
      .value("REVOLUTE", JointType::kRevolute)
      .value("CONTINUOUS", JointType::kContinuous)
      .value("PRISMATIC", JointType::kPrismatic)
      .value("SCREW", JointType::kScrew);

  py::class_<DriveDesc>(m, "DriveDesc",
                        "PD drive: force = stiffness (target - q) + damping (velocity_target - "
                        "qdot), clamped to +-force_limit.")
      .def(py::init<>())
      .def_readwrite("stiffness", &DriveDesc::stiffness, "Stiffness (N/m or N m/rad, >= 0).")
      .def_readwrite("damping", &DriveDesc::damping, "Damping (N s/m or N m s/rad, >= 0).")
      .def_readwrite("force_limit", &DriveDesc::force_limit,
                     "Largest drive force (N or N m, > 0); inf: no clamp.")
      .def_readwrite("target", &DriveDesc::target,
                     "Position target the drive starts with (m or rad); the current target is "
                     "state (Joint.get_drive_target).")
      .def_readwrite("velocity_target", &DriveDesc::velocity_target,
                     "Velocity target the drive starts with (m/s or rad/s).");

  py::class_<JointDesc>(m, "JointDesc",
                        "The joint that connects a link to its parent. The joint frame J is "
                        "fixed to the parent at pose_in_parent and to the child at "
                        "pose_in_child; at q = 0 the two coincide.")
      .def(py::init<>())
      .def_readwrite("name", &JointDesc::name, "Joint name.")
      .def_readwrite("type", &JointDesc::type,
                     "JointType (default FIXED); the joint moves along or about J's x axis.")
      .def_readwrite("pose_in_parent", &JointDesc::pose_in_parent,
                     "X_PJ: the joint frame J in the parent link's frame P.")
      .def_readwrite("pose_in_child", &JointDesc::pose_in_child,
                     "X_CJ: the joint frame J in the child link's frame C.")
      .def_readwrite("lower", &JointDesc::lower, "m or rad; -inf when unlimited.")
      .def_readwrite("upper", &JointDesc::upper, "m or rad; +inf when unlimited.")
      .def_readwrite("friction", &JointDesc::friction, "Dry friction (N or N m, >= 0).")
      .def_readwrite("damping", &JointDesc::damping, "Viscous damping (N s/m or N m s/rad, >= 0).")
      .def_readwrite("armature", &JointDesc::armature, "Added rotor inertia (kg or kg m^2, >= 0).")
      .def_readwrite("pitch", &JointDesc::pitch, "Screw joints: metres per radian.")
      .def_readwrite("effort_limit", &JointDesc::effort_limit,
                     "N or N m: the actuator's largest effort (URDF <limit effort>); effort "
                     "controllers clamp to it. inf: none given.")
      .def_readwrite("drive", &JointDesc::drive,
                     "DriveDesc: the joint's PD drive (zero gains by default: no drive).");

  py::class_<LinkDesc, BodyDesc>(m, "LinkDesc", "A link: a body and the joint to its parent.")
      .def(py::init<>())
      .def_readwrite("parent", &LinkDesc::parent, "Index of the parent link; -1 for the root.")
      .def_readwrite("joint", &LinkDesc::joint,
                     "JointDesc of the joint to the parent (ignored for the root).");

  py::class_<JointCoupling>(m, "JointCoupling",
                            "A coupled joint (URDF mimic): q[joint] = multiplier * q[source] + "
                            "offset.")
      .def(py::init<>())
      .def_readwrite("joint", &JointCoupling::joint,
                     "Name of the coupled joint; it keeps its own dof, qpos entry and drive.")
      .def_readwrite("source", &JointCoupling::source,
                     "Name of the joint it follows; a source may not itself be coupled.")
      .def_readwrite("multiplier", &JointCoupling::multiplier,
                     "Factor on the source's position (joint unit per source unit).")
      .def_readwrite("offset", &JointCoupling::offset,
                     "Added to multiplier * q[source], in the coupled joint's unit (m or rad).");

  py::class_<ArticulationDesc>(m, "ArticulationDesc",
                               "A tree of links connected by joints. List attributes are copies: "
                               "assign a whole list to change them.")
      .def(py::init<>())
      .def_readwrite("name", &ArticulationDesc::name, "Articulation name.")
      .def_readwrite("links", &ArticulationDesc::links, "Parents come before their children.")
      .def_readwrite("fix_root", &ArticulationDesc::fix_root,
                     "True (default): the root link is welded to the world; False: a free root "
                     "with 6 extra dof that are not in qpos.")
      .def_readwrite("kinematic", &ArticulationDesc::kinematic,
                     "True: link poses follow qpos by forward kinematics, no dynamics.")
      .def_readwrite("root_pose", &ArticulationDesc::root_pose, "X_WR at creation.")
      .def_readwrite("couplings", &ArticulationDesc::couplings,
                     "list of JointCoupling (URDF mimic joints); a copy: assign a whole list.")
      .def_readwrite("disabled_collisions", &ArticulationDesc::disabled_collisions,
                     "Pairs of link names that never collide with each other.");

  m.def("validate", py::overload_cast<const ActorDesc&, const std::string&>(&Validate),
        py::arg("actor"), py::arg("where") = "",
        "Checks an actor description; raises PartsimError naming the element at fault.");
  m.def("validate", py::overload_cast<const ArticulationDesc&, const std::string&>(&Validate),
        py::arg("art"), py::arg("where") = "",
        "Checks an articulation description; raises PartsimError naming the element at fault.");
}

void BindHandles(py::module_& m) {
  const auto ka = py::keep_alive<0, 1>();

  // registered before Actor and Link, which return it
  py::class_<Shape> shape(m, "Shape",
                          "Handle to one collision shape of an actor or a link (SAPIEN's "
                          "CollisionShape); its description is get_desc().");
  shape.def("get_index", &Shape::GetIndex, "Index in the body's collisions.")
      .def("get_desc", &Shape::GetDesc, "A copy of the shape's description.")
      .def("get_collision_groups", &Shape::GetCollisionGroups,
           "SAPIEN's collision groups [g0, g1, g2, g3].")
      .def("set_collision_groups", &Shape::SetCollisionGroups, py::arg("groups"),
           "SAPIEN's collision groups [g0, g1, g2, g3] (uint32): shapes A and B collide when "
           "(A.g0 & B.g1 or A.g1 & B.g0) and not (A.g2 & B.g2 and A.g3 == B.g3). The scene's "
           "state is kept.")
      .def(
          "set_collision_groups",
          [](Shape& self, uint32_t group0, uint32_t group1, uint32_t group2, uint32_t group3) {
            self.SetCollisionGroups({group0, group1, group2, group3});
          },
          py::arg("group0"), py::arg("group1"), py::arg("group2"), py::arg("group3"),
          "Same as set_collision_groups([group0, group1, group2, group3]) with the four uint32 "
          "groups as separate arguments.")
      .def("__repr__",
           [](const Shape& self) { return "<Shape " + std::to_string(self.GetIndex()) + ">"; });

  py::class_<Actor>(m, "Actor", "Handle to an actor; valid until the actor is removed.")
      .def("get_id", &Actor::GetId,
           "Scene-wide id (unique among actors, articulations and links): also the actor's "
           "entity id in segmentation pictures.")
      .def("get_name", &Actor::GetName, "The actor's name.")
      .def("set_name", &Actor::SetName, py::arg("name"), "Renames the actor.")
      .def_property_readonly("name", &Actor::GetName, "The actor's name.")
      .def_property_readonly("type", &Actor::GetType, "ActorType: STATIC, KINEMATIC or DYNAMIC.")
      .def("get_pose", &Actor::GetPose, "X_WA: the actor's frame in the world.")
      .def("set_pose", &Actor::SetPose, py::arg("pose"),
           "Teleports the actor to X_WA. A static actor is moved in the model: meant for "
           "placing it before simulating (what rests on it is not carried along).")
      .def("get_velocity", &Actor::GetVelocity,
           "World-frame linear velocity (3,) of the actor's origin, m/s.")
      .def("set_velocity", &Actor::SetVelocity, py::arg("v"),
           "Sets the world-frame linear velocity (3,) of the actor's origin, m/s; raises "
           "PartsimError for an actor that is not dynamic or a non-finite v.")
      .def("get_angular_velocity", &Actor::GetAngularVelocity,
           "World-frame angular velocity (3,), rad/s.")
      .def("set_angular_velocity", &Actor::SetAngularVelocity, py::arg("w"),
           "Sets the world-frame angular velocity (3,), rad/s; raises PartsimError for an "
           "actor that is not dynamic or a non-finite w.")
      .def("get_mass", &Actor::GetMass, "Mass (kg) as compiled.")
      .def("get_inertia", &Actor::GetInertia,
           "Principal moments (3,), kg m^2, as compiled: given, or computed by MuJoCo from the "
           "shapes (meshes from their convex hulls).")
      .def("get_cmass_pose", &Actor::GetCMassPose,
           "X_WC: the centre of mass frame (principal axes) in the world.")
      .def("set_damping", &Actor::SetDamping, py::arg("linear"), py::arg("angular"),
           "Velocity damping (1/s, >= 0) of a dynamic actor, as PhysX's: dv/dt = -linear v, "
           "dw/dt = -angular w; integrated implicitly.")
      .def("get_linear_damping", &Actor::GetLinearDamping, "Linear velocity damping (1/s).")
      .def("get_angular_damping", &Actor::GetAngularDamping, "Angular velocity damping (1/s).")
      .def("add_force_at_point", &Actor::AddForceAtPoint, py::arg("force"), py::arg("point"),
           "Adds a world-frame force (N) at a world point (m) for the next step.")
      .def("add_force_torque", &Actor::AddForceTorque, py::arg("force"), py::arg("torque"),
           "Adds a world-frame force (N) at the centre of mass and a torque (N m) for the next "
           "step.")
      .def("get_desc", &Actor::GetDesc, "A copy of the actor's description.")
      .def(
          "get_collision_shapes",
          [](py::object self) {
            return HandleList(self.cast<const Actor&>().GetCollisionShapes(), self);
          },
          "One Shape per collision shape, in the order of get_desc().collisions.")
      .def("__eq__", &Actor::operator==)
      .def("__hash__",
           [](const Actor& self) {
             return py::hash(
                 py::make_tuple(reinterpret_cast<uintptr_t>(self.GetScene()), self.GetId()));
           })
      .def("__repr__", [](const Actor& self) { return "<Actor '" + self.GetName() + "'>"; });

  py::class_<Link>(m, "Link", "Handle to a link of an articulation.")
      .def("get_name", &Link::GetName, "The link's name.")
      .def_property_readonly("name", &Link::GetName, "The link's name.")
      .def("get_index", &Link::GetIndex, "Index in the articulation (0 is the root).")
      .def("get_id", &Link::GetId,
           "Scene-wide id (unique among actors, articulations and links): the link's entity id "
           "in segmentation pictures.")
      .def("get_articulation_id", &Link::GetArticulationId,
           "Id of the articulation the link belongs to (Articulation.get_id()).")
      .def("get_parent_index", &Link::GetParentIndex, "Parent link index; -1 for the root.")
      .def("get_pose", &Link::GetPose, "X_WL: the link frame in the world.")
      .def("get_cmass_pose", &Link::GetCMassPose,
           "X_WC: centre of mass frame (principal axes) in the world.")
      .def("get_velocity", &Link::GetVelocity, "World-frame velocity (3,) at the origin, m/s.")
      .def("get_angular_velocity", &Link::GetAngularVelocity,
           "World-frame angular velocity (3,), rad/s.")
      .def("get_mass", &Link::GetMass, "Mass (kg) as compiled.")
      .def("get_inertia", &Link::GetInertia, "Principal moments (3,), kg m^2.")
      .def("add_force_at_point", &Link::AddForceAtPoint, py::arg("force"), py::arg("point"),
           "Adds a world-frame force (N) at a world point (m) for the next step.")
      .def("get_desc", &Link::GetDesc, "A copy of the link's description.")
      .def(
          "get_collision_shapes",
          [](py::object self) {
            return HandleList(self.cast<const Link&>().GetCollisionShapes(), self);
          },
          "One Shape per collision shape, in the order of get_desc().collisions.")
      .def(
          "get_semantic_label", [](const Link& self) { return self.GetDesc().semantic_label; },
          "The part label (semantics.txt's vocabulary for PartNet-Mobility objects: "
          "\"drawer\", \"rotation_door\", ...), \"\" if none.")
      .def(
          "get_partnet_name", [](const Link& self) { return self.GetDesc().partnet_name; },
          "The PartNet part name (mobility_v2.json's \"name\"), \"\" if none.")
      .def("__repr__", [](const Link& self) { return "<Link '" + self.GetName() + "'>"; });

  py::class_<Joint>(m, "Joint",
                    "Handle to the joint between a link and its parent (joint index == child "
                    "link index).")
      .def("get_name", &Joint::GetName, "The joint's name.")
      .def_property_readonly("name", &Joint::GetName, "The joint's name.")
      .def_property_readonly("type", &Joint::GetType,
                             "JointType: FIXED, REVOLUTE, CONTINUOUS, PRISMATIC or SCREW.")
      .def("get_index", &Joint::GetIndex,
           "Index of the joint in its articulation: its child link's index (>= 1).")
      .def("get_dof", &Joint::GetDof, "0 for a fixed joint, else 1 (coupled joints included).")
      .def("get_dof_index", &Joint::GetDofIndex, "Index in qpos, -1 if the joint has no dof.")
      .def("get_parent_link", &Joint::GetParentLink, ka, "The parent link's handle.")
      .def("get_child_link", &Joint::GetChildLink, ka,
           "The child link's handle (the link the joint moves).")
      .def("get_pose_in_parent", &Joint::GetPoseInParent,
           "X_PJ: the joint frame in the parent link's frame.")
      .def("get_pose_in_child", &Joint::GetPoseInChild,
           "X_CJ: the joint frame in the child link's frame.")
      .def("get_global_pose", &Joint::GetGlobalPose, "X_WJ: the joint frame in the world.")
      .def("get_global_axis", &Joint::GetGlobalAxis, "Joint axis (3,) in world coordinates.")
      .def("get_limits", &Joint::GetLimits, "(lower, upper) as (2,); +-inf when unlimited.")
      .def("set_limits", &Joint::SetLimits, py::arg("lower"), py::arg("upper"),
           "Sets the limits (m or rad, +-inf for none), keeping the scene's state; raises "
           "PartsimError when lower > upper or either is NaN, and for a fixed or continuous "
           "joint.")
      .def("get_friction", &Joint::GetFriction, "Dry friction (N or N m).")
      .def("get_damping", &Joint::GetDamping, "Viscous damping (N s/m or N m s/rad).")
      .def("get_armature", &Joint::GetArmature, "Added rotor inertia (kg or kg m^2).")
      .def("set_friction", &Joint::SetFriction, py::arg("friction"),
           "Sets dry friction (N or N m, >= 0).")
      .def("set_damping", &Joint::SetDamping, py::arg("damping"),
           "Sets viscous damping (N s/m or N m s/rad, >= 0).")
      .def("set_armature", &Joint::SetArmature, py::arg("armature"),
           "Sets added rotor inertia (kg or kg m^2, >= 0).")
      .def("get_pitch", &Joint::GetPitch, "Screw pitch, metres per radian.")
      .def("set_drive_property", &Joint::SetDriveProperty, py::arg("stiffness"), py::arg("damping"),
           py::arg("force_limit") = kInf,
           "PD drive: force = stiffness (target - q) + damping (velocity_target - qdot), "
           "clamped to +-force_limit.")
      .def("set_drive_target", &Joint::SetDriveTarget, py::arg("target"),
           "Sets the drive's position target (m or rad).")
      .def("set_drive_velocity_target", &Joint::SetDriveVelocityTarget, py::arg("velocity"),
           "Sets the drive's velocity target (m/s or rad/s).")
      .def("get_drive_target", &Joint::GetDriveTarget, "The drive's position target (m or rad).")
      .def("get_drive_velocity_target", &Joint::GetDriveVelocityTarget,
           "The drive's velocity target (m/s or rad/s).")
      .def("get_drive_stiffness", &Joint::GetDriveStiffness,
           "The drive's stiffness (N/m or N m/rad).")
      .def("get_drive_damping", &Joint::GetDriveDamping,
           "The drive's damping (N s/m or N m s/rad).")
      .def("get_drive_force_limit", &Joint::GetDriveForceLimit,
           "The drive's force limit (N or N m); inf when unclamped.")
      .def("get_qpos", &Joint::GetQpos, "Joint position (m or rad).")
      .def("get_qvel", &Joint::GetQvel, "Joint velocity (m/s or rad/s).")
      .def("get_desc", &Joint::GetDesc, "A copy of the joint's description.")
      .def("__repr__", [](const Joint& self) { return "<Joint '" + self.GetName() + "'>"; });

  py::class_<Articulation>(m, "Articulation",
                           "Handle to an articulation. Joint-space arrays have one entry per "
                           "dof, ordered as get_active_joints(); a free root's 6 dof are not "
                           "included.")
      .def("get_id", &Articulation::GetId,
           "Scene-wide id, unique among actors, articulations and links.")
      .def("get_name", &Articulation::GetName, "The articulation's name.")
      .def("set_name", &Articulation::SetName, py::arg("name"), "Renames the articulation.")
      .def_property_readonly("name", &Articulation::GetName, "The articulation's name.")
      .def("is_kinematic", &Articulation::IsKinematic,
           "True when link poses follow qpos by forward kinematics (no dynamics).")
      .def("has_fixed_root", &Articulation::HasFixedRoot,
           "True when the root link is welded to the world, False for a free root.")
      .def_property_readonly("dof", &Articulation::Dof,
                             "Degrees of freedom: the length of qpos (a free root's 6 excluded).")
      .def("get_dof", &Articulation::Dof,
           "Degrees of freedom: the length of qpos (a free root's 6 excluded).")
      .def(
          "get_links",
          [](py::object self) {
            return HandleList(self.cast<const Articulation&>().GetLinks(), self);
          },
          "Every link's handle, in index order (0 is the root; parents before children).")
      .def(
          "get_joints",
          [](py::object self) {
            return HandleList(self.cast<const Articulation&>().GetJoints(), self);
          },
          "One joint per non-root link.")
      .def(
          "get_active_joints",
          [](py::object self) {
            return HandleList(self.cast<const Articulation&>().GetActiveJoints(), self);
          },
          "Joints with a dof, in qpos order.")
      .def("get_link", &Articulation::GetLink, py::arg("index"), ka,
           "Link `index` (0 is the root); raises PartsimIndexError when out of range.")
      .def("get_joint", &Articulation::GetJoint, py::arg("index"), ka,
           "The joint above link `index` (1 .. number of links - 1); raises PartsimIndexError "
           "when out of range.")
      .def("find_link_by_name", &Articulation::FindLinkByName, py::arg("name"), ka,
           "The link named `name`; raises PartsimError when there is none.")
      .def("find_joint_by_name", &Articulation::FindJointByName, py::arg("name"), ka,
           "The joint named `name`; raises PartsimError when there is none.")
      .def("get_qpos", &Articulation::GetQpos, "Joint positions (dof,), m or rad.")
      .def("set_qpos", &Articulation::SetQpos, py::arg("qpos"),
           "Sets joint positions (dof,), m or rad; a coupled (mimic) joint's entry is replaced "
           "by multiplier * qpos[source] + offset. Raises PartsimError on a wrong length.")
      .def("get_qvel", &Articulation::GetQvel, "Joint velocities (dof,), m/s or rad/s.")
      .def("set_qvel", &Articulation::SetQvel, py::arg("qvel"),
           "Sets joint velocities (dof,), m/s or rad/s; a coupled joint's entry is replaced by "
           "multiplier * qvel[source]. Raises PartsimError on a wrong length.")
      .def("get_qacc", &Articulation::GetQacc, "Joint accelerations (dof,) of the last step.")
      .def("set_qacc", &Articulation::SetQacc, py::arg("qacc"),
           "Sets accelerations; they only seed the solver's warm start.")
      .def("get_qf", &Articulation::GetQf, "User generalized forces (dof,), N or N m.")
      .def("set_qf", &Articulation::SetQf, py::arg("qf"),
           "Generalized forces (dof,); they persist until changed.")
      .def("get_qlimits", &Articulation::GetQlimits, "(dof, 2) array of (lower, upper).")
      .def("set_qlimits", &Articulation::SetQlimits, py::arg("limits"),
           "Sets (dof, 2) limits (lower, upper), m or rad; rows of continuous joints are "
           "ignored. Raises PartsimError on a wrong row count or lower > upper. Recompiles, "
           "keeping the state.")
      .def("get_root_pose", &Articulation::GetRootPose, "X_WR: the root link's frame in the world.")
      .def("set_root_pose", &Articulation::SetRootPose, py::arg("pose"),
           "Moves the root to X_WR (a fixed root's weld to the world moves with it).")
      .def("get_root_velocity", &Articulation::GetRootVelocity,
           "World-frame linear velocity (3,) of a free root, m/s; zeros for a fixed root.")
      .def("get_root_angular_velocity", &Articulation::GetRootAngularVelocity,
           "World-frame angular velocity (3,) of a free root, rad/s; zeros for a fixed root.")
      .def("set_root_velocity", &Articulation::SetRootVelocity, py::arg("v"),
           "Sets a free root's world-frame linear velocity (3,), m/s; raises PartsimError for "
           "a fixed root.")
      .def("set_root_angular_velocity", &Articulation::SetRootAngularVelocity, py::arg("w"),
           "Sets a free root's world-frame angular velocity (3,), rad/s; raises PartsimError "
           "for a fixed root.")
      .def("set_drive_target", &Articulation::SetDriveTarget, py::arg("target"),
           "Drive position targets (dof,), m or rad.")
      .def("set_drive_velocity_target", &Articulation::SetDriveVelocityTarget, py::arg("velocity"),
           "Drive velocity targets (dof,), m/s or rad/s.")
      .def("get_drive_target", &Articulation::GetDriveTarget,
           "Drive position targets (dof,), m or rad.")
      .def("get_drive_velocity_target", &Articulation::GetDriveVelocityTarget,
           "Drive velocity targets (dof,), m/s or rad/s.")
      .def("set_drive_property", &Articulation::SetDriveProperty, py::arg("stiffness"),
           py::arg("damping"), py::arg("force_limit") = kInf,
           "Same drive parameters on every active joint.")
      .def("compute_passive_force", &Articulation::ComputePassiveForce, py::arg("gravity") = true,
           py::arg("coriolis_and_centrifugal") = true, py::arg("external") = true,
           "Generalized force (dof,) that cancels gravity, Coriolis and centrifugal forces and "
           "the external forces added to the links for the next step, each when asked, at the "
           "current state: set_qf(it) holds the articulation still.")
      .def("compute_forward_dynamics", &Articulation::ComputeForwardDynamics, py::arg("qf"),
           "Accelerations (dof,) from generalized forces qf, without contacts, limits or "
           "drives.")
      .def("compute_inverse_dynamics", &Articulation::ComputeInverseDynamics, py::arg("qacc"),
           "Generalized forces (dof,) that produce accelerations qacc: M qacc + bias.")
      .def("compute_manipulator_inertia_matrix", &Articulation::ComputeManipulatorInertiaMatrix,
           "Mass matrix (dof, dof).")
      .def("compute_link_jacobian", &Articulation::ComputeLinkJacobian, py::arg("index"),
           "World-frame Jacobian (6, dof) of link `index` at its origin, rows (linear; "
           "angular).")
      .def("compute_world_cartesian_jacobian", &Articulation::ComputeWorldCartesianJacobian,
           "Stacked link Jacobians (6 nlinks, dof).")
      .def("get_link_incoming_joint_forces", &Articulation::GetLinkIncomingJointForces,
           "(nlinks, 6): for each link, the spatial force its parent exerts on it through its "
           "joint, from the forward dynamics of the current state: force (N) then torque (N m) "
           "about the joint's origin, in the joint's frame on the child, as PhysX's incoming "
           "joint force; the root's row is zero.")
      .def("disable_collision", &Articulation::DisableCollision, py::arg("link_a"),
           py::arg("link_b"),
           "The two links of this articulation never collide with each other from now on "
           "(links joined by a joint never do); the scene's state is kept.")
      .def("get_desc", &Articulation::GetDesc, "A copy of the articulation's description.")
      .def("__eq__", &Articulation::operator==)
      .def("__hash__",
           [](const Articulation& self) {
             return py::hash(
                 py::make_tuple(reinterpret_cast<uintptr_t>(self.GetScene()), self.GetId()));
           })
      .def("__repr__", [](const Articulation& self) {
        return "<Articulation '" + self.GetName() + "' dof=" + std::to_string(self.Dof()) + ">";
      });
}

void BindContacts(py::module_& m) {
  py::class_<ContactPoint>(m, "ContactPoint", "One contact point between two bodies.")
      .def_readonly("position", &ContactPoint::position, "World position (3,), m.")
      .def_readonly("normal", &ContactPoint::normal,
                    "World normal (3,), from body1 into body0 (as SAPIEN's).")
      .def_readonly("impulse", &ContactPoint::impulse,
                    "World impulse (3,) on body0 (SAPIEN's actor0) over the last step, N s.")
      .def_readonly("force", &ContactPoint::force, "World force (3,) on body0, N.")
      .def_readonly("separation", &ContactPoint::separation,
                    "Signed distance (m), negative when penetrating.");

  py::class_<ContactBody> body(m, "ContactBody",
                               "What a contact touches: an actor or a link, and which shape.");
  py::enum_<ContactBody::Kind>(body, "Kind", "Whether a ContactBody is an actor or a link.")
      .value("ACTOR", ContactBody::Kind::kActor)
      .value("LINK", ContactBody::Kind::kLink);
  body.def_readonly("kind", &ContactBody::kind,
                    "ContactBody.Kind: ACTOR (actor_id is set) or LINK (articulation_id and "
                    "link_index are set).")
      .def_readonly("actor_id", &ContactBody::actor_id,
                    "Kind.ACTOR: the actor's id (-1 for a link).")
      .def_readonly("articulation_id", &ContactBody::articulation_id,
                    "Kind.LINK: the articulation's id (-1 for an actor).")
      .def_readonly("link_index", &ContactBody::link_index,
                    "Kind.LINK: the link's index in its articulation (-1 for an actor).")
      .def_readonly("shape_index", &ContactBody::shape_index, "Index in the body's collisions.")
      .def_readonly("name", &ContactBody::name, "Actor or link name.");

  py::class_<Contact>(m, "Contact",
                      "The contact between two shapes, with its points. When one of the two is "
                      "a static actor (the ground, a wall) and the other is not, the static one "
                      "is body1.")
      .def_readonly("body0", &Contact::body0, "ContactBody: the first body.")
      .def_readonly("body1", &Contact::body1,
                    "ContactBody: the second body (the static one, if only one is).")
      .def_readonly("points", &Contact::points, "list of ContactPoint.")
      .def("__repr__", [](const Contact& self) {
        return "<Contact '" + self.body0.name + "' - '" + self.body1.name + "', " +
               std::to_string(self.points.size()) + " points>";
      });

  py::class_<RayHit>(m, "RayHit", "Where a ray first meets a collision shape (Scene.raycast).")
      .def_readonly("distance", &RayHit::distance, "Along the ray (m).")
      .def_readonly("position", &RayHit::position, "World point hit (3,), m.")
      .def_readonly("normal", &RayHit::normal, "The surface's outward normal (3,), world.")
      .def_readonly("body", &RayHit::body,
                    "ContactBody: the actor or link hit and which of its shapes (an actor id of "
                    "-1 for a geom of an MJCF model that belongs to neither).")
      .def("__repr__", [](const RayHit& self) {
        return "<RayHit '" + self.body.name + "' at " + FormatNumber(self.distance) + " m>";
      });

  py::class_<Warning>(m, "SceneWarning", "A warning recorded during stepping.")
      .def_readonly("time", &Warning::time, "Simulated time (s).")
      .def_readonly("message", &Warning::message,
                    "What happened: a MuJoCo warning, numerical instability (MuJoCo reset the "
                    "state), or a contact buffer that filled and grew.")
      .def("__repr__", [](const Warning& self) {
        return "<Warning t=" + FormatNumber(self.time) + ": " + self.message + ">";
      });
}

void BindBuilders(py::module_& m) {
  const auto ka = py::keep_alive<0, 1>();
  const auto ri = py::return_value_policy::reference_internal;

  py::class_<ActorBuilder> actor_builder(m, "ActorBuilder",
                                         "Builds an actor piece by piece (SAPIEN's ActorBuilder).");
  actor_builder
      .def("set_name", &ActorBuilder::SetName, py::arg("name"), ri,
           "Names the actor. Returns self.")
      .def("set_initial_pose", &ActorBuilder::SetInitialPose, py::arg("pose"), ri,
           "X_WA at creation. Returns self.");
  BindShapeAdders<ActorBuilder>(actor_builder);
  actor_builder
      .def("add_multiple_convex_collisions_from_file",
           &AddMultipleConvexCollisionsFromFile<ActorBuilder>, py::arg("filename"),
           py::arg("pose") = Pose(), py::arg("scale") = Eigen::Vector3d::Ones().eval(),
           py::arg("material") = py::none(), py::arg("density") = 1000.0, ri,
           "One convex piece per sub-mesh (or connected component) of a mesh file. Returns "
           "self.")
      .def(
          "add_convex_collision_from_mesh",
          [](ActorBuilder& self, std::shared_ptr<MeshData> mesh, const Pose& pose,
             const std::optional<PhysicalMaterial>& material, double density) -> ActorBuilder& {
            return AddConvexCollisionFromMesh(self, std::move(mesh), pose, material, density);
          },
          py::arg("mesh"), py::arg("pose") = Pose(), py::arg("material") = py::none(),
          py::arg("density") = 1000.0, ri,
          "Adds the convex hull of a MeshData's vertices. Returns self.")
      .def("build", &ActorBuilder::Build, py::arg("kinematic") = false, ka,
           "Adds the actor to the scene (dynamic, or kinematic) and returns its handle.")
      .def("build_kinematic", &ActorBuilder::BuildKinematic, ka,
           "Adds the actor as kinematic (moved by set_pose only; it pushes dynamic bodies and "
           "forces do not move it) and returns its handle.")
      .def("build_static", &ActorBuilder::BuildStatic, ka,
           "Adds the actor as static (it never moves while simulating) and returns its "
           "handle.")
      .def("get_desc", &ActorBuilder::GetDesc, "A copy of the description built so far.");

  py::class_<LinkBuilder> link_builder(
      m, "LinkBuilder", "Builds one link; owned by the ArticulationBuilder that created it.");
  link_builder
      .def("get_index", &LinkBuilder::GetIndex,
           "Index of the link in the articulation (0 for the first one created).")
      .def("set_name", &LinkBuilder::SetName, py::arg("name"), ri, "Names the link. Returns self.")
      .def("set_joint_name", &LinkBuilder::SetJointName, py::arg("name"), ri,
           "Names the joint to the parent. Returns self.")
      .def("set_joint_properties", &LinkBuilder::SetJointProperties, py::arg("type"),
           py::arg("limits"), py::arg("pose_in_parent") = Pose(), py::arg("pose_in_child") = Pose(),
           py::arg("friction") = 0.0, py::arg("damping") = 0.0, ri,
           "Joint to the parent: type (JointType or its name: 'fixed', 'revolute', "
           "'continuous', 'prismatic', 'screw'), limits (lower, upper) in m or rad, frames "
           "X_PJ and X_CJ, friction and damping. Returns self.")
      .def(
          "set_joint_properties",
          [](LinkBuilder& self, const std::string& type, const Eigen::Vector2d& limits,
             const Pose& pose_in_parent, const Pose& pose_in_child, double friction,
             double damping) -> LinkBuilder& {
            return self.SetJointProperties(JointTypeFromName(type), limits, pose_in_parent,
                                           pose_in_child, friction, damping);
          },
          py::arg("type"), py::arg("limits"), py::arg("pose_in_parent") = Pose(),
          py::arg("pose_in_child") = Pose(), py::arg("friction") = 0.0, py::arg("damping") = 0.0,
          ri,
          "Same, with the joint type by name: 'fixed', 'revolute', 'continuous', 'prismatic' "
          "or 'screw'; raises PartsimError for another name. Returns self.")
      .def("set_joint_armature", &LinkBuilder::SetJointArmature, py::arg("armature"), ri,
           "Added rotor inertia of the joint (kg or kg m^2, >= 0). Returns self.")
      .def("set_screw_pitch", &LinkBuilder::SetScrewPitch, py::arg("pitch"), ri,
           "Metres per radian. Returns self.");
  BindShapeAdders<LinkBuilder>(link_builder);

  py::class_<ArticulationBuilder>(m, "ArticulationBuilder",
                                  "Builds an articulation link by link (SAPIEN's "
                                  "ArticulationBuilder).")
      .def("set_name", &ArticulationBuilder::SetName, py::arg("name"), ri,
           "Names the articulation. Returns self.")
      .def("set_initial_pose", &ArticulationBuilder::SetInitialPose, py::arg("pose"), ri,
           "X_WR: the root link's pose in the world at creation. Returns self.")
      .def("create_link_builder", &ArticulationBuilder::CreateLinkBuilder,
           py::arg("parent") = nullptr, ri,
           "New link whose parent is `parent` (None for the root); the LinkBuilder stays "
           "owned by this builder.")
      .def("build", &ArticulationBuilder::Build, py::arg("fix_root_link") = false, ka,
           "Adds the articulation to the scene, its root welded to the world when "
           "fix_root_link, free otherwise, and returns its handle; raises PartsimError naming "
           "the element at fault.")
      .def("build_kinematic", &ArticulationBuilder::BuildKinematic, ka,
           "Adds the articulation as kinematic (link poses follow set_qpos by forward "
           "kinematics) and returns its handle.")
      .def("get_desc", &ArticulationBuilder::GetDesc, "A copy of the description built so far.");
}

void BindScene(py::module_& m) {
  const auto ka = py::keep_alive<0, 1>();

  py::enum_<Integrator>(m, "Integrator", "Numerical integrator of the scene.")
      .value("EULER", Integrator::kEuler)
      .value("IMPLICIT", Integrator::kImplicit)
      .value("RK4", Integrator::kRK4)
      .value("IMPLICITFAST", Integrator::kImplicitFast);

  py::class_<SceneConfig>(m, "SceneConfig",
                          "Scene-wide settings: timestep, gravity, default material, solver "
                          "iterations and integrator.")
      .def(py::init<>())
      .def_readwrite("timestep", &SceneConfig::timestep,
                     "Timestep in seconds, > 0 (default 1/500).")
      .def_readwrite("gravity", &SceneConfig::gravity, "(3,) m/s^2, world frame.")
      .def_readwrite("default_material", &SceneConfig::default_material,
                     "PhysicalMaterial of the collision shapes that name none.")
      .def_readwrite("solver_iterations", &SceneConfig::solver_iterations,
                     "Constraint solver iterations per step, >= 1 (default 50).")
      .def_readwrite(
          "integrator", &SceneConfig::integrator,
          "Integrator (default IMPLICITFAST; the implicit ones handle stiff PD damping).")
      .def_readwrite("contact_offset", &SceneConfig::contact_offset,
                     "m, >= rest_offset: each shape's distance within which contacts are found "
                     "(SAPIEN's contact offset; a pair adds up its two shapes'); contacts beyond "
                     "the rest offset are reported with zero force (default 0).")
      .def_readwrite("rest_offset", &SceneConfig::rest_offset,
                     "m, >= 0: each shape's distance at which bodies rest on it (SAPIEN's rest "
                     "offset; a pair adds up its two shapes'; default 0).")
      .def_readwrite("contact_impedance", &SceneConfig::contact_impedance,
                     "In (0, 0.9999]: the share of the force a contact needs that it gives at the "
                     "moment of touching (MuJoCo's solimp dmin; default 0.999: nearly hard, as "
                     "PhysX's are; MuJoCo's own is 0.9).");

  py::class_<Scene, std::shared_ptr<Scene>>(
      m, "Scene", "A simulated world. Handles and builders taken from it keep it alive.")
      .def(py::init<const SceneConfig&>(), py::arg("config") = SceneConfig(),
           "Empty scene with the given settings.")
      .def(py::init([](double timestep, const Eigen::Vector3d& gravity) {
             SceneConfig config;
             config.timestep = timestep;
             config.gravity = gravity;
             return std::make_shared<Scene>(config);
           }),
           py::arg("timestep") = SceneConfig().timestep, py::arg("gravity") = SceneConfig().gravity,
           "Scene with the default SceneConfig but `timestep` (s) and `gravity` (3,) m/s^2.")
      .def(
          "clone", [](const Scene& self) { return std::shared_ptr<Scene>(self.Clone()); },
          "Independent copy with the same description and state.")
      .def("get_config", &Scene::GetConfig, "A copy of the scene's settings.")
      .def_property("timestep", &Scene::GetTimestep, &Scene::SetTimestep,
                    "Timestep in seconds, > 0.")
      .def("get_timestep", &Scene::GetTimestep, "Timestep in seconds.")
      .def("set_timestep", &Scene::SetTimestep, py::arg("dt"), "Sets the timestep dt (s, > 0).")
      .def_property("gravity", &Scene::GetGravity, &Scene::SetGravity,
                    "Gravity (3,) in m/s^2, world frame.")
      .def("get_gravity", &Scene::GetGravity, "Gravity (3,) in m/s^2, world frame.")
      .def("set_gravity", &Scene::SetGravity, py::arg("g"),
           "Sets gravity (3,) in m/s^2, world frame.")
      .def("get_time", &Scene::GetTime,
           "Simulated time in seconds (unpack restores it with the state).")
      .def("create_actor_builder", &Scene::CreateActorBuilder, ka,
           "A new ActorBuilder whose build() adds to this scene.")
      .def("create_articulation_builder", &Scene::CreateArticulationBuilder, ka,
           "A new ArticulationBuilder whose build() adds to this scene.")
      .def_static(
          "create_physical_material",
          [](double static_friction, double dynamic_friction, double restitution) {
            return PhysicalMaterial{static_friction, dynamic_friction, restitution};
          },
          py::arg("static_friction"), py::arg("dynamic_friction"), py::arg("restitution"),
          "Same as PhysicalMaterial(static_friction, dynamic_friction, restitution).")
      .def("add_ground", &Scene::AddGround, py::arg("altitude") = 0.0,
           py::arg("material") = py::none(), py::arg("name") = "ground", py::arg("render") = true,
           py::arg("render_half_size") = Eigen::Vector2d(10, 10),
           py::arg("render_material") = py::none(), ka,
           "Adds a static ground plane at z = altitude (m). Cameras see a square of "
           "render_half_size (2,) m around the origin in render_material (light grey by "
           "default), or nothing when render is False.")
      .def("set_default_material", &Scene::SetDefaultMaterial, py::arg("material"),
           "Material of the collision shapes that name none, those already built included.")
      .def("add_actor", &Scene::AddActor, py::arg("desc"), ka,
           "Adds an actor from an ActorDesc and returns its handle; the description is "
           "validated first (PartsimError naming the fault) and the state of everything else "
           "is kept.")
      .def("add_articulation", &Scene::AddArticulation, py::arg("desc"), ka,
           "Adds an articulation from an ArticulationDesc and returns its handle; validated "
           "first, as add_actor.")
      .def("remove_actor", &Scene::RemoveActor, py::arg("actor"),
           "Removes the actor (its handles become invalid); raises PartsimError for an actor "
           "of another scene or one already removed.")
      .def("remove_articulation", &Scene::RemoveArticulation, py::arg("articulation"),
           "Removes the articulation (its handles become invalid); raises PartsimError for "
           "one of another scene or one already removed.")
      .def(
          "get_actors",
          [](py::object self) { return HandleList(self.cast<const Scene&>().GetActors(), self); },
          "Handles of every actor in the scene (the ground included).")
      .def(
          "get_articulations",
          [](py::object self) {
            return HandleList(self.cast<const Scene&>().GetArticulations(), self);
          },
          "Handles of every articulation in the scene.")
      .def("find_actor_by_name", &Scene::FindActorByName, py::arg("name"), ka,
           "The first actor named `name`; raises PartsimError when there is none.")
      .def("find_articulation_by_name", &Scene::FindArticulationByName, py::arg("name"), ka,
           "The first articulation named `name`; raises PartsimError when there is none.")
      .def(
          "step", [](Scene& s, int n) { WithoutGil(s, [&] { s.Step(n); }); }, py::arg("n") = 1,
          "Advances by n timesteps. The GIL is released meanwhile: other Python threads run; "
          "their steps of this scene wait their turn, and their other calls on it raise "
          "PartsimError until step returns.")
      .def("get_contacts", &Scene::GetContacts, "list of Contact: the contacts of the last step.")
      .def("raycast", &Scene::Raycast, py::arg("origin"), py::arg("direction"), py::arg("distance"),
           "The first collision shape a ray from `origin` (3,) along `direction` (3,, normalized "
           "here) meets within `distance` (m), at the current state: a RayHit, or None when it "
           "meets nothing.")
      .def("get_warnings", &Scene::GetWarnings,
           "list of SceneWarning recorded so far (numerical trouble during steps).")
      .def("clear_warnings", &Scene::ClearWarnings, "Forgets the warnings recorded so far.")
      .def(
          "pack",
          [](const Scene& self) {
            std::vector<char> state = self.Pack();
            return py::bytes(state.data(), state.size());
          },
          "Whole dynamic state as bytes, bit-exact.")
      .def(
          "unpack",
          [](Scene& self, const py::bytes& state) {
            std::string s = state;
            self.Unpack(std::vector<char>(s.begin(), s.end()));
          },
          py::arg("state"), "Restores a state from pack() of this scene.")
      .def("get_mjcf", &Scene::GetMjcf, "The MJCF text the last compile used (debugging).");
}

}  // namespace

void BindMjcf(py::module_& m) {
  const auto ka = py::keep_alive<0, 1>();
  py::class_<MjcfModel>(
      m, "MjcfModel",
      "An MJCF model loaded into a scene (Scene.load_mjcf): its bodies, joints, tendons, "
      "equality constraints, actuators and sensors as MuJoCo defines them, with partsim's "
      "handles on its bodies.")
      .def_property_readonly("id", &MjcfModel::GetId, "The model's id in its scene.")
      .def_property_readonly("name", &MjcfModel::GetName,
                             "The model's name (<mujoco model=...>, else the file's stem).")
      .def_property_readonly("path", &MjcfModel::GetPath, "The file it was loaded from.")
      .def_property_readonly("prefix", &MjcfModel::GetPrefix,
                             "What its element names start with in the scene's MuJoCo model.")
      .def(
          "get_articulations",
          [](py::object self) {
            return HandleList(self.cast<const MjcfModel&>().GetArticulations(), self);
          },
          "The articulations made of its kinematic trees.")
      .def(
          "get_actors",
          [](py::object self) {
            return HandleList(self.cast<const MjcfModel&>().GetActors(), self);
          },
          "The actors made of its free, static and mocap bodies (and its worldbody's geoms).")
      .def("get_bodies_without_handle", &MjcfModel::GetBodiesWithoutHandle,
           "Bodies MuJoCo simulates that have no partsim handle (trees with a ball joint).")
      .def("get_actuator_names", &MjcfModel::GetActuatorNames,
           "Its actuators' names, without the prefix, in MuJoCo's order.")
      .def("get_ctrl", &MjcfModel::GetCtrl, "Its actuators' controls (MuJoCo's ctrl), (nu,).")
      .def("set_ctrl", py::overload_cast<const Eigen::VectorXd&>(&MjcfModel::SetCtrl),
           py::arg("ctrl"), "Sets every actuator's control; kept until set again.")
      .def("set_ctrl", py::overload_cast<const std::string&, double>(&MjcfModel::SetCtrl),
           py::arg("actuator"), py::arg("value"), "Sets one actuator's control by name.")
      .def("get_joint_names", &MjcfModel::GetJointNames,
           "Its joints' names, without the prefix, in MuJoCo's order.")
      .def("get_qpos", &MjcfModel::GetQpos, "Its slice of MuJoCo's qpos, joint by joint.")
      .def("set_qpos", &MjcfModel::SetQpos, py::arg("qpos"),
           "Sets its slice of MuJoCo's qpos (free joints: position and w, x, y, z quaternion).")
      .def("get_qvel", &MjcfModel::GetQvel, "Its slice of MuJoCo's qvel, joint by joint.")
      .def("set_qvel", &MjcfModel::SetQvel, py::arg("qvel"), "Sets its slice of MuJoCo's qvel.")
      .def("get_tendon_names", &MjcfModel::GetTendonNames,
           "Its tendons' names, without the prefix, in MuJoCo's order.")
      .def("get_tendon_lengths", &MjcfModel::GetTendonLengths,
           "Its tendons' lengths now (m), in the order of get_tendon_names().")
      .def("mj_id", &MjcfModel::MjId, py::arg("mj_object_type"), py::arg("name"),
           "The id of one of its elements in the scene's MuJoCo model (mujoco.mjtObj value), "
           "-1 when it has none of that name.");

  py::class_<Scene, std::shared_ptr<Scene>>(m.attr("Scene"))
      .def(
          "load_mjcf",
          [](Scene& scene, const std::string& path, const Pose& pose) {
            return LoadMjcf(scene, path, pose);
          },
          py::arg("path"), py::arg("pose") = Pose(), ka,
          "Loads an MJCF file (MuJoCo's format) into the scene at `pose`; returns its "
          "MjcfModel. <include>, <replicate>, <attach> and relative asset paths work; the "
          "scene's options are kept. Raises PartsimError with MuJoCo's message (file and line) "
          "and leaves the scene as it was.")
      .def(
          "get_mjcf_models",
          [](py::object self) {
            return HandleList(GetMjcfModels(self.cast<const Scene&>()), self);
          },
          "The MJCF models loaded into the scene.");
  m.def("scene_config_from_mjcf", &SceneConfigFromMjcf, py::arg("path"),
        "The options of an MJCF file (timestep, gravity, integrator, iterations) as a "
        "SceneConfig.");
  m.def("is_mjcf_file", &IsMjcfFile, py::arg("path"),
        "Whether a file is MJCF (a .xml whose root element is <mujoco>).");
}

void BindPhysics(py::module_& m) {
  // classes are registered before the signatures that mention them, so docstrings (and the
  // stubs made from them) name Python types
  BindDescription(m);
  BindContacts(m);
  BindHandles(m);
  BindBuilders(m);
  BindScene(m);
  BindMjcf(m);
}

}  // namespace partsim::python
