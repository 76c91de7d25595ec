// Setters change the simulation, not only the description: each is checked against the motion it
// must produce (closed-form where there is one), after the change and without a rebuild by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "partsim/physics/scene.h"
#include "physics/test_worlds.h"

namespace partsim {
namespace {

// A fixed base and one 2 kg link on a horizontal prismatic joint along world x; gravity does not
// act along the joint.
Articulation AddSlider(Scene& scene) {
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.SetName("slider");
  LinkBuilder* base = b.CreateLinkBuilder();
  base->SetName("base").SetMassAndInertia(1.0, Pose(), Eigen::Vector3d::Constant(0.01));
  LinkBuilder* cart = b.CreateLinkBuilder(base);
  cart->SetName("cart")
      .SetJointName("rail")
      .SetJointProperties(JointType::kPrismatic, Eigen::Vector2d(-10, 10), Pose(), Pose())
      .SetMassAndInertia(2.0, Pose(), Eigen::Vector3d::Constant(0.01));
  Articulation a = b.Build(/*fix_root_link=*/true);
  a.SetRootPose(Pose(Eigen::Vector3d(0, 0, 1)));
  return a;
}

double PushFor(Scene& scene, Articulation& a, double force, double seconds) {
  a.SetQpos(Eigen::VectorXd::Zero(1));
  a.SetQvel(Eigen::VectorXd::Zero(1));
  a.SetQf(Eigen::VectorXd::Constant(1, force));
  scene.Step(static_cast<int>(std::lround(seconds / scene.GetTimestep())));
  return a.GetQpos()[0];
}

TEST(SettersTest, ArmatureAddsInertiaToTheJoint) {
  Scene scene;
  Articulation a = AddSlider(scene);
  Joint rail = a.FindJointByName("rail");
  // x = F t^2 / (2 (m + armature))
  EXPECT_NEAR(PushFor(scene, a, 4.0, 1.0), 4.0 / (2 * 2.0), 0.02);
  rail.SetArmature(2.0);
  EXPECT_NEAR(PushFor(scene, a, 4.0, 1.0), 4.0 / (2 * 4.0), 0.02);
}

TEST(SettersTest, DampingBringsTheJointToItsTerminalVelocity) {
  Scene scene;
  Articulation a = AddSlider(scene);
  a.FindJointByName("rail").SetDamping(20.0);
  PushFor(scene, a, 4.0, 2.0);  // time constant m / c = 0.1 s
  EXPECT_NEAR(a.GetQvel()[0], 4.0 / 20.0, 1e-3);
}

TEST(SettersTest, DryFrictionHoldsTheJointUntilTheForceExceedsIt) {
  Scene scene;
  Articulation a = AddSlider(scene);
  Joint rail = a.FindJointByName("rail");
  rail.SetFriction(5.0);
  // held (the constraint is soft: it creeps by about a millimetre, where the free cart goes
  // 0.25 m)
  EXPECT_LT(std::abs(PushFor(scene, a, 4.0, 0.5)), 0.01);
  // above it: (F - f) / m
  EXPECT_NEAR(PushFor(scene, a, 9.0, 1.0), (9.0 - 5.0) / (2 * 2.0), 0.03);
}

TEST(SettersTest, LimitsStopTheJointWhereTheyAreSet) {
  Scene scene;
  Articulation a = AddSlider(scene);
  a.FindJointByName("rail").SetLimits(-0.1, 0.25);
  EXPECT_NEAR(PushFor(scene, a, 10.0, 1.0), 0.25, 0.01);
}

TEST(SettersTest, GravityAcceleratesAFreeBody) {
  Scene scene;
  Actor box = testing::AddBox(scene, 0.05, 10.0);
  scene.SetGravity(Eigen::Vector3d(0, 0, -2.0));
  scene.Step(500);  // 1 s
  EXPECT_NEAR(box.GetPose().p.z(), 10.0 - 0.5 * 2.0, 0.01);
  scene.SetGravity(Eigen::Vector3d(3.0, 0, 0));
  box.SetPose(Pose(Eigen::Vector3d(0, 0, 10)));
  box.SetVelocity(Eigen::Vector3d::Zero());
  scene.Step(500);
  EXPECT_NEAR(box.GetPose().p.x(), 0.5 * 3.0, 0.01);
  EXPECT_NEAR(box.GetPose().p.z(), 10.0, 1e-6);
}

TEST(SettersTest, RootPoseOfAFixedRootMovesItsCollisionShapes) {
  Scene scene;
  scene.AddGround(0.0);
  // a table: a fixed root with a 0.4 x 0.4 x 0.1 m top
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.CreateLinkBuilder()->SetName("top").AddBoxCollision(Pose(), Eigen::Vector3d(0.2, 0.2, 0.05));
  Articulation table = b.Build(/*fix_root_link=*/true);
  table.SetRootPose(Pose(Eigen::Vector3d(2.0, 0, 0.5)));
  scene.Step(200);
  // it stays where it was put: a fixed root does not fall
  EXPECT_LT((table.GetRootPose().p - Eigen::Vector3d(2.0, 0, 0.5)).norm(), 1e-9);
  // a box dropped over its new place rests on it, not on the ground
  Actor box = testing::AddBox(scene, 0.03, 1.0);
  box.SetPose(Pose(Eigen::Vector3d(2.05, 0.05, 1.0)));
  scene.Step(1000);
  EXPECT_NEAR(box.GetPose().p.z(), 0.5 + 0.05 + 0.03, 0.01);
  // and moved again, the table leaves it to fall to the ground
  table.SetRootPose(Pose(Eigen::Vector3d(-2.0, 0, 0.5)));
  scene.Step(1000);
  EXPECT_NEAR(box.GetPose().p.z(), 0.03, 0.01);
}

// A box on flat ground under gravity tilted by 20 degrees: friction 0.5 (> tan 20 = 0.36) holds
// it, the default material at 0.1 lets it slide.
TEST(SettersTest, TheDefaultMaterialsFrictionDecidesWhetherABoxSlides) {
  Scene scene;
  scene.AddGround(0.0);
  const double t = 20.0 * M_PI / 180.0;
  scene.SetGravity(9.81 * Eigen::Vector3d(std::sin(t), 0, -std::cos(t)));
  Actor box = testing::AddBox(scene, 0.05, 0.05);
  scene.Step(500);
  EXPECT_LT(std::abs(box.GetPose().p.x()), 0.01);
  PhysicalMaterial slippery;
  slippery.static_friction = slippery.dynamic_friction = 0.1;
  scene.SetDefaultMaterial(slippery);
  scene.Step(500);  // 1 s: a = g (sin t - 0.1 cos t) = 2.43 m/s^2
  EXPECT_GT(box.GetPose().p.x(), 0.5);
}

}  // namespace
}  // namespace partsim
