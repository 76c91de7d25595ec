// Small worlds shared by the physics tests.
#pragma once

#include "partsim/physics/scene.h"

namespace partsim::testing {

/// A box of half-size h (density 1000) at height z above a ground plane.
inline Actor AddBox(Scene& scene, double h, double z, const std::string& name = "box") {
  return scene.CreateActorBuilder()
      .SetName(name)
      .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(h))
      .AddBoxVisual(Pose(), Eigen::Vector3d::Constant(h))
      .SetInitialPose(Pose(Eigen::Vector3d(0, 0, z)))
      .Build();
}

/// A fixed-base arm: revolute (about z), revolute (about y), prismatic (along the last link),
/// and a screw joint at the tip. Joint axes are the x axes of their frames.
inline Articulation AddArm(Scene& scene, bool kinematic = false, bool with_screw = true) {
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.SetName("arm");
  const Eigen::Quaterniond x_to_z(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()));
  const Eigen::Quaterniond x_to_y(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  LinkBuilder* base = b.CreateLinkBuilder();
  base->SetName("base").AddBoxCollision(Pose(), Eigen::Vector3d(0.1, 0.1, 0.05));
  LinkBuilder* l1 = b.CreateLinkBuilder(base);
  l1->SetName("l1")
      .SetJointName("j1")
      .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-3, 3),
                          Pose(Eigen::Vector3d(0, 0, 0.1), x_to_z),
                          Pose(Eigen::Vector3d::Zero(), x_to_z))
      .AddCapsuleCollision(Pose(Eigen::Vector3d(0, 0, 0.15), x_to_z), 0.04, 0.1);
  LinkBuilder* l2 = b.CreateLinkBuilder(l1);
  l2->SetName("l2")
      .SetJointName("j2")
      .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-2, 2),
                          Pose(Eigen::Vector3d(0, 0, 0.3), x_to_y),
                          Pose(Eigen::Vector3d::Zero(), x_to_y))
      .AddBoxCollision(Pose(Eigen::Vector3d(0.15, 0, 0)), Eigen::Vector3d(0.15, 0.03, 0.03));
  LinkBuilder* l3 = b.CreateLinkBuilder(l2);
  l3->SetName("l3")
      .SetJointName("j3")
      .SetJointProperties(JointType::kPrismatic, Eigen::Vector2d(-0.1, 0.2),
                          Pose(Eigen::Vector3d(0.3, 0, 0)), Pose())
      .AddBoxCollision(Pose(Eigen::Vector3d(0.1, 0, 0)), Eigen::Vector3d(0.1, 0.02, 0.02));
  if (with_screw) {
    LinkBuilder* l4 = b.CreateLinkBuilder(l3);
    l4->SetName("cap")
        .SetJointName("j4")
        .SetJointProperties(JointType::kScrew, Eigen::Vector2d(-6, 6),
                            Pose(Eigen::Vector3d(0.2, 0, 0)), Pose())
        .SetScrewPitch(0.01)
        .AddCylinderCollision(Pose(Eigen::Vector3d(0.02, 0, 0)), 0.03, 0.02);
  }
  return kinematic ? b.BuildKinematic() : b.Build(/*fix_root_link=*/true);
}

}  // namespace partsim::testing
