// A real robot description (7-joint arm with a two-finger gripper; DAE visuals, STL collisions,
// package:// paths, a mimic finger) loaded into a scene.
#include <gtest/gtest.h>

#include "partsim/assets/urdf.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

const std::string kPanda =
    std::string(PARTSIM_TEST_DATA_DIR) + "/arm/arm_description/urdf/panda.urdf";

TEST(RobotTest, ArmHoldsItsPoseUnderGravityWithDrivesOnTheInitialPose) {
  Scene scene;
  scene.AddGround(0.0);
  UrdfLoader loader = CreateUrdfLoader(scene);
  loader.fix_root_link = true;
  Articulation arm = loader.Load(kPanda);
  // 7 arm joints + 2 fingers (the second a dof of its own that follows the first)
  ASSERT_EQ(arm.Dof(), 9);
  EXPECT_EQ(arm.FindJointByName("panda_finger_joint2").GetDof(), 1);
  int visuals = 0, meshes = 0;
  for (const Link& l : arm.GetLinks()) {
    visuals += static_cast<int>(l.GetDesc().visuals.size());
    for (const CollisionShape& s : l.GetDesc().collisions)
      meshes += s.type == ShapeType::kConvexMesh;
  }
  EXPECT_GE(visuals, 10);
  EXPECT_GE(meshes, 10);

  Eigen::VectorXd home(9);
  home << 0.0, -0.4, 0.0, -2.1, 0.0, 1.8, 0.8, 0.03, 0.03;
  arm.SetQpos(home);
  std::vector<Joint> joints = arm.GetActiveJoints();
  for (size_t k = 0; k < joints.size(); ++k) {
    // effort limits of the file stay as force limits
    double limit = joints[k].GetDriveForceLimit();
    EXPECT_GT(limit, 0);
    joints[k].SetDriveProperty(k < 7 ? 2000 : 500, k < 7 ? 200 : 50, limit);
  }
  arm.SetDriveTarget(home);
  Pose hand0 = arm.FindLinkByName("panda_hand").GetPose();
  scene.Step(1000);  // 2 s
  Eigen::VectorXd q = arm.GetQpos();
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(q[k], home[k], 0.02) << "dof " << k;
  Pose hand = arm.FindLinkByName("panda_hand").GetPose();
  EXPECT_LT((hand.p - hand0.p).norm(), 0.01);
  EXPECT_LT(arm.GetQvel().norm(), 1e-2);
  // the mimic finger mirrors the first
  Pose f1 = arm.FindLinkByName("panda_leftfinger").GetPose();
  Pose f2 = arm.FindLinkByName("panda_rightfinger").GetPose();
  EXPECT_NEAR((f1.p - f2.p).norm(), 2 * home[7], 0.01);
}

TEST(RobotTest, ArmWithoutDrivesFallsUnderGravity) {
  Scene scene;
  Articulation arm = CreateUrdfLoader(scene).Load(kPanda);
  Eigen::VectorXd home(9);
  home << 0.0, -0.4, 0.0, -2.1, 0.0, 1.8, 0.8, 0.03, 0.03;
  arm.SetQpos(home);
  scene.Step(250);
  EXPECT_GT((arm.GetQpos() - home).norm(), 0.1);
}

TEST(RobotTest, NumericalBlowUpIsAWarningAndTheSceneStaysUsable) {
  Scene scene;
  scene.AddGround(0.0);
  Actor box = scene.CreateActorBuilder()
                  .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1))
                  .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 0.5)))
                  .Build();
  box.SetVelocity(Eigen::Vector3d(0, 0, 1e30));
  box.SetAngularVelocity(Eigen::Vector3d(1e30, 0, 0));
  scene.Step(3);
  ASSERT_FALSE(scene.GetWarnings().empty());
  EXPECT_TRUE(box.GetPose().p.allFinite());
  scene.ClearWarnings();
  scene.Step(500);
  EXPECT_TRUE(scene.GetWarnings().empty());
  EXPECT_NEAR(box.GetPose().p.z(), 0.1, 5e-3);
}

}  // namespace
}  // namespace partsim
