// Names of enum values and validation of descriptions.
#include "partsim/physics/description.h"

#include <cmath>
#include <set>

#include "partsim/core/check.h"
#include "partsim/core/error.h"

namespace partsim {

const char* ShapeTypeName(ShapeType t) {
  switch (t) {
    case ShapeType::kBox:
      return "box";
    case ShapeType::kSphere:
      return "sphere";
    case ShapeType::kCapsule:
      return "capsule";
    case ShapeType::kCylinder:
      return "cylinder";
    case ShapeType::kConvexMesh:
      return "convex_mesh";
    case ShapeType::kPlane:
      return "plane";
  }
  return "?";
}

const char* ActorTypeName(ActorType t) {
  switch (t) {
    case ActorType::kStatic:
      return "static";
    case ActorType::kKinematic:
      return "kinematic";
    case ActorType::kDynamic:
      return "dynamic";
  }
  return "?";
}

const char* JointTypeName(JointType t) {
  switch (t) {
    case JointType::kFixed:
      return "fixed";
    case JointType::kRevolute:
      return "revolute";
    case JointType::kContinuous:
      return "continuous";
    case JointType::kPrismatic:
      return "prismatic";
    case JointType::kScrew:
      return "screw";
  }
  return "?";
}

double DriveVelocityGain(const DriveDesc& drive, double dt) {
  return drive.damping + drive.stiffness * dt;
}

double DriveArmature(const DriveDesc& drive, double dt) {
  return dt * DriveVelocityGain(drive, dt);
}

namespace {

std::string Prefix(const std::string& where) { return where.empty() ? "" : where + ": "; }

// Throws Error("<where>: <message()>") unless `ok`. The message is made only then: Validate
// runs these checks for every link and joint, and formatting their messages (a pose each) took
// half the load time of a wide URDF.
template <class Message>
void Require(bool ok, const std::string& where, const Message& message) {
  if (!ok) throw Error(Prefix(where) + std::string(message()));
}

// Largest coordinate or size (m) a description may hold: past it MuJoCo's arithmetic overflows
// (an origin of 1e308 or a box of 1e300 made every state NaN).
constexpr double kMaxLength = 1e6;
// Largest mass (kg) and principal moment of inertia (kg m^2): kMaxMass at kMaxLength from its
// axis. A mass of 1e308 made every state NaN after one step.
constexpr double kMaxMass = 1e9;
constexpr double kMaxInertia = kMaxMass * kMaxLength * kMaxLength;

void CheckPose(const Pose& pose, const std::string& where, const std::string& what) {
  Require(pose.p.allFinite(), where,
          [&] { return what + " has a non-finite position " + pose.ToString(); });
  Require(pose.p.cwiseAbs().maxCoeff() <= kMaxLength, where,
          [&] { return what + " has a position beyond 1e6 m " + pose.ToString(); });
  Require(pose.q.coeffs().allFinite() && pose.q.norm() > 1e-6, where,
          [&] { return what + " has an invalid rotation " + pose.ToString(); });
}

void CheckNonNegative(double v, const std::string& where, const std::string& what) {
  Require(std::isfinite(v) && v >= 0.0, where,
          [&] { return what + " must be finite and >= 0, got " + FormatNumber(v); });
}

void CheckPositive(double v, const std::string& where, const std::string& what) {
  Require(std::isfinite(v) && v > 0.0, where,
          [&] { return what + " must be finite and > 0, got " + FormatNumber(v); });
}

// A shape's size: > 0 (or >= 0) and at most kMaxLength.
void CheckLength(double v, bool allow_zero, const std::string& where, const std::string& what) {
  Require(std::isfinite(v) && (allow_zero ? v >= 0.0 : v > 0.0) && v <= kMaxLength, where, [&] {
    return what + " must be " + (allow_zero ? ">= 0" : "> 0") + " and at most 1e6 m, got " +
           FormatNumber(v);
  });
}

void CheckMaterial(const PhysicalMaterial& m, const std::string& where, const std::string& what) {
  CheckNonNegative(m.static_friction, where, what + " static_friction");
  CheckNonNegative(m.dynamic_friction, where, what + " dynamic_friction");
  Require(std::isfinite(m.restitution) && m.restitution >= 0 && m.restitution <= 1, where, [&] {
    return what + " restitution must be in [0, 1], got " + FormatNumber(m.restitution);
  });
}

void CheckBody(const BodyDesc& b, const std::string& where, const std::string& what) {
  for (size_t i = 0; i < b.collisions.size(); ++i) {
    const CollisionShape& s = b.collisions[i];
    std::string w =
        what + " collision shape " + std::to_string(i) + " (" + ShapeTypeName(s.type) + ")";
    CheckPose(s.pose, where, w + " pose");
    CheckPositive(s.density, where, w + " density");
    if (s.material) CheckMaterial(*s.material, where, w + " material");
    switch (s.type) {
      case ShapeType::kBox:
        for (int k = 0; k < 3; ++k) CheckLength(s.half_size[k], false, where, w + " half_size");
        break;
      case ShapeType::kSphere:
        CheckLength(s.radius, false, where, w + " radius");
        break;
      case ShapeType::kCapsule:
        CheckLength(s.radius, false, where, w + " radius");
        CheckLength(s.half_length, true, where, w + " half_length");
        break;
      case ShapeType::kCylinder:
        CheckLength(s.radius, false, where, w + " radius");
        CheckLength(s.half_length, false, where, w + " half_length");
        break;
      case ShapeType::kPlane:
        break;
      case ShapeType::kConvexMesh: {
        Require(s.mesh != nullptr, where, [&] { return w + " has no mesh"; });
        std::string src = s.mesh->source.empty() ? "" : " from " + s.mesh->source;
        Require(s.mesh->vertices.size() >= 4, where, [&] {
          return w + src + " needs at least 4 vertices, has " +
                 std::to_string(s.mesh->vertices.size());
        });
        Eigen::Vector3f lo = s.mesh->vertices[0], hi = lo;
        for (const auto& v : s.mesh->vertices) {
          Require(
              v.allFinite() && v.cwiseAbs().maxCoeff() <= static_cast<float>(kMaxLength), where,
              [&] { return w + src + " has a vertex that is not finite or lies beyond 1e6 m"; });
          lo = lo.cwiseMin(v);
          hi = hi.cwiseMax(v);
        }
        Eigen::Vector3f ext = hi - lo;
        Require(ext.minCoeff() > 1e-6f * std::max(1e-3f, ext.maxCoeff()), where,
                [&] { return w + src + " is flat (its convex hull has no volume)"; });
        break;
      }
    }
  }
  if (b.inertial) {
    CheckPositive(b.inertial->mass, where, what + " mass");
    Require(b.inertial->mass <= kMaxMass, where, [&] {
      return what + " mass must be at most 1e9 kg, got " + FormatNumber(b.inertial->mass);
    });
    for (int k = 0; k < 3; ++k) {
      CheckPositive(b.inertial->inertia[k], where, what + " inertia");
      Require(b.inertial->inertia[k] <= kMaxInertia, where, [&] {
        return what + " inertia must be at most 1e21 kg m^2, got " +
               FormatNumber(b.inertial->inertia[k]);
      });
    }
    CheckPose(b.inertial->cmass_local_pose, where, what + " centre-of-mass pose");
  }
}

}  // namespace

void Validate(const PhysicalMaterial& material, const std::string& where) {
  CheckMaterial(material, where, "material");
}

void Validate(const ActorDesc& a, const std::string& where) {
  std::string what = "actor '" + a.name + "'";
  CheckPose(a.pose, where, what + " pose");
  CheckBody(a, where, what);
  Require(std::isfinite(a.linear_damping) && a.linear_damping >= 0 &&
              std::isfinite(a.angular_damping) && a.angular_damping >= 0,
          where, [&] {
            return what + " damping must be finite and >= 0, got linear " +
                   FormatNumber(a.linear_damping) + ", angular " + FormatNumber(a.angular_damping);
          });
}

void Validate(const ArticulationDesc& art, const std::string& where) {
  std::string what = "articulation '" + art.name + "'";
  Require(!art.links.empty(), where, [&] { return what + " has no links"; });
  CheckPose(art.root_pose, where, what + " root pose");
  int roots = 0;
  std::set<std::string> link_names, joint_names;
  for (size_t i = 0; i < art.links.size(); ++i) {
    const LinkDesc& l = art.links[i];
    std::string lw = what + " link " + std::to_string(i) + " '" + l.name + "'";
    if (!l.name.empty())
      Require(link_names.insert(l.name).second, where,
              [&] { return "duplicate link name '" + l.name + "'"; });
    CheckBody(l, where, lw);
    if (l.parent < 0) {
      ++roots;
      continue;
    }
    Require(l.parent < static_cast<int>(i), where, [&] {
      return lw + " has parent " + std::to_string(l.parent) +
             ", which does not come before it (links must be listed parents first)";
    });
    const JointDesc& j = l.joint;
    std::string jw = "joint '" + j.name + "' of " + lw;
    if (!j.name.empty())
      Require(joint_names.insert(j.name).second, where,
              [&] { return "duplicate joint name '" + j.name + "'"; });
    CheckPose(j.pose_in_parent, where, jw + " pose_in_parent");
    CheckPose(j.pose_in_child, where, jw + " pose_in_child");
    Require(!std::isnan(j.lower) && !std::isnan(j.upper), where,
            [&] { return jw + " has a NaN limit"; });
    Require(j.lower <= j.upper, where, [&] {
      return jw + " has lower limit " + FormatNumber(j.lower) + " above upper limit " +
             FormatNumber(j.upper);
    });
    CheckNonNegative(j.friction, where, jw + " friction");
    CheckNonNegative(j.damping, where, jw + " damping");
    CheckNonNegative(j.armature, where, jw + " armature");
    Require(std::isfinite(j.pitch), where, [&] { return jw + " pitch must be finite"; });
    Require(j.effort_limit > 0, where, [&] {
      return jw + " effort_limit must be > 0 (inf for none), got " + FormatNumber(j.effort_limit);
    });
    CheckNonNegative(j.drive.stiffness, where, jw + " drive stiffness");
    CheckNonNegative(j.drive.damping, where, jw + " drive damping");
    Require(!std::isnan(j.drive.force_limit) && j.drive.force_limit > 0, where,
            [&] { return jw + " drive force_limit must be > 0"; });
    Require(std::isfinite(j.drive.target) && std::isfinite(j.drive.velocity_target), where,
            [&] { return jw + " drive target must be finite"; });
  }
  Require(roots == 1, where,
          [&] { return what + " must have exactly one root link, has " + std::to_string(roots); });
  // couplings name existing, independent joints
  std::set<std::string> coupled;
  for (const JointCoupling& c : art.couplings) {
    auto find = [&](const std::string& name) -> const LinkDesc* {
      for (const LinkDesc& l : art.links)
        if (l.parent >= 0 && l.joint.name == name) return &l;
      return nullptr;
    };
    std::string cw = "coupling of joint '" + c.joint + "' to '" + c.source + "'";
    const LinkDesc* j = find(c.joint);
    const LinkDesc* s = find(c.source);
    Require(j != nullptr, where, [&] { return cw + ": joint '" + c.joint + "' does not exist"; });
    Require(s != nullptr, where,
            [&] { return cw + ": source joint '" + c.source + "' does not exist"; });
    Require(c.joint != c.source, where, [&] { return cw + ": a joint cannot follow itself"; });
    Require(j->joint.type != JointType::kFixed && s->joint.type != JointType::kFixed, where,
            [&] { return cw + ": both joints must move"; });
    Require(std::isfinite(c.multiplier) && std::isfinite(c.offset), where,
            [&] { return cw + ": multiplier and offset must be finite"; });
    Require(coupled.insert(c.joint).second, where, [&] { return cw + ": joint is coupled twice"; });
  }
  for (const JointCoupling& c : art.couplings)
    Require(!coupled.count(c.source), where, [&] {
      return "joint '" + c.joint + "' follows '" + c.source + "', which itself follows another";
    });
  // pairs that never collide name existing links
  for (const auto& pair : art.disabled_collisions) {
    for (const std::string& name : {pair.first, pair.second})
      Require(!name.empty() && link_names.count(name), where, [&] {
        return what + ": disabled collision pair ('" + pair.first + "', '" + pair.second +
               "') names link '" + name + "', which does not exist";
      });
  }
}

namespace {

void NormalizeBody(BodyDesc* b) {
  for (CollisionShape& c : b->collisions) c.pose.q.normalize();
  for (VisualShape& v : b->visuals) v.pose.q.normalize();
  if (b->inertial) b->inertial->cmass_local_pose.q.normalize();
}

}  // namespace

void NormalizeRotations(ActorDesc* actor) {
  actor->pose.q.normalize();
  NormalizeBody(actor);
}

void NormalizeRotations(ArticulationDesc* articulation) {
  articulation->root_pose.q.normalize();
  for (LinkDesc& l : articulation->links) {
    l.joint.pose_in_parent.q.normalize();
    l.joint.pose_in_child.q.normalize();
    NormalizeBody(&l);
  }
}

}  // namespace partsim
