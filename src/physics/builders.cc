// ActorBuilder, LinkBuilder and ArticulationBuilder: assemble descriptions piece by piece. The
// steps that read mesh files or check convex pieces are free functions of the assets layer
// (partsim/assets/mesh_builders.h), as is CreateUrdfLoader (partsim/assets/urdf.h).
#include <cmath>

#include "partsim/core/log.h"
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

// Shape adders shared by the builders.
void AddRound(BodyDesc& b, ShapeType type, const Pose& pose, double radius, double half_length,
              const std::optional<PhysicalMaterial>& material, double density) {
  CollisionShape s = Primitive(type, pose, material, density);
  s.radius = radius;
  s.half_length = half_length;
  b.collisions.push_back(s);
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
// BodyBuilder

template <typename D>
D& BodyBuilder<D>::SetName(const std::string& name) {
  body().name = name;
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddBoxCollision(const Pose& pose, const Eigen::Vector3d& half_size,
                                   const std::optional<PhysicalMaterial>& material,
                                   double density) {
  CollisionShape s = Primitive(ShapeType::kBox, pose, material, density);
  s.half_size = half_size;
  body().collisions.push_back(s);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddSphereCollision(const Pose& pose, double radius,
                                      const std::optional<PhysicalMaterial>& material,
                                      double density) {
  CollisionShape s = Primitive(ShapeType::kSphere, pose, material, density);
  s.radius = radius;
  body().collisions.push_back(s);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddCapsuleCollision(const Pose& pose, double radius, double half_length,
                                       const std::optional<PhysicalMaterial>& material,
                                       double density) {
  AddRound(body(), ShapeType::kCapsule, pose, radius, half_length, material, density);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddCylinderCollision(const Pose& pose, double radius, double half_length,
                                        const std::optional<PhysicalMaterial>& material,
                                        double density) {
  AddRound(body(), ShapeType::kCylinder, pose, radius, half_length, material, density);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddBoxVisual(const Pose& pose, const Eigen::Vector3d& half_size,
                                const Eigen::Vector4f& color, const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kBox, pose, color, name);
  v.half_size = half_size;
  body().visuals.push_back(v);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddSphereVisual(const Pose& pose, double radius, const Eigen::Vector4f& color,
                                   const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kSphere, pose, color, name);
  v.radius = radius;
  body().visuals.push_back(v);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddCapsuleVisual(const Pose& pose, double radius, double half_length,
                                    const Eigen::Vector4f& color, const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kCapsule, pose, color, name);
  v.radius = radius;
  v.half_length = half_length;
  body().visuals.push_back(v);
  return self();
}
template <typename D>
D& BodyBuilder<D>::AddCylinderVisual(const Pose& pose, double radius, double half_length,
                                     const Eigen::Vector4f& color, const std::string& name) {
  VisualShape v = PrimitiveVisual(ShapeType::kCylinder, pose, color, name);
  v.radius = radius;
  v.half_length = half_length;
  body().visuals.push_back(v);
  return self();
}
template <typename D>
int BodyBuilder<D>::GetVisualCount() {
  return static_cast<int>(body().visuals.size());
}
template <typename D>
D& BodyBuilder<D>::SetVisualMaterial(int index, const RenderMaterial& material) {
  std::vector<VisualShape>& v = body().visuals;
  if (index < 0 || index >= static_cast<int>(v.size()))
    throw Error("set_visual_material: visual index " + std::to_string(index) + " out of range (" +
                std::to_string(v.size()) + " visuals)");
  v[index].material = material;
  return self();
}
template <typename D>
D& BodyBuilder<D>::SetMassAndInertia(double mass, const Pose& cmass_local_pose,
                                     const Eigen::Vector3d& inertia) {
  body().inertial = MakeInertial(mass, cmass_local_pose, inertia);
  return self();
}
template <typename D>
D& BodyBuilder<D>::SetCollisionGroups(const std::array<uint32_t, 4>& groups) {
  collision_groups_ = groups;
  return self();
}
template <typename D>
void BodyBuilder<D>::ApplyCollisionGroups(BodyDesc& body) const {
  if (!collision_groups_) return;
  for (CollisionShape& s : body.collisions) s.collision_groups = *collision_groups_;
}

template class BodyBuilder<ActorBuilder>;
template class BodyBuilder<LinkBuilder>;

// ---------------------------------------------------------------------------------------------
// ActorBuilder

ActorBuilder& ActorBuilder::SetInitialPose(const Pose& pose) {
  desc_.pose = pose;
  return *this;
}

Actor ActorBuilder::Build(bool kinematic) {
  desc_.type = kinematic ? ActorType::kKinematic : ActorType::kDynamic;
  ApplyCollisionGroups(desc_);
  return scene_->AddActor(desc_);
}

Actor ActorBuilder::BuildStatic() {
  desc_.type = ActorType::kStatic;
  ApplyCollisionGroups(desc_);
  return scene_->AddActor(desc_);
}

// ---------------------------------------------------------------------------------------------
// LinkBuilder

LinkDesc& LinkBuilder::link() { return owner_->desc_.links[index_]; }
BodyDesc& LinkBuilder::Body() { return link(); }

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

ArticulationDesc ArticulationBuilder::Finished() const {
  ArticulationDesc desc = Named(desc_);
  for (size_t i = 0; i < link_builders_.size(); ++i)
    link_builders_[i]->ApplyCollisionGroups(desc.links[i]);
  return desc;
}

Articulation ArticulationBuilder::Build(bool fix_root_link) {
  ArticulationDesc desc = Finished();
  desc.fix_root = fix_root_link;
  desc.kinematic = false;
  return scene_->AddArticulation(desc);
}

Articulation ArticulationBuilder::BuildKinematic() {
  ArticulationDesc desc = Finished();
  desc.fix_root = true;
  desc.kinematic = true;
  return scene_->AddArticulation(desc);
}

// ---------------------------------------------------------------------------------------------
// Scene factories

ActorBuilder Scene::CreateActorBuilder() { return ActorBuilder(this); }
ArticulationBuilder Scene::CreateArticulationBuilder() { return ArticulationBuilder(this); }

}  // namespace partsim
