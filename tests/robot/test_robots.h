// Small robots shared by the robot tests, built with the ArticulationBuilder (no URDF, no
// robots.cc): a 7-dof arm of capsules with a telescoping (prismatic) joint, a 2-link planar arm
// with closed-form kinematics, and a vertical slider.
#pragma once

#include <cmath>
#include <initializer_list>

#include "partsim/physics/scene.h"

namespace partsim::testing {

/// A vector from a list: V({1, 2, 3}).
inline Eigen::VectorXd V(std::initializer_list<double> v) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(v.size()));
  int i = 0;
  for (double x : v) out[i++] = x;
  return out;
}

/// Rotations that carry a joint's x axis onto z and onto y.
inline Eigen::Quaterniond XToZ() {
  return Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()));
}
inline Eigen::Quaterniond XToY() {
  return Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
}

/// A fixed-base 7-dof arm standing up along z at `root`: joints z, y, z, prismatic z (0 to
/// 0.15 m), y, z, y, then a fixed "hand" link 0.1 m beyond the last joint: 1.26 m from the shoulder
/// (j2, 0.3 m above the root) to the hand. The base box stays clear of link1 (a link welded to
/// the world collides with its child).
/// The last joint has a pose_in_child with an offset and a rotation.
inline Articulation AddArm7(Scene& scene, const Pose& root = Pose(),
                            const std::string& name = "arm7") {
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.SetName(name);
  b.SetInitialPose(root);
  const Eigen::Quaterniond z = XToZ(), y = XToY();
  LinkBuilder* base = b.CreateLinkBuilder();
  base->SetName("base").AddBoxCollision(Pose(Eigen::Vector3d(0, 0, 0.025)),
                                        Eigen::Vector3d(0.08, 0.08, 0.025));
  struct J {
    const char* name;
    JointType type;
    Eigen::Quaterniond axis;
    double lo, hi, offset, length;
  };
  const J joints[] = {{"j1", JointType::kRevolute, z, -2.9, 2.9, 0.1, 0.2},
                      {"j2", JointType::kRevolute, y, -1.8, 1.8, 0.2, 0.3},
                      {"j3", JointType::kRevolute, z, -2.9, 2.9, 0.3, 0.1},
                      {"j4", JointType::kPrismatic, z, 0.0, 0.15, 0.1, 0.25},
                      {"j5", JointType::kRevolute, y, -2.5, 2.5, 0.25, 0.2},
                      {"j6", JointType::kRevolute, z, -2.9, 2.9, 0.2, 0.16},
                      {"j7", JointType::kRevolute, y, -2.0, 2.0, 0.16, 0.1}};
  LinkBuilder* parent = base;
  for (int i = 0; i < 7; ++i) {
    const J& j = joints[i];
    LinkBuilder* l = b.CreateLinkBuilder(parent);
    Pose in_child(Eigen::Vector3d::Zero(), j.axis);
    if (i == 6) {
      // a child frame that is neither at nor aligned with the joint frame
      Eigen::Quaterniond extra(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
      in_child = Pose(Eigen::Vector3d(0.01, -0.02, 0.03), extra * j.axis);
    }
    l->SetName(std::string("link") + std::to_string(i + 1))
        .SetJointName(j.name)
        .SetJointProperties(j.type, Eigen::Vector2d(j.lo, j.hi),
                            Pose(Eigen::Vector3d(0, 0, j.offset), j.axis), in_child);
    // a capsule along the link's nominal z, from the joint to the next one
    Pose X_CN = in_child.Inverse() * Pose(Eigen::Vector3d::Zero(), j.axis);
    l->AddCapsuleCollision(X_CN * Pose(Eigen::Vector3d(0, 0, j.length / 2), z), 0.03, j.length / 2);
    parent = l;
  }
  LinkBuilder* hand = b.CreateLinkBuilder(parent);
  hand->SetName("hand")
      .SetJointName("hand_joint")
      .SetJointProperties(JointType::kFixed, Eigen::Vector2d(0, 0),
                          Pose(Eigen::Vector3d(0, 0, 0.1)), Pose())
      .AddBoxCollision(Pose(), Eigen::Vector3d(0.02, 0.05, 0.02));
  return b.Build(/*fix_root_link=*/true);
}

/// A planar arm in the xy plane (gravity-free directions): revolute joints about z at the origin
/// and at (l1, 0, 0), and a fixed "tip" link at (l2, 0, 0) from the second joint. Tip position:
/// (l1 cos q1 + l2 cos(q1 + q2), l1 sin q1 + l2 sin(q1 + q2), 0).
inline Articulation AddPlanar2(Scene& scene, double l1 = 0.5, double l2 = 0.4, double limit = 3.0) {
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.SetName("planar");
  const Eigen::Quaterniond z = XToZ();
  LinkBuilder* base = b.CreateLinkBuilder();
  base->SetName("base");  // no shape: it would collide with the upper arm
  LinkBuilder* a = b.CreateLinkBuilder(base);
  a->SetName("upper")
      .SetJointName("shoulder")
      .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-limit, limit),
                          Pose(Eigen::Vector3d::Zero(), z), Pose(Eigen::Vector3d::Zero(), z))
      .AddCapsuleCollision(Pose(Eigen::Vector3d(l1 / 2, 0, 0)), 0.02, l1 / 2 - 0.03);
  LinkBuilder* f = b.CreateLinkBuilder(a);
  f->SetName("fore")
      .SetJointName("elbow")
      .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-limit, limit),
                          Pose(Eigen::Vector3d(l1, 0, 0), z), Pose(Eigen::Vector3d::Zero(), z))
      .AddCapsuleCollision(Pose(Eigen::Vector3d(l2 / 2, 0, 0)), 0.02, l2 / 2 - 0.03);
  LinkBuilder* tip = b.CreateLinkBuilder(f);
  tip->SetName("tip")
      .SetJointName("tip_joint")
      .SetJointProperties(JointType::kFixed, Eigen::Vector2d(0, 0), Pose(Eigen::Vector3d(l2, 0, 0)),
                          Pose())
      .SetMassAndInertia(0.01, Pose(), Eigen::Vector3d::Constant(1e-5));
  return b.Build(/*fix_root_link=*/true);
}

/// A carriage of mass 1 kg on a vertical prismatic joint (limits -0.5 to 0.5 m).
inline Articulation AddSlider(Scene& scene) {
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.SetName("slider");
  LinkBuilder* base = b.CreateLinkBuilder();
  base->SetName("rail").AddBoxCollision(Pose(Eigen::Vector3d(0, 0.2, 0)),
                                        Eigen::Vector3d(0.02, 0.02, 0.6));
  LinkBuilder* c = b.CreateLinkBuilder(base);
  c->SetName("carriage")
      .SetJointName("slide")
      .SetJointProperties(JointType::kPrismatic, Eigen::Vector2d(-0.5, 0.5),
                          Pose(Eigen::Vector3d(0, 0, 1), XToZ()),
                          Pose(Eigen::Vector3d::Zero(), XToZ()))
      .AddBoxCollision(Pose(), Eigen::Vector3d(0.05, 0.05, 0.05))
      .SetMassAndInertia(1.0, Pose(), Eigen::Vector3d::Constant(1e-3));
  return b.Build(/*fix_root_link=*/true);
}

}  // namespace partsim::testing
