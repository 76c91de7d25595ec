// ActorBuilder, LinkBuilder and ArticulationBuilder: assemble descriptions piece by piece.
#include <cmath>

#include "partsim/assets/mesh.h"
#include "partsim/assets/urdf.h"
#include "partsim/physics/scene.h"

namespace partsim {

namespace {

CollisionShape Primitive(ShapeType type, const Pose& pose,
                         const std::optional<PhysicalMaterial>& material, double density) {
  CollisionShape s;
  s.type = type;
  s.pose = pose;
  s.material = material;
  s.density = density;
  return s;
}

VisualShape PrimitiveVisual(ShapeType type, const Pose& pose, const Eigen::Vector4f& color,
                            const std::string& name) {
  VisualShape v;
  v.type = type;
  v.pose = pose;
  v.material.base_color = color;
  v.name = name;
  return v;
}

// Shape adders shared by actor and link builders.
void AddBox(BodyDesc& b, const Pose& pose, const Eigen::Vector3d& half_size,
            const std::optional<PhysicalMaterial>& material, double density) {
  CollisionShape s = Primitive(ShapeType::kBox, pose, material, density);
  s.half_size = half_size;
  b.collisions.push_back(s);
}

void AddSphere(BodyDesc& b, const Pose& pose, double radius,
               const std::optional<PhysicalMaterial>& material, double density) {
  CollisionShape s = Primitive(ShapeType::kSphere, pose, material, density);
  s.radius = radius;
  b.collisions.push_back(s);
}

void AddRound(BodyDesc& b, ShapeType type, const Pose& pose, double radius, double half_length,
              const std::optional<PhysicalMaterial>& material, double density) {
  CollisionShape s = Primitive(type, pose, material, density);
  s.radius = radius;
  s.half_length = half_length;
  b.collisions.push_back(s);
}

void AddConvexMesh(BodyDesc& b, std::shared_ptr<const MeshData> mesh, const Pose& pose,
                   const std::optional<PhysicalMaterial>& material, double density) {
  CollisionShape s = Primitive(ShapeType::kConvexMesh, pose, material, density);
  s.mesh = std::move(mesh);
  b.collisions.push_back(s);
}

void CheckScale(const Eigen::Vector3d& scale, const std::string& filename) {
  if (!scale.allFinite() || (scale.array() == 0).any())
    throw Error("mesh '" + filename + "': scale must be finite and non-zero");
}

void AddVisualFile(BodyDesc& b, const std::string& filename, const Pose& pose,
                   const Eigen::Vector3d& scale, const std::string& name) {
  CheckScale(scale, filename);
  for (const LoadedMesh& lm : LoadMeshFile(filename, scale)) {
    VisualShape v;
    v.type = ShapeType::kConvexMesh;
    v.pose = pose;
    v.mesh = lm.mesh;
    v.material = lm.material;
    v.name = name;
    b.visuals.push_back(v);
  }
}

Inertial MakeInertial(double mass, const Pose& pose, const Eigen::Vector3d& inertia) {
  Inertial i;
  i.mass = mass;
  i.cmass_local_pose = pose;
  i.inertia = inertia;
  return i;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ActorBuilder

ActorBuilder& ActorBuilder::SetName(const std::string& name) {
  desc_.name = name;
  return *this;
}
ActorBuilder& ActorBuilder::SetInitialPose(const Pose& pose) {
  desc_.pose = pose;
  return *this;
}
ActorBuilder& ActorBuilder::AddBoxCollision(const Pose& pose, const Eigen::Vector3d& half_size,
                                            const std::optional<PhysicalMaterial>& material,
                                            double density) {
  AddBox(desc_, pose, half_size, material, density);
  return *this;
}
ActorBuilder& ActorBuilder::AddSphereCollision(const Pose& pose, double radius,
                                               const std::optional<PhysicalMaterial>& material,
                                               double density) {
  AddSphere(desc_, pose, radius, material, density);
  return *this;
}
ActorBuilder& ActorBuilder::AddCapsuleCollision(const Pose& pose, double radius, double half_length,
                                                const std::optional<PhysicalMaterial>& material,
                                                double density) {
  AddRound(desc_, ShapeType::kCapsule, pose, radius, half_length, material, density);
  return *this;
}
ActorBuilder& ActorBuilder::AddCylinderCollision(const Pose& pose, double radius,
                                                 double half_length,
                                                 const std::optional<PhysicalMaterial>& material,
                                                 double density) {
  AddRound(desc_, ShapeType::kCylinder, pose, radius, half_length, material, density);
  return *this;
}
ActorBuilder& ActorBuilder::AddConvexCollisionFromFile(
    const std::string& filename, const Pose& pose, const Eigen::Vector3d& scale,
    const std::optional<PhysicalMaterial>& material, double density) {
  CheckScale(scale, filename);
  AddConvexMesh(desc_, LoadMergedMesh(filename, scale), pose, material, density);
  return *this;
}
ActorBuilder& ActorBuilder::AddMultipleConvexCollisionsFromFile(
    const std::string& filename, const Pose& pose, const Eigen::Vector3d& scale,
    const std::optional<PhysicalMaterial>& material, double density) {
  CheckScale(scale, filename);
  for (auto& piece : LoadConvexPieces(filename, scale))
    AddConvexMesh(desc_, piece, pose, material, density);
  return *this;
}
ActorBuilder& ActorBuilder::AddConvexCollisionFromMesh(
    std::shared_ptr<const MeshData> mesh, const Pose& pose,
    const std::optional<PhysicalMaterial>& material, double density) {
  AddConvexMesh(desc_, std::move(mesh), pose, material, density);
  return *this;
}
ActorBuilder& ActorBuilder::AddBoxVisual(const Pose& pose, const Eigen::Vector3d& half_size,
                                         const Eigen::Vector4f& color, const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kBox, pose, color, name);
  v.half_size = half_size;
  desc_.visuals.push_back(v);
  return *this;
}
ActorBuilder& ActorBuilder::AddSphereVisual(const Pose& pose, double radius,
                                            const Eigen::Vector4f& color, const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kSphere, pose, color, name);
  v.radius = radius;
  desc_.visuals.push_back(v);
  return *this;
}
ActorBuilder& ActorBuilder::AddCapsuleVisual(const Pose& pose, double radius, double half_length,
                                             const Eigen::Vector4f& color,
                                             const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kCapsule, pose, color, name);
  v.radius = radius;
  v.half_length = half_length;
  desc_.visuals.push_back(v);
  return *this;
}
ActorBuilder& ActorBuilder::AddCylinderVisual(const Pose& pose, double radius, double half_length,
                                              const Eigen::Vector4f& color,
                                              const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kCylinder, pose, color, name);
  v.radius = radius;
  v.half_length = half_length;
  desc_.visuals.push_back(v);
  return *this;
}
ActorBuilder& ActorBuilder::AddVisualFromFile(const std::string& filename, const Pose& pose,
                                              const Eigen::Vector3d& scale,
                                              const std::string& name) {
  AddVisualFile(desc_, filename, pose, scale, name);
  return *this;
}
ActorBuilder& ActorBuilder::SetMassAndInertia(double mass, const Pose& cmass_local_pose,
                                              const Eigen::Vector3d& inertia) {
  desc_.inertial = MakeInertial(mass, cmass_local_pose, inertia);
  return *this;
}

Actor ActorBuilder::Build(bool kinematic) {
  desc_.type = kinematic ? ActorType::kKinematic : ActorType::kDynamic;
  return scene_->AddActor(desc_);
}

Actor ActorBuilder::BuildStatic() {
  desc_.type = ActorType::kStatic;
  return scene_->AddActor(desc_);
}

// ---------------------------------------------------------------------------------------------
// LinkBuilder

LinkDesc& LinkBuilder::link() { return owner_->desc_.links[index_]; }

LinkBuilder& LinkBuilder::SetName(const std::string& name) {
  link().name = name;
  return *this;
}
LinkBuilder& LinkBuilder::SetJointName(const std::string& name) {
  link().joint.name = name;
  return *this;
}
LinkBuilder& LinkBuilder::SetJointProperties(JointType type, const Eigen::Vector2d& limits,
                                             const Pose& pose_in_parent, const Pose& pose_in_child,
                                             double friction, double damping) {
  JointDesc& j = link().joint;
  j.type = type;
  j.lower = limits[0];
  j.upper = limits[1];
  j.pose_in_parent = pose_in_parent;
  j.pose_in_child = pose_in_child;
  j.friction = friction;
  j.damping = damping;
  return *this;
}
LinkBuilder& LinkBuilder::SetJointArmature(double armature) {
  link().joint.armature = armature;
  return *this;
}
LinkBuilder& LinkBuilder::SetScrewPitch(double pitch) {
  link().joint.pitch = pitch;
  return *this;
}
LinkBuilder& LinkBuilder::AddBoxCollision(const Pose& pose, const Eigen::Vector3d& half_size,
                                          const std::optional<PhysicalMaterial>& material,
                                          double density) {
  AddBox(link(), pose, half_size, material, density);
  return *this;
}
LinkBuilder& LinkBuilder::AddSphereCollision(const Pose& pose, double radius,
                                             const std::optional<PhysicalMaterial>& material,
                                             double density) {
  AddSphere(link(), pose, radius, material, density);
  return *this;
}
LinkBuilder& LinkBuilder::AddCapsuleCollision(const Pose& pose, double radius, double half_length,
                                              const std::optional<PhysicalMaterial>& material,
                                              double density) {
  AddRound(link(), ShapeType::kCapsule, pose, radius, half_length, material, density);
  return *this;
}
LinkBuilder& LinkBuilder::AddCylinderCollision(const Pose& pose, double radius, double half_length,
                                               const std::optional<PhysicalMaterial>& material,
                                               double density) {
  AddRound(link(), ShapeType::kCylinder, pose, radius, half_length, material, density);
  return *this;
}
LinkBuilder& LinkBuilder::AddConvexCollisionFromFile(
    const std::string& filename, const Pose& pose, const Eigen::Vector3d& scale,
    const std::optional<PhysicalMaterial>& material, double density) {
  CheckScale(scale, filename);
  AddConvexMesh(link(), LoadMergedMesh(filename, scale), pose, material, density);
  return *this;
}
LinkBuilder& LinkBuilder::AddBoxVisual(const Pose& pose, const Eigen::Vector3d& half_size,
                                       const Eigen::Vector4f& color, const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kBox, pose, color, name);
  v.half_size = half_size;
  link().visuals.push_back(v);
  return *this;
}
LinkBuilder& LinkBuilder::AddSphereVisual(const Pose& pose, double radius,
                                          const Eigen::Vector4f& color, const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kSphere, pose, color, name);
  v.radius = radius;
  link().visuals.push_back(v);
  return *this;
}
LinkBuilder& LinkBuilder::AddCapsuleVisual(const Pose& pose, double radius, double half_length,
                                           const Eigen::Vector4f& color, const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kCapsule, pose, color, name);
  v.radius = radius;
  v.half_length = half_length;
  link().visuals.push_back(v);
  return *this;
}
LinkBuilder& LinkBuilder::AddCylinderVisual(const Pose& pose, double radius, double half_length,
                                            const Eigen::Vector4f& color, const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kCylinder, pose, color, name);
  v.radius = radius;
  v.half_length = half_length;
  link().visuals.push_back(v);
  return *this;
}
LinkBuilder& LinkBuilder::AddVisualFromFile(const std::string& filename, const Pose& pose,
                                            const Eigen::Vector3d& scale, const std::string& name) {
  AddVisualFile(link(), filename, pose, scale, name);
  return *this;
}
LinkBuilder& LinkBuilder::SetMassAndInertia(double mass, const Pose& cmass_local_pose,
                                            const Eigen::Vector3d& inertia) {
  link().inertial = MakeInertial(mass, cmass_local_pose, inertia);
  return *this;
}

// ---------------------------------------------------------------------------------------------
// ArticulationBuilder

ArticulationBuilder& ArticulationBuilder::SetName(const std::string& name) {
  desc_.name = name;
  return *this;
}
ArticulationBuilder& ArticulationBuilder::SetInitialPose(const Pose& pose) {
  desc_.root_pose = pose;
  return *this;
}

LinkBuilder* ArticulationBuilder::CreateLinkBuilder(LinkBuilder* parent) {
  int index = static_cast<int>(desc_.links.size());
  LinkDesc link;
  if (parent) {
    if (parent->GetIndex() < 0 || parent->GetIndex() >= index ||
        link_builders_[parent->GetIndex()].get() != parent)
      throw Error("create_link_builder: parent does not belong to this articulation builder");
    link.parent = parent->GetIndex();
    link.joint.type = JointType::kFixed;
  } else if (!desc_.links.empty()) {
    throw Error("create_link_builder: the articulation already has a root; give a parent");
  }
  desc_.links.push_back(link);
  link_builders_.push_back(std::make_unique<LinkBuilder>(this, index));
  return link_builders_.back().get();
}

namespace {

// Unnamed links and joints get names, so that they can be found.
ArticulationDesc Named(ArticulationDesc desc) {
  for (size_t i = 0; i < desc.links.size(); ++i) {
    if (desc.links[i].name.empty()) desc.links[i].name = "link_" + std::to_string(i);
    if (desc.links[i].parent >= 0 && desc.links[i].joint.name.empty())
      desc.links[i].joint.name = "joint_" + std::to_string(i);
  }
  return desc;
}

}  // namespace

Articulation ArticulationBuilder::Build(bool fix_root_link) {
  ArticulationDesc desc = Named(desc_);
  desc.fix_root = fix_root_link;
  desc.kinematic = false;
  return scene_->AddArticulation(desc);
}

Articulation ArticulationBuilder::BuildKinematic() {
  ArticulationDesc desc = Named(desc_);
  desc.fix_root = true;
  desc.kinematic = true;
  return scene_->AddArticulation(desc);
}

// ---------------------------------------------------------------------------------------------
// Scene factories

ActorBuilder Scene::CreateActorBuilder() { return ActorBuilder(this); }
ArticulationBuilder Scene::CreateArticulationBuilder() { return ArticulationBuilder(this); }
UrdfLoader Scene::CreateUrdfLoader() { return UrdfLoader(this); }

}  // namespace partsim
