// Queries of the scene's state: rays, an actor's mass properties as compiled, the forces links get
// through their joints; each against a closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "partsim/physics/scene.h"
#include "physics/test_worlds.h"

namespace partsim {
namespace {

constexpr double kG = 9.81;

Actor AddBlock(Scene& scene) {
  return scene.CreateActorBuilder()
      .SetName("block")
      .AddBoxCollision(Pose(), Eigen::Vector3d(0.1, 0.2, 0.3))
      .SetInitialPose(Pose(Eigen::Vector3d(1, 0, 0.3)))
      .BuildStatic();
}

TEST(RaycastTest, ARayMeetsTheFirstShapeWithItsNormalAndOwner) {
  Scene scene;
  scene.AddGround(0.0);
  AddBlock(scene);
  // not normalized: the direction is normalized, the distance is along the ray in metres
  auto hit = scene.Raycast(Eigen::Vector3d(0, 0, 0.2), Eigen::Vector3d(2, 0, 0), 10.0);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->distance, 0.9, 1e-9);
  EXPECT_TRUE(hit->position.isApprox(Eigen::Vector3d(0.9, 0, 0.2), 1e-9));
  EXPECT_TRUE(hit->normal.isApprox(Eigen::Vector3d(-1, 0, 0), 1e-9));
  EXPECT_EQ(hit->body.kind, ContactBody::Kind::kActor);
  EXPECT_EQ(hit->body.name, "block");
  EXPECT_EQ(hit->body.shape_index, 0);
  // the ground from above; nothing behind; nothing within a shorter distance
  auto down = scene.Raycast(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1), 10.0);
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(down->distance, 1.0, 1e-9);
  EXPECT_TRUE(down->normal.isApprox(Eigen::Vector3d(0, 0, 1), 1e-9));
  EXPECT_EQ(down->body.name, "ground");
  EXPECT_FALSE(scene.Raycast(Eigen::Vector3d(0, 0, 0.2), Eigen::Vector3d(-1, 0, 0), 10.0));
  EXPECT_FALSE(scene.Raycast(Eigen::Vector3d(0, 0, 0.2), Eigen::Vector3d(1, 0, 0), 0.5));
}

TEST(RaycastTest, ARayNamesTheLinkItMeets) {
  Scene scene;
  Articulation arm = testing::AddArm(scene);
  arm.SetQpos(Eigen::VectorXd::Zero(arm.Dof()));
  // straight down onto the base (a 0.1 m half-height box at the root)
  auto hit = scene.Raycast(Eigen::Vector3d(0.08, 0.08, 1), Eigen::Vector3d(0, 0, -1), 5.0);
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->body.kind, ContactBody::Kind::kLink);
  EXPECT_EQ(hit->body.articulation_id, arm.GetId());
  EXPECT_EQ(hit->body.name, "base");
  EXPECT_NEAR(hit->distance, 0.95, 1e-9);
}

TEST(RaycastTest, BadRaysAreRefusedNamingTheArgument) {
  Scene scene;
  Actor block = AddBlock(scene);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(
      {
        try {
          scene.Raycast(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1.0);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("direction"), std::string::npos);
          throw;
        }
      },
      Error);
  EXPECT_THROW(scene.Raycast(Eigen::Vector3d(nan, 0, 0), Eigen::Vector3d::UnitX(), 1.0), Error);
  EXPECT_THROW(scene.Raycast(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), -1.0), Error);
  scene.Step();
  EXPECT_TRUE(scene.Raycast(Eigen::Vector3d(0, 0, 0.2), Eigen::Vector3d::UnitX(), 2.0));
  EXPECT_NEAR(block.GetPose().p.z(), 0.3, 1e-12);
}

TEST(ActorMassTest, InertiaAndCentreOfMassAsCompiled) {
  Scene scene;
  Actor block =
      scene.CreateActorBuilder()
          .AddBoxCollision(Pose(Eigen::Vector3d(0.05, 0, 0)), Eigen::Vector3d(0.1, 0.2, 0.3))
          .SetInitialPose(Pose(Eigen::Vector3d(1, 2, 3)))
          .Build();
  EXPECT_NEAR(block.GetMass(), 48.0, 1e-9);
  // a box of half sizes a, b, c: m/3 (b^2 + c^2, a^2 + c^2, a^2 + b^2), in some order of axes
  Eigen::Vector3d moments = block.GetInertia();
  std::sort(moments.data(), moments.data() + 3);
  EXPECT_TRUE(moments.isApprox(Eigen::Vector3d(0.8, 1.6, 2.08), 1e-9)) << moments.transpose();
  EXPECT_TRUE(block.GetCMassPose().p.isApprox(Eigen::Vector3d(1.05, 2, 3), 1e-12));
}

// A fixed root and a 1 kg box 0.3 m out along a hinge about the world's y, held level by a
// stiff drive (SAPIEN's own pendulum; the joint's frame turns x onto the hinge axis).
Articulation AddHeldPendulum(Scene& scene, bool fixed) {
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  const Eigen::Quaterniond about_y(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  LinkBuilder* root = b.CreateLinkBuilder();
  root->SetName("root").AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.05));
  LinkBuilder* arm = b.CreateLinkBuilder(root);
  arm->SetName("arm")
      .SetJointName("hinge")
      .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-3, 3),
                          Pose(Eigen::Vector3d(0, 0, 1), about_y),
                          Pose(Eigen::Vector3d::Zero(), about_y))
      .AddBoxCollision(Pose(Eigen::Vector3d(0.3, 0, 0)), Eigen::Vector3d::Constant(0.05));
  Articulation a = b.Build(fixed);
  a.GetActiveJoints()[0].SetDriveProperty(1e4, 100, std::numeric_limits<double>::infinity());
  return a;
}

TEST(IncomingJointForceTest, AHeldPendulumGetsItsWeightAndItsMomentFromTheHinge) {
  Scene scene;
  scene.SetTimestep(0.002);
  Articulation a = AddHeldPendulum(scene, /*fixed=*/true);
  a.SetRootPose(Pose(Eigen::Vector3d(0.5, 0.2, 0),
                     Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()))));
  scene.Step(2000);
  const Eigen::MatrixXd f = a.GetLinkIncomingJointForces();
  ASSERT_EQ(f.rows(), 2);
  ASSERT_EQ(f.cols(), 6);
  EXPECT_TRUE(f.row(0).isZero());
  // in the hinge's frame (z up, x along the hinge): the weight held up, and the moment m g 0.3
  // about the hinge that the drive supplies
  const double m = 1.0, lever = 0.3;
  EXPECT_NEAR(f(1, 0), 0.0, 1e-3);
  EXPECT_NEAR(f(1, 1), 0.0, 1e-2);
  EXPECT_NEAR(f(1, 2), m * kG, 1e-3 * m * kG);
  EXPECT_NEAR(f(1, 3), -m * kG * lever, 1e-3 * m * kG * lever);
  EXPECT_NEAR(f(1, 4), 0.0, 1e-3);
  EXPECT_NEAR(f(1, 5), 0.0, 1e-3);
}

TEST(IncomingJointForceTest, LinksInFreeFallExertNothingOnEachOther) {
  Scene scene;
  Articulation a = AddHeldPendulum(scene, /*fixed=*/false);
  a.SetRootPose(Pose(Eigen::Vector3d(0, 0, 10)));
  scene.Step(10);
  const Eigen::MatrixXd f = a.GetLinkIncomingJointForces();
  // what the drive does against the hinge's own (zero) deflection: nothing to hold
  EXPECT_LT(f.row(1).norm(), 1e-6) << f;
}

}  // namespace
}  // namespace partsim
