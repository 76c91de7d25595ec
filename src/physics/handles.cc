// Actor, Link, Joint and Articulation handles: views into the scene's description and data.
#include <algorithm>
#include <cmath>

#include "partsim/core/check.h"
#include "partsim/physics/frame_motion.h"
#include "partsim/physics/scene.h"
#include "physics/dynamics.h"
#include "physics/scene_internal.h"

namespace partsim {

using internal::CompiledArticulation;
using internal::CompiledJoint;
using internal::DriveStep;
using internal::SceneImpl;

namespace {

SceneImpl& S(Scene* scene) {
  if (!scene) throw Error("empty handle: it does not belong to a scene");
  return scene->impl();
}

Eigen::Vector3d V3(const double* v) { return Eigen::Vector3d(v[0], v[1], v[2]); }
Eigen::Quaterniond Q4(const double* q) { return Eigen::Quaterniond(q[0], q[1], q[2], q[3]); }

void CheckVector(const Eigen::VectorXd& v, int n, const std::string& what,
                 const std::string& owner) {
  if (v.size() != n)
    throw Error(what + " has " + std::to_string(v.size()) + " entries, " + owner + " has " +
                std::to_string(n) + " dof");
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v[i]))
      throw Error(what + "[" + std::to_string(i) + "] is " + FormatNumber(v[i]) +
                  ", must be finite");
}

// World-frame velocity of a body at its origin: (linear, angular).
std::pair<Eigen::Vector3d, Eigen::Vector3d> BodyVelocity(SceneImpl& s, int body) {
  s.EnsureKinematics();
  mjtNum res[6];
  mj_objectVelocity(s.m(), s.d(), mjOBJ_BODY, body, res, 0);
  return {V3(res + 3), V3(res)};
}

void AddBodyForce(SceneImpl& s, int body, const Eigen::Vector3d& f, const Eigen::Vector3d& point) {
  CheckFinite("force", f);
  CheckFinite("point", point);
  s.EnsureKinematics();
  Eigen::Vector3d com = V3(s.d()->xipos + 3 * body);
  Eigen::Vector3d torque = (point - com).cross(f);
  for (int k = 0; k < 3; ++k) {
    s.d()->xfrc_applied[6 * body + k] += f[k];
    s.d()->xfrc_applied[6 * body + 3 + k] += torque[k];
  }
  s.data.xfrc_dirty = true;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Actor

const std::string& Actor::GetName() const { return S(scene_).GetActor(id_).desc.name; }
void Actor::SetName(const std::string& name) { S(scene_).GetActor(id_).desc.name = name; }
ActorType Actor::GetType() const { return S(scene_).GetActor(id_).desc.type; }
const ActorDesc& Actor::GetDesc() const { return S(scene_).GetActor(id_).desc; }

Pose Actor::GetPose() const {
  SceneImpl& s = S(scene_);
  auto& a = s.GetActor(id_);
  const auto& c = s.Compiled(a);
  if (c.qposadr >= 0) return Pose(V3(s.d()->qpos + c.qposadr), Q4(s.d()->qpos + c.qposadr + 3));
  if (c.mocap >= 0)
    return Pose(V3(s.d()->mocap_pos + 3 * c.mocap), Q4(s.d()->mocap_quat + 4 * c.mocap));
  return a.desc.pose;
}

void Actor::SetPose(const Pose& pose) {
  CheckPose("actor pose", pose);
  SceneImpl& s = S(scene_);
  auto& a = s.GetActor(id_);
  if (s.IsUncompiled(id_)) {  // not in the model yet: it will start there
    a.desc.pose = Pose(pose.p, pose.q.normalized());
    return;
  }
  const auto& c = s.Compiled(a);
  Eigen::Quaterniond q = pose.q.normalized();
  double* dst;
  if (c.qposadr >= 0) {
    dst = s.d()->qpos + c.qposadr;
    for (int k = 0; k < 3; ++k) dst[k] = pose.p[k];
    dst += 3;
  } else if (c.mocap >= 0) {
    for (int k = 0; k < 3; ++k) s.d()->mocap_pos[3 * c.mocap + k] = pose.p[k];
    dst = s.d()->mocap_quat + 4 * c.mocap;
  } else {
    // a static actor is welded to the world: move the weld in the model (contacts with what
    // rests on it are not carried along)
    for (int k = 0; k < 3; ++k) s.m()->body_pos[3 * c.body + k] = pose.p[k];
    dst = s.m()->body_quat + 4 * c.body;
  }
  dst[0] = q.w();
  dst[1] = q.x();
  dst[2] = q.y();
  dst[3] = q.z();
  a.desc.pose = pose;
  s.Invalidate();
}

Eigen::Vector3d Actor::GetVelocity() const {
  SceneImpl& s = S(scene_);
  const auto& c = s.Compiled(s.GetActor(id_));
  if (c.dofadr < 0) return Eigen::Vector3d::Zero();
  return V3(s.d()->qvel + c.dofadr);
}

Eigen::Vector3d Actor::GetAngularVelocity() const {
  SceneImpl& s = S(scene_);
  const auto& c = s.Compiled(s.GetActor(id_));
  if (c.dofadr < 0) return Eigen::Vector3d::Zero();
  // a free joint's angular velocity is in the body frame
  return Q4(s.d()->qpos + c.qposadr + 3).normalized() * V3(s.d()->qvel + c.dofadr + 3);
}

void Actor::SetVelocity(const Eigen::Vector3d& v) {
  CheckFinite("velocity", v);
  SceneImpl& s = S(scene_);
  auto& a = s.GetActor(id_);
  const auto& c = s.Compiled(a);
  if (c.dofadr < 0) throw Error("actor '" + a.desc.name + "' is not dynamic: no velocity to set");
  for (int k = 0; k < 3; ++k) s.d()->qvel[c.dofadr + k] = v[k];
  s.Invalidate();
}

void Actor::SetAngularVelocity(const Eigen::Vector3d& w) {
  CheckFinite("angular velocity", w);
  SceneImpl& s = S(scene_);
  auto& a = s.GetActor(id_);
  const auto& c = s.Compiled(a);
  if (c.dofadr < 0) throw Error("actor '" + a.desc.name + "' is not dynamic: no velocity to set");
  Eigen::Vector3d local = Q4(s.d()->qpos + c.qposadr + 3).normalized().conjugate() * w;
  for (int k = 0; k < 3; ++k) s.d()->qvel[c.dofadr + 3 + k] = local[k];
  s.Invalidate();
}

double Actor::GetMass() const {
  SceneImpl& s = S(scene_);
  const int body = s.Compiled(s.GetActor(id_)).body;  // may compile: before reading s.m()
  return s.m()->body_mass[body];
}

Eigen::Vector3d Actor::GetInertia() const {
  SceneImpl& s = S(scene_);
  const int body = s.Compiled(s.GetActor(id_)).body;  // may compile: before reading s.m()
  return V3(s.m()->body_inertia + 3 * body);
}

Pose Actor::GetCMassPose() const {
  SceneImpl& s = S(scene_);
  const int body = s.Compiled(s.GetActor(id_)).body;
  s.EnsureKinematics();
  const mjData* d = s.d();
  return Pose(
      V3(d->xipos + 3 * body),
      Eigen::Quaterniond(Eigen::Matrix3d(
          Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->ximat + 9 * body))));
}

void Actor::SetDamping(double linear, double angular) {
  SceneImpl& s = S(scene_);
  auto& a = s.GetActor(id_);
  const auto& c = s.Compiled(a);
  if (c.dofadr < 0)
    throw Error("actor '" + a.desc.name + "' is " + ActorTypeName(a.desc.type) +
                ": only dynamic actors have velocity damping");
  ActorDesc changed = a.desc;  // checked as a description would be, before it changes
  changed.linear_damping = linear;
  changed.angular_damping = angular;
  Validate(changed);
  a.desc.linear_damping = linear;
  a.desc.angular_damping = angular;
  SyncActorDamping(s.model, a.desc, c);
}

double Actor::GetLinearDamping() const { return S(scene_).GetActor(id_).desc.linear_damping; }
double Actor::GetAngularDamping() const { return S(scene_).GetActor(id_).desc.angular_damping; }

void Actor::AddForceAtPoint(const Eigen::Vector3d& force, const Eigen::Vector3d& point) {
  SceneImpl& s = S(scene_);
  AddBodyForce(s, s.Compiled(s.GetActor(id_)).body, force, point);
}

void Actor::AddForceTorque(const Eigen::Vector3d& force, const Eigen::Vector3d& torque) {
  CheckFinite("force", force);
  CheckFinite("torque", torque);
  SceneImpl& s = S(scene_);
  int body = s.Compiled(s.GetActor(id_)).body;
  for (int k = 0; k < 3; ++k) {
    s.d()->xfrc_applied[6 * body + k] += force[k];
    s.d()->xfrc_applied[6 * body + 3 + k] += torque[k];
  }
  s.data.xfrc_dirty = true;
}

std::vector<Shape> Actor::GetCollisionShapes() const {
  std::vector<Shape> out;
  int n = static_cast<int>(GetDesc().collisions.size());
  for (int i = 0; i < n; ++i) out.emplace_back(scene_, id_, -1, -1, i);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Link

namespace {

const LinkDesc& LinkAt(SceneImpl& s, int art, int index) {
  const auto& links = s.GetArticulation(art).desc.links;
  if (index < 0 || index >= static_cast<int>(links.size()))
    throw IndexError("link index " + std::to_string(index) + " out of range [0, " +
                     std::to_string(links.size()) + ")");
  return links[index];
}

int LinkBody(SceneImpl& s, int art, int index) {
  LinkAt(s, art, index);
  return s.Compiled(s.GetArticulation(art)).link_body[index];
}

}  // namespace

const std::string& Link::GetName() const {
  return LinkAt(S(scene_), articulation_id_, index_).name;
}
int Link::GetId() const {
  LinkAt(S(scene_), articulation_id_, index_);  // throws when gone
  return static_cast<int>(S(scene_).GetArticulation(articulation_id_).render_id_base) + index_;
}
int Link::GetParentIndex() const { return LinkAt(S(scene_), articulation_id_, index_).parent; }
const LinkDesc& Link::GetDesc() const { return LinkAt(S(scene_), articulation_id_, index_); }

Pose Link::GetPose() const {
  SceneImpl& s = S(scene_);
  int b = LinkBody(s, articulation_id_, index_);
  s.EnsureKinematics();
  return Pose(V3(s.d()->xpos + 3 * b), Q4(s.d()->xquat + 4 * b));
}

Pose Link::GetCMassPose() const {
  SceneImpl& s = S(scene_);
  int b = LinkBody(s, articulation_id_, index_);
  s.EnsureKinematics();
  Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> r(s.d()->ximat + 9 * b);
  return Pose(V3(s.d()->xipos + 3 * b), Eigen::Quaterniond(Eigen::Matrix3d(r)));
}

Eigen::Vector3d Link::GetVelocity() const {
  SceneImpl& s = S(scene_);
  return BodyVelocity(s, LinkBody(s, articulation_id_, index_)).first;
}

Eigen::Vector3d Link::GetAngularVelocity() const {
  SceneImpl& s = S(scene_);
  return BodyVelocity(s, LinkBody(s, articulation_id_, index_)).second;
}

double Link::GetMass() const {
  SceneImpl& s = S(scene_);
  const int body = LinkBody(s, articulation_id_, index_);  // may compile: before reading s.m()
  return s.m()->body_mass[body];
}

Eigen::Vector3d Link::GetInertia() const {
  SceneImpl& s = S(scene_);
  const int body = LinkBody(s, articulation_id_, index_);  // may compile: before reading s.m()
  return V3(s.m()->body_inertia + 3 * body);
}

void Link::AddForceAtPoint(const Eigen::Vector3d& force, const Eigen::Vector3d& point) {
  SceneImpl& s = S(scene_);
  AddBodyForce(s, LinkBody(s, articulation_id_, index_), force, point);
}

std::vector<Shape> Link::GetCollisionShapes() const {
  std::vector<Shape> out;
  int n = static_cast<int>(GetDesc().collisions.size());
  for (int i = 0; i < n; ++i) out.emplace_back(scene_, -1, articulation_id_, index_, i);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Shape

Actor Shape::GetActor() const { return articulation_id_ < 0 ? Actor(scene_, actor_id_) : Actor(); }
Link Shape::GetLink() const {
  return articulation_id_ < 0 ? Link() : Link(scene_, articulation_id_, link_index_);
}

CollisionShape& Shape::Desc() const {
  SceneImpl& s = S(scene_);
  BodyDesc& body = articulation_id_ < 0
                       ? static_cast<BodyDesc&>(s.GetActor(actor_id_).desc)
                       : const_cast<LinkDesc&>(LinkAt(s, articulation_id_, link_index_));
  if (index_ < 0 || index_ >= static_cast<int>(body.collisions.size()))
    throw IndexError("collision shape index " + std::to_string(index_) + " out of range [0, " +
                     std::to_string(body.collisions.size()) + ") of '" + body.name + "'");
  return body.collisions[index_];
}

const CollisionShape& Shape::GetDesc() const { return Desc(); }
std::array<uint32_t, 4> Shape::GetCollisionGroups() const { return Desc().collision_groups; }

void Shape::SetCollisionGroups(const std::array<uint32_t, 4>& groups) {
  CollisionShape& shape = Desc();
  std::array<uint32_t, 4> old = shape.collision_groups;
  shape.collision_groups = groups;
  SceneImpl& s = S(scene_);
  // g2 / g3 decide which body pairs are excluded at compile time: recompile, keeping the state
  if (old[2] != groups[2] || old[3] != groups[3]) {
    s.dirty = true;
    s.EnsureCompiled();
    return;
  }
  // g0 / g1 are the geom's contype / conaffinity: patch the compiled model
  s.EnsureCompiled();
  std::string body = articulation_id_ < 0 ? internal::ActorBodyName(actor_id_)
                                          : internal::LinkBodyName(articulation_id_, link_index_);
  int geom = mj_name2id(s.m(), mjOBJ_GEOM, (body + "_g" + std::to_string(index_)).c_str());
  if (geom < 0) throw Error("collision shape " + std::to_string(index_) + " was not compiled");
  s.m()->geom_contype[geom] = static_cast<int>(groups[0]);
  s.m()->geom_conaffinity[geom] = static_cast<int>(groups[1]);
  s.Invalidate();
}

// ---------------------------------------------------------------------------------------------
// Joint

namespace {

struct JointRef {
  SceneImpl::ArticulationEntry* entry;
  JointDesc* desc;
  CompiledJoint* compiled;
};

JointRef GetJointRef(Scene* scene, int art, int index) {
  SceneImpl& s = S(scene);
  auto& a = s.GetArticulation(art);
  if (index < 1 || index >= static_cast<int>(a.desc.links.size()))
    throw IndexError("joint index " + std::to_string(index) + " out of range [1, " +
                     std::to_string(a.desc.links.size()) +
                     ") (joint i connects link i to its "
                     "parent; the root has none)");
  s.Compiled(a);  // compiles a changed description
  return {&a, &a.desc.links[index].joint, &s.model.articulations.at(art).joints[index]};
}

JointRef DofJoint(Scene* scene, int art, int index, const char* what) {
  JointRef j = GetJointRef(scene, art, index);
  if (j.compiled->dof_index < 0)
    throw Error(std::string(what) + ": joint '" + j.desc->name + "' has no degree of freedom (" +
                JointTypeName(j.desc->type) + ")");
  return j;
}

void CheckDriveParam(double v, const char* what) {
  if (!std::isfinite(v) || v < 0) throw Error(std::string(what) + " must be finite and >= 0");
}

// Sets a dof's armature in the compiled model, and the constants MuJoCo derives from it when it
// compiles (the mass matrix of simple dofs, dof_M0, used as is; the constraint weights; the mean
// inertia), as a compile would: mj_setConst works at qpos0, and changes no state but qpos.
void SetDofArmature(SceneImpl& s, int dofadr, double armature) {
  if (s.m()->dof_armature[dofadr] == armature) return;
  s.m()->dof_armature[dofadr] = armature;
  std::vector<double> qpos(s.d()->qpos, s.d()->qpos + s.m()->nq);
  mj_setConst(s.m(), s.d());
  std::copy(qpos.begin(), qpos.end(), s.d()->qpos);
  s.Invalidate();
}

// Writes a drive's gains into the compiled model, as the compiler writes them: a backward-Euler
// drive's velocity gain goes to ctrl (SceneImpl::ApplyDrives) and its inertia to the armature.
void SyncDrive(SceneImpl& s, const JointRef& j) {
  if (j.compiled->actuator < 0) return;
  int a = j.compiled->actuator;
  const DriveDesc& dr = j.desc->drive;
  const double dt = DriveStep(s.config);
  j.compiled->drive = internal::CompileDrive(dr, dt);
  s.m()->actuator_biasprm[a * mjNBIAS + 1] = -dr.stiffness;
  s.m()->actuator_biasprm[a * mjNBIAS + 2] = dt > 0 ? 0.0 : -dr.damping;
  SetDofArmature(s, j.compiled->dofadr, j.desc->armature + j.compiled->drive.armature);
  bool limited = std::isfinite(dr.force_limit);
  s.m()->actuator_forcelimited[a] = limited;
  s.m()->actuator_forcerange[2 * a] = limited ? -dr.force_limit : 0;
  s.m()->actuator_forcerange[2 * a + 1] = limited ? dr.force_limit : 0;
  s.Invalidate();
}

}  // namespace

const std::string& Joint::GetName() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->name;
}
JointType Joint::GetType() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->type;
}
const JointDesc& Joint::GetDesc() const {
  return *GetJointRef(scene_, articulation_id_, index_).desc;
}
int Joint::GetDof() const {
  return GetJointRef(scene_, articulation_id_, index_).compiled->dof_index >= 0 ? 1 : 0;
}
int Joint::GetDofIndex() const {
  return GetJointRef(scene_, articulation_id_, index_).compiled->dof_index;
}
Link Joint::GetParentLink() const {
  JointRef j = GetJointRef(scene_, articulation_id_, index_);
  return Link(scene_, articulation_id_, j.entry->desc.links[index_].parent);
}
Link Joint::GetChildLink() const { return Link(scene_, articulation_id_, index_); }
Pose Joint::GetPoseInParent() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->pose_in_parent;
}
Pose Joint::GetPoseInChild() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->pose_in_child;
}
Pose Joint::GetGlobalPose() const { return GetChildLink().GetPose() * GetPoseInChild(); }
Eigen::Vector3d Joint::GetGlobalAxis() const {
  return GetGlobalPose().q * Eigen::Vector3d::UnitX();
}

Eigen::Vector2d Joint::GetLimits() const {
  JointRef j = GetJointRef(scene_, articulation_id_, index_);
  return Eigen::Vector2d(j.desc->lower, j.desc->upper);
}

void Joint::SetLimits(double lower, double upper) {
  JointRef j = GetJointRef(scene_, articulation_id_, index_);
  if (std::isnan(lower) || std::isnan(upper) || lower > upper)
    throw Error("joint '" + j.desc->name + "': limits must satisfy lower <= upper, got (" +
                FormatNumber(lower) + ", " + FormatNumber(upper) + ")");
  if (j.desc->type == JointType::kFixed || j.desc->type == JointType::kContinuous)
    throw Error("joint '" + j.desc->name + "' is " + JointTypeName(j.desc->type) +
                " and has no limits to set");
  j.desc->lower = lower;
  j.desc->upper = upper;
  // whether a joint is limited is fixed at compile time: recompile, keeping the state
  SceneImpl& s = S(scene_);
  s.dirty = true;
  s.EnsureCompiled();
}

double Joint::GetFriction() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->friction;
}
double Joint::GetDamping() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->damping;
}
double Joint::GetArmature() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->armature;
}
double Joint::GetPitch() const { return GetJointRef(scene_, articulation_id_, index_).desc->pitch; }

void Joint::SetFriction(double v) {
  CheckDriveParam(v, "friction");
  JointRef j = GetJointRef(scene_, articulation_id_, index_);
  j.desc->friction = v;
  if (j.compiled->dofadr >= 0) S(scene_).m()->dof_frictionloss[j.compiled->dofadr] = v;
}

void Joint::SetDamping(double v) {
  CheckDriveParam(v, "damping");
  JointRef j = GetJointRef(scene_, articulation_id_, index_);
  j.desc->damping = v;
  if (j.compiled->dofadr >= 0) S(scene_).m()->dof_damping[j.compiled->dofadr] = v;
}

void Joint::SetArmature(double v) {
  CheckDriveParam(v, "armature");
  JointRef j = GetJointRef(scene_, articulation_id_, index_);
  j.desc->armature = v;
  if (j.compiled->dofadr >= 0)
    SetDofArmature(S(scene_), j.compiled->dofadr, v + j.compiled->drive.armature);
  S(scene_).Invalidate();
}

void Joint::SetDriveProperty(double stiffness, double damping, double force_limit) {
  CheckDriveParam(stiffness, "drive stiffness");
  CheckDriveParam(damping, "drive damping");
  if (std::isnan(force_limit) || force_limit <= 0)
    throw Error("drive force_limit must be > 0 (inf for no limit)");
  JointRef j = DofJoint(scene_, articulation_id_, index_, "set_drive_property");
  j.desc->drive.stiffness = stiffness;
  j.desc->drive.damping = damping;
  j.desc->drive.force_limit = force_limit;
  SyncDrive(S(scene_), j);
}

namespace {

// The data of the joint's articulation.
internal::ArticulationData& JointState(Scene* scene, const JointRef& j) {
  return S(scene).State(*j.entry);
}

}  // namespace

void Joint::SetDriveTarget(double target) {
  if (!std::isfinite(target)) throw Error("drive target must be finite");
  JointRef j = DofJoint(scene_, articulation_id_, index_, "set_drive_target");
  JointState(scene_, j).drive_target[j.compiled->dof_index] = target;
  S(scene_).Invalidate();
}

void Joint::SetDriveVelocityTarget(double v) {
  if (!std::isfinite(v)) throw Error("drive velocity target must be finite");
  JointRef j = DofJoint(scene_, articulation_id_, index_, "set_drive_velocity_target");
  JointState(scene_, j).drive_velocity_target[j.compiled->dof_index] = v;
  S(scene_).Invalidate();
}

// A joint without a dof has no drive: its description's (zero) targets
double Joint::GetDriveTarget() const {
  JointRef j = GetJointRef(scene_, articulation_id_, index_);
  if (j.compiled->dof_index < 0) return j.desc->drive.target;
  return JointState(scene_, j).drive_target[j.compiled->dof_index];
}
double Joint::GetDriveVelocityTarget() const {
  JointRef j = GetJointRef(scene_, articulation_id_, index_);
  if (j.compiled->dof_index < 0) return j.desc->drive.velocity_target;
  return JointState(scene_, j).drive_velocity_target[j.compiled->dof_index];
}
double Joint::GetDriveStiffness() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->drive.stiffness;
}
double Joint::GetDriveDamping() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->drive.damping;
}
double Joint::GetDriveForceLimit() const {
  return GetJointRef(scene_, articulation_id_, index_).desc->drive.force_limit;
}

double Joint::GetQpos() const {
  JointRef j = DofJoint(scene_, articulation_id_, index_, "get_qpos");
  return Articulation(scene_, articulation_id_).GetQpos()[j.compiled->dof_index];
}

double Joint::GetQvel() const {
  JointRef j = DofJoint(scene_, articulation_id_, index_, "get_qvel");
  return Articulation(scene_, articulation_id_).GetQvel()[j.compiled->dof_index];
}

// ---------------------------------------------------------------------------------------------
// Articulation

namespace {

struct ArtRef {
  SceneImpl& s;
  SceneImpl::ArticulationEntry& a;
  const CompiledArticulation& c;
  int dof() const { return static_cast<int>(c.dof_links.size()); }
  std::string owner() const { return "articulation '" + a.desc.name + "'"; }
};

// CheckVector for an articulation's dofs; the owner's name is only built for the message.
void CheckDofVector(const Eigen::VectorXd& v, const ArtRef& r, const char* what) {
  if (v.size() == r.dof() && v.allFinite()) return;
  CheckVector(v, r.dof(), what, r.owner());
}

ArtRef GetArt(Scene* scene, int id) {
  SceneImpl& s = S(scene);
  auto& a = s.GetArticulation(id);
  return {s, a, s.Compiled(a)};
}

ArtRef DynamicArt(Scene* scene, int id, const char* what) {
  ArtRef r = GetArt(scene, id);
  if (r.a.desc.kinematic)
    throw Error(std::string(what) + ": " + r.owner() +
                " is kinematic; dynamics queries need a dynamic articulation");
  return r;
}

// Gathers or scatters a per-dof quantity of MuJoCo (qvel-like arrays) for an articulation.
Eigen::VectorXd GatherDofs(const ArtRef& r, const double* src) {
  Eigen::VectorXd out(r.dof());
  for (int k = 0; k < r.dof(); ++k) out[k] = src[r.c.joints[r.c.dof_links[k]].dofadr];
  return out;
}

// Writes x into dst at the articulation's MuJoCo dofs, through the coupling matrix G.
void ScatterDofs(const ArtRef& r, const Eigen::VectorXd& x, double* dst) {
  Eigen::VectorXd full = r.c.G * x;
  for (size_t i = 0; i < r.c.mj_dofs.size(); ++i) dst[r.c.mj_dofs[i]] = full[i];
}

// Joint-space values with every coupled joint (URDF mimic) set from its source: positions
// (q = multiplier * q_source + offset) or velocities (qd = multiplier * qd_source).
Eigen::VectorXd WithCouplings(const ArtRef& r, Eigen::VectorXd x, bool positions) {
  for (const auto& cp : r.c.couplings)
    x[cp.dof] = cp.multiplier * x[cp.source_dof] + (positions ? cp.offset : 0.0);
  return x;
}

}  // namespace

const std::string& Articulation::GetName() const {
  return S(scene_).GetArticulation(id_).desc.name;
}
void Articulation::SetName(const std::string& name) {
  S(scene_).GetArticulation(id_).desc.name = name;
}
bool Articulation::IsKinematic() const { return S(scene_).GetArticulation(id_).desc.kinematic; }
bool Articulation::HasFixedRoot() const { return S(scene_).GetArticulation(id_).desc.fix_root; }
const ArticulationDesc& Articulation::GetDesc() const {
  return S(scene_).GetArticulation(id_).desc;
}
int Articulation::Dof() const { return GetArt(scene_, id_).dof(); }

std::vector<Link> Articulation::GetLinks() const {
  std::vector<Link> out;
  int n = static_cast<int>(S(scene_).GetArticulation(id_).desc.links.size());
  for (int i = 0; i < n; ++i) out.emplace_back(scene_, id_, i);
  return out;
}

std::vector<Joint> Articulation::GetJoints() const {
  std::vector<Joint> out;
  const auto& links = S(scene_).GetArticulation(id_).desc.links;
  for (size_t i = 0; i < links.size(); ++i)
    if (links[i].parent >= 0) out.emplace_back(scene_, id_, static_cast<int>(i));
  return out;
}

std::vector<Joint> Articulation::GetActiveJoints() const {
  ArtRef r = GetArt(scene_, id_);
  std::vector<Joint> out;
  for (int li : r.c.dof_links) out.emplace_back(scene_, id_, li);
  return out;
}

Link Articulation::GetLink(int index) const {
  LinkAt(S(scene_), id_, index);
  return Link(scene_, id_, index);
}

Joint Articulation::GetJoint(int index) const {
  GetJointRef(scene_, id_, index);
  return Joint(scene_, id_, index);
}

Link Articulation::FindLinkByName(const std::string& name) const {
  const auto& links = S(scene_).GetArticulation(id_).desc.links;
  for (size_t i = 0; i < links.size(); ++i)
    if (links[i].name == name) return Link(scene_, id_, static_cast<int>(i));
  throw Error("articulation '" + GetName() + "' has no link named '" + name + "'");
}

Joint Articulation::FindJointByName(const std::string& name) const {
  const auto& links = S(scene_).GetArticulation(id_).desc.links;
  for (size_t i = 0; i < links.size(); ++i)
    if (links[i].parent >= 0 && links[i].joint.name == name)
      return Joint(scene_, id_, static_cast<int>(i));
  throw Error("articulation '" + GetName() + "' has no joint named '" + name + "'");
}

Eigen::VectorXd Articulation::GetQpos() const {
  ArtRef r = GetArt(scene_, id_);
  if (r.a.desc.kinematic) return r.s.State(r.a).kin_qpos;
  Eigen::VectorXd out(r.dof());
  for (int k = 0; k < r.dof(); ++k) out[k] = r.s.d()->qpos[r.c.joints[r.c.dof_links[k]].qposadr];
  return out;
}

void Articulation::SetQpos(const Eigen::VectorXd& qpos) {
  ArtRef r = GetArt(scene_, id_);
  CheckDofVector(qpos, r, "qpos");
  // coupled joints follow their sources, so that the coupling holds from the start
  const Eigen::VectorXd values = WithCouplings(r, qpos, true);
  if (r.a.desc.kinematic) {
    r.s.State(r.a).kin_qpos = values;
    r.s.UpdateKinematicArticulation(r.a);
    return;
  }
  double* q = r.s.d()->qpos;
  for (int k = 0; k < r.dof(); ++k) {
    const CompiledJoint& j = r.c.joints[r.c.dof_links[k]];
    q[j.qposadr] = values[k];
    if (j.screw_slide_qposadr >= 0)
      q[j.screw_slide_qposadr] = r.a.desc.links[r.c.dof_links[k]].joint.pitch * values[k];
  }
  r.s.Invalidate();
}

Eigen::VectorXd Articulation::GetQvel() const {
  ArtRef r = GetArt(scene_, id_);
  if (r.a.desc.kinematic) return r.s.State(r.a).kin_qvel;
  return GatherDofs(r, r.s.d()->qvel);
}

void Articulation::SetQvel(const Eigen::VectorXd& qvel) {
  ArtRef r = GetArt(scene_, id_);
  CheckDofVector(qvel, r, "qvel");
  if (r.a.desc.kinematic) {
    r.s.State(r.a).kin_qvel = WithCouplings(r, qvel, false);
    return;
  }
  ScatterDofs(r, WithCouplings(r, qvel, false), r.s.d()->qvel);
  r.s.Invalidate();
}

Eigen::VectorXd Articulation::GetQacc() const {
  ArtRef r = GetArt(scene_, id_);
  if (r.a.desc.kinematic) return Eigen::VectorXd::Zero(r.dof());
  return GatherDofs(r, r.s.d()->qacc);
}

void Articulation::SetQacc(const Eigen::VectorXd& qacc) {
  ArtRef r = DynamicArt(scene_, id_, "set_qacc");
  CheckDofVector(qacc, r, "qacc");
  ScatterDofs(r, qacc, r.s.d()->qacc);
  ScatterDofs(r, qacc, r.s.d()->qacc_warmstart);
}

Eigen::VectorXd Articulation::GetQf() const {
  ArtRef r = GetArt(scene_, id_);
  if (r.a.desc.kinematic) return Eigen::VectorXd::Zero(r.dof());
  // the force on each partsim dof is G^T of the MuJoCo dof forces
  return r.c.G.transpose() * internal::MjDofs(r.c, r.s.d()->qfrc_applied);
}

void Articulation::SetQf(const Eigen::VectorXd& qf) {
  ArtRef r = DynamicArt(scene_, id_, "set_qf");
  CheckDofVector(qf, r, "qf");
  for (int mj : r.c.mj_dofs) r.s.d()->qfrc_applied[mj] = 0;
  for (int k = 0; k < r.dof(); ++k)
    r.s.d()->qfrc_applied[r.c.joints[r.c.dof_links[k]].dofadr] = qf[k];
  r.s.Invalidate();
}

Eigen::MatrixX2d Articulation::GetQlimits() const { return DofLimits(GetArt(scene_, id_).a.desc); }

void Articulation::SetQlimits(const Eigen::MatrixX2d& limits) {
  ArtRef r = GetArt(scene_, id_);
  if (limits.rows() != r.dof())
    throw Error("qlimits has " + std::to_string(limits.rows()) + " rows, " + r.owner() + " has " +
                std::to_string(r.dof()) + " dof");
  for (int k = 0; k < r.dof(); ++k)
    if (std::isnan(limits(k, 0)) || std::isnan(limits(k, 1)) || limits(k, 0) > limits(k, 1))
      throw Error("qlimits row " + std::to_string(k) + " must satisfy lower <= upper");
  for (int k = 0; k < r.dof(); ++k) {
    JointDesc& j = r.a.desc.links[r.c.dof_links[k]].joint;
    if (j.type == JointType::kContinuous) continue;
    j.lower = limits(k, 0);
    j.upper = limits(k, 1);
  }
  r.s.dirty = true;
  r.s.EnsureCompiled();
}

Pose Articulation::GetRootPose() const {
  ArtRef r = GetArt(scene_, id_);
  if (r.c.root_qposadr >= 0)
    return Pose(V3(r.s.d()->qpos + r.c.root_qposadr), Q4(r.s.d()->qpos + r.c.root_qposadr + 3));
  return r.a.desc.root_pose;
}

void Articulation::SetRootPose(const Pose& pose) {
  CheckPose("root pose", pose);
  ArtRef r = GetArt(scene_, id_);
  Eigen::Quaterniond q = pose.q.normalized();
  r.a.desc.root_pose = pose;
  if (r.c.root_qposadr >= 0) {
    double* dst = r.s.d()->qpos + r.c.root_qposadr;
    for (int k = 0; k < 3; ++k) dst[k] = pose.p[k];
    dst[3] = q.w(), dst[4] = q.x(), dst[5] = q.y(), dst[6] = q.z();
  } else if (r.a.desc.kinematic) {
    r.s.UpdateKinematicArticulation(r.a);
  } else {
    // a fixed root is welded to the world: move the weld in the model
    int b = r.c.link_body[0];
    for (size_t i = 0; i < r.a.desc.links.size(); ++i)
      if (r.a.desc.links[i].parent < 0) b = r.c.link_body[i];
    for (int k = 0; k < 3; ++k) r.s.m()->body_pos[3 * b + k] = pose.p[k];
    double* mq = r.s.m()->body_quat + 4 * b;
    mq[0] = q.w(), mq[1] = q.x(), mq[2] = q.y(), mq[3] = q.z();
  }
  r.s.Invalidate();
}

Eigen::Vector3d Articulation::GetRootVelocity() const {
  ArtRef r = GetArt(scene_, id_);
  if (r.c.root_dofadr < 0) return Eigen::Vector3d::Zero();
  return V3(r.s.d()->qvel + r.c.root_dofadr);
}

Eigen::Vector3d Articulation::GetRootAngularVelocity() const {
  ArtRef r = GetArt(scene_, id_);
  if (r.c.root_dofadr < 0) return Eigen::Vector3d::Zero();
  return Q4(r.s.d()->qpos + r.c.root_qposadr + 3).normalized() *
         V3(r.s.d()->qvel + r.c.root_dofadr + 3);
}

void Articulation::SetRootVelocity(const Eigen::Vector3d& v) {
  CheckFinite("root velocity", v);
  ArtRef r = GetArt(scene_, id_);
  if (r.c.root_dofadr < 0) throw Error(r.owner() + " has a fixed root: no root velocity to set");
  for (int k = 0; k < 3; ++k) r.s.d()->qvel[r.c.root_dofadr + k] = v[k];
  r.s.Invalidate();
}

void Articulation::SetRootAngularVelocity(const Eigen::Vector3d& w) {
  CheckFinite("root angular velocity", w);
  ArtRef r = GetArt(scene_, id_);
  if (r.c.root_dofadr < 0) throw Error(r.owner() + " has a fixed root: no root velocity to set");
  Eigen::Vector3d local = Q4(r.s.d()->qpos + r.c.root_qposadr + 3).normalized().conjugate() * w;
  for (int k = 0; k < 3; ++k) r.s.d()->qvel[r.c.root_dofadr + 3 + k] = local[k];
  r.s.Invalidate();
}

void Articulation::SetDriveTarget(const Eigen::VectorXd& target) {
  ArtRef r = GetArt(scene_, id_);
  CheckDofVector(target, r, "drive target");
  r.s.State(r.a).drive_target = target;
  r.s.Invalidate();
}

void Articulation::SetDriveVelocityTarget(const Eigen::VectorXd& velocity) {
  ArtRef r = GetArt(scene_, id_);
  CheckDofVector(velocity, r, "drive velocity target");
  r.s.State(r.a).drive_velocity_target = velocity;
  r.s.Invalidate();
}

Eigen::VectorXd Articulation::GetDriveTarget() const {
  ArtRef r = GetArt(scene_, id_);
  return r.s.State(r.a).drive_target;
}

Eigen::VectorXd Articulation::GetDriveVelocityTarget() const {
  ArtRef r = GetArt(scene_, id_);
  return r.s.State(r.a).drive_velocity_target;
}

void Articulation::SetDriveProperty(double stiffness, double damping, double force_limit) {
  for (Joint& j : GetActiveJoints()) j.SetDriveProperty(stiffness, damping, force_limit);
}

Eigen::VectorXd Articulation::ComputePassiveForce(bool gravity, bool coriolis,
                                                  bool external) const {
  ArtRef r = DynamicArt(scene_, id_, "compute_passive_force");
  r.s.EnsureForward();
  return internal::PassiveForce(r.s.model, r.s.data, id_, gravity, coriolis, external);
}

Eigen::VectorXd Articulation::ComputeForwardDynamics(const Eigen::VectorXd& qf) const {
  ArtRef r = DynamicArt(scene_, id_, "compute_forward_dynamics");
  CheckDofVector(qf, r, "qf");
  r.s.EnsureForward();
  return internal::ForwardDynamics(r.s.model, r.s.data, id_, qf);
}

Eigen::VectorXd Articulation::ComputeInverseDynamics(const Eigen::VectorXd& qacc) const {
  ArtRef r = DynamicArt(scene_, id_, "compute_inverse_dynamics");
  CheckDofVector(qacc, r, "qacc");
  r.s.EnsureForward();
  return internal::InverseDynamics(r.s.model, r.s.data, id_, qacc);
}

Eigen::MatrixXd Articulation::ComputeManipulatorInertiaMatrix() const {
  ArtRef r = DynamicArt(scene_, id_, "compute_manipulator_inertia_matrix");
  r.s.EnsureForward();
  return internal::MassMatrix(r.s.model, r.s.data, id_);
}

Eigen::MatrixXd Articulation::ComputeLinkJacobian(int index) const {
  ArtRef r = DynamicArt(scene_, id_, "compute_link_jacobian");
  LinkBody(r.s, id_, index);  // throws for an index out of range
  r.s.EnsureKinematics();
  return internal::LinkJacobian(r.s.model, r.s.data, id_, index);
}

void Articulation::DisableCollision(const Link& a, const Link& b) {
  ArtRef r = GetArt(scene_, id_);
  std::string names[2];
  const Link* links[2] = {&a, &b};
  for (int k = 0; k < 2; ++k) {
    const Link& l = *links[k];
    if (l.GetScene() != scene_ || l.GetArticulationId() != id_)
      throw Error("disable_collision: the link does not belong to " + r.owner());
    names[k] = LinkAt(r.s, id_, l.GetIndex()).name;
    if (names[k].empty())
      throw Error("disable_collision: link " + std::to_string(l.GetIndex()) + " of " + r.owner() +
                  " has no name");
  }
  auto pair = std::make_pair(names[0], names[1]);
  auto& pairs = r.a.desc.disabled_collisions;
  auto swapped = std::make_pair(pair.second, pair.first);
  if (std::find(pairs.begin(), pairs.end(), pair) != pairs.end() ||
      std::find(pairs.begin(), pairs.end(), swapped) != pairs.end())
    return;
  pairs.push_back(pair);
  // excluded pairs are part of the compiled model: recompile, keeping the state
  r.s.dirty = true;
  r.s.EnsureCompiled();
}

Eigen::MatrixXd Articulation::GetLinkIncomingJointForces() const {
  ArtRef r = DynamicArt(scene_, id_, "get_link_incoming_joint_forces");
  r.s.EnsureForward();
  const mjModel* m = r.s.m();
  mjData* d = r.s.d();
  // cfrc_int: the com-based force each body gets from its parent (torque about the subtree
  // centre of mass of its tree's root, then force, world axes)
  mj_rnePostConstraint(m, d);
  const int n = static_cast<int>(r.a.desc.links.size());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, 6);
  for (int i = 0; i < n; ++i) {
    if (r.a.desc.links[i].parent < 0) continue;  // the root has no joint to a parent
    const int body = LinkBody(r.s, id_, i);
    const Eigen::Vector3d c = V3(d->subtree_com + 3 * m->body_rootid[body]);
    const Eigen::Vector3d torque_c = V3(d->cfrc_int + 6 * body);
    const Eigen::Vector3d force = V3(d->cfrc_int + 6 * body + 3);
    const Pose joint = Link(scene_, id_, i).GetPose() * r.a.desc.links[i].joint.pose_in_child;
    const Eigen::Vector3d torque = torque_c + (c - joint.p).cross(force);
    const Eigen::Matrix3d rt = joint.q.toRotationMatrix().transpose();
    out.row(i).head<3>() = (rt * force).transpose();
    out.row(i).tail<3>() = (rt * torque).transpose();
  }
  return out;
}

Eigen::MatrixXd Articulation::ComputeWorldCartesianJacobian() const {
  ArtRef r = DynamicArt(scene_, id_, "compute_world_cartesian_jacobian");
  int n = static_cast<int>(r.a.desc.links.size());
  Eigen::MatrixXd out(6 * n, r.dof());
  for (int i = 0; i < n; ++i) out.middleRows(6 * i, 6) = ComputeLinkJacobian(i);
  return out;
}

// ---------------------------------------------------------------------------------------------
// frame motion (partsim/physics/frame_motion.h)

namespace {

FrameMotion BodyFrame(SceneImpl& s, int body, const Pose& X_WB, const Pose& offset) {
  CheckPose("offset", offset);
  Pose X_BS = offset;
  X_BS.q.normalize();
  s.EnsureForward();
  FrameMotion out;
  out.pose = X_WB * X_BS;
  const internal::BodyFrameMotion m = internal::FrameMotion(s.model, s.data, body, out.pose.p);
  out.linear_velocity = m.linear_velocity;
  out.angular_velocity = m.angular_velocity;
  out.linear_acceleration = m.linear_acceleration;
  out.angular_acceleration = m.angular_acceleration;
  out.time = s.d()->time;
  return out;
}

}  // namespace

FrameMotion ComputeFrameMotion(const Link& link, const Pose& offset) {
  const Pose X_WL = link.GetPose();  // throws for an empty or removed handle
  SceneImpl& s = S(link.GetScene());
  return BodyFrame(s, LinkBody(s, link.GetArticulationId(), link.GetIndex()), X_WL, offset);
}

FrameMotion ComputeFrameMotion(const Actor& actor, const Pose& offset) {
  const Pose X_WA = actor.GetPose();
  SceneImpl& s = S(actor.GetScene());
  return BodyFrame(s, s.Compiled(s.GetActor(actor.GetId())).body, X_WA, offset);
}

}  // namespace partsim
