// The stages of a scene: the description keeps what was described, the data what changes
// (drive targets), the compiled model what a setter of a model parameter changed; Clone copies
// all three; the frame-motion and proximity queries of the physics layer.
#include <gtest/gtest.h>

#include <cmath>

#include "partsim/core/error.h"
#include "partsim/physics/frame_motion.h"
#include "partsim/physics/proximity.h"
#include "partsim/physics/scene.h"
#include "test_worlds.h"

namespace partsim {
namespace {

using testing::AddArm;
using testing::AddBox;

TEST(StagesTest, DriveTargetsAreStateNotDescription) {
  Scene scene;
  Articulation arm = AddArm(scene);
  arm.SetDriveProperty(100, 10);
  const Eigen::VectorXd target = Eigen::VectorXd::LinSpaced(arm.Dof(), 0.1, 0.4);
  arm.SetDriveTarget(target);
  arm.GetJoint(2).SetDriveVelocityTarget(0.5);
  // the description still says what the articulation was described with
  for (const LinkDesc& l : arm.GetDesc().links) {
    EXPECT_EQ(l.joint.drive.target, 0.0);
    EXPECT_EQ(l.joint.drive.velocity_target, 0.0);
  }
  EXPECT_EQ(arm.GetDriveTarget(), target);
  EXPECT_EQ(arm.GetJoint(2).GetDriveVelocityTarget(), 0.5);
  // a recompile (limits are compiled) keeps the state, targets included
  arm.GetJoint(1).SetLimits(-2.5, 2.5);
  EXPECT_EQ(arm.GetDriveTarget(), target);
  EXPECT_EQ(arm.GetDriveVelocityTarget()[1], 0.5);
  // and so do pack and unpack
  const std::vector<char> state = scene.Pack();
  arm.SetDriveTarget(Eigen::VectorXd::Zero(arm.Dof()));
  scene.Unpack(state);
  EXPECT_EQ(arm.GetDriveTarget(), target);
  // a fixed joint has no drive: its targets are its description's
  Scene fixed_scene;
  ArticulationBuilder b = fixed_scene.CreateArticulationBuilder();
  LinkBuilder* base = b.CreateLinkBuilder();
  base->AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1));
  b.CreateLinkBuilder(base)->SetJointName("weld").AddBoxCollision(Pose(),
                                                                  Eigen::Vector3d::Constant(0.1));
  Articulation welded = b.Build(true);
  EXPECT_EQ(welded.GetJoint(1).GetDriveTarget(), 0.0);
  EXPECT_THROW(welded.GetJoint(1).SetDriveTarget(1.0), Error);
}

TEST(StagesTest, ADescribedTargetIsWhereTheDriveStarts) {
  Scene scene;
  Articulation arm = AddArm(scene);
  ArticulationDesc desc = arm.GetDesc();
  for (LinkDesc& l : desc.links) {
    l.joint.drive.stiffness = 50;
    l.joint.drive.target = 0.05;
  }
  desc.name = "second";
  Articulation second = scene.AddArticulation(desc);
  EXPECT_EQ(second.GetDriveTarget(), Eigen::VectorXd::Constant(second.Dof(), 0.05));
  // the first articulation's targets survive the recompile that added the second
  EXPECT_EQ(arm.GetDriveTarget(), Eigen::VectorXd::Zero(arm.Dof()));
}

TEST(StagesTest, CloneCopiesModelParametersAndStateAndStepsIdentically) {
  Scene scene;
  scene.AddGround(0);
  Articulation arm = AddArm(scene);
  Actor box = AddBox(scene, 0.05, 0.5);
  arm.SetDriveProperty(200, 20);
  arm.SetDriveTarget(Eigen::VectorXd::Constant(arm.Dof(), 0.2));
  arm.GetJoint(1).SetFriction(0.3);  // written into the compiled model only
  arm.GetJoint(2).SetArmature(0.05);
  box.SetDamping(0.2, 0.1);
  scene.Step(20);
  std::unique_ptr<Scene> copy = scene.Clone();
  EXPECT_EQ(copy->GetMjcf(), scene.GetMjcf());
  Articulation copy_arm = copy->FindArticulationByName("arm");
  EXPECT_EQ(copy_arm.GetDriveTarget(), arm.GetDriveTarget());
  EXPECT_EQ(copy_arm.GetJoint(1).GetFriction(), 0.3);
  EXPECT_EQ(copy->GetTime(), scene.GetTime());
  scene.Step(50);
  copy->Step(50);
  EXPECT_EQ(copy_arm.GetQpos(), arm.GetQpos());
  EXPECT_EQ(copy->FindActorByName("box").GetPose().p, box.GetPose().p);
  // the copy is independent: changing it leaves the original as it was
  copy_arm.SetDriveTarget(Eigen::VectorXd::Zero(arm.Dof()));
  EXPECT_EQ(arm.GetDriveTarget(), Eigen::VectorXd::Constant(arm.Dof(), 0.2));
  copy->RemoveActor(copy->FindActorByName("box"));
  EXPECT_EQ(scene.GetActors().size(), 2u);
}

TEST(FrameMotionTest, RestingBodyReadsGravityUpwardsAndFallingBodyReadsNothing) {
  Scene scene;
  scene.AddGround(0);
  Actor resting = AddBox(scene, 0.1, 0.1, "resting");
  Actor falling = AddBox(scene, 0.1, 5.0, "falling");
  scene.Step(200);  // settled on the ground; the other box is still in the air
  const FrameMotion rest = ComputeFrameMotion(resting);
  EXPECT_NEAR(rest.linear_acceleration.z(), 9.81, 0.05);
  EXPECT_NEAR(rest.linear_acceleration.head<2>().norm(), 0.0, 0.05);
  const FrameMotion fall = ComputeFrameMotion(falling, Pose(Eigen::Vector3d(0.05, 0, 0)));
  EXPECT_NEAR(fall.linear_acceleration.norm(), 0.0, 1e-6);
  EXPECT_NEAR(fall.linear_velocity.z(), -9.81 * scene.GetTime(), 0.05);
  EXPECT_NEAR((fall.pose.p - (falling.GetPose() * Pose(Eigen::Vector3d(0.05, 0, 0))).p).norm(), 0.0,
              1e-12);
  EXPECT_EQ(fall.time, scene.GetTime());
  EXPECT_THROW(ComputeFrameMotion(Actor()), Error);
}

TEST(FrameMotionTest, PointOnASpinningLinkHasCentripetalAcceleration) {
  SceneConfig config;
  config.gravity = Eigen::Vector3d::Zero();
  Scene scene(config);
  Articulation arm = AddArm(scene, false, false);
  Eigen::VectorXd qvel = Eigen::VectorXd::Zero(arm.Dof());
  const double w = 2.0;
  qvel[0] = w;  // j1 turns about the world z axis
  arm.SetQvel(qvel);
  // a point 0.3 m out along the arm at j2 = 0: the link l2 frame's x axis is horizontal
  const Link l2 = arm.GetLink(2);
  const FrameMotion m = ComputeFrameMotion(l2, Pose(Eigen::Vector3d(0.3, 0, 0)));
  const Eigen::Vector3d axis_point = arm.GetLink(1).GetPose().p;
  Eigen::Vector3d r = m.pose.p - axis_point;
  r.z() = 0;
  EXPECT_NEAR(m.angular_velocity.z(), w, 1e-9);
  EXPECT_NEAR((m.linear_velocity - Eigen::Vector3d(0, 0, w).cross(r)).norm(), 0.0, 1e-9);
  // no torque, no gravity: the acceleration is -w^2 r (within what the joint constraint gives)
  EXPECT_NEAR((m.linear_acceleration + w * w * r).norm(), 0.0, 1e-6 + 1e-3 * w * w * r.norm());
}

TEST(ProximityQueryTest, ReportsShapesWithinTheMarginOnACopy) {
  Scene scene;
  Articulation arm = AddArm(scene, false, false);
  // a box beside the tip of the arm at q = 0: the l3 link's box reaches x = 0.3 + 0.2
  Actor wall = scene.CreateActorBuilder()
                   .SetName("wall")
                   .AddBoxCollision(Pose(), Eigen::Vector3d(0.05, 0.2, 0.2))
                   .SetInitialPose(Pose(Eigen::Vector3d(0.6, 0, 0.4)))
                   .BuildStatic();
  scene.Step(1);
  const size_t contacts_before = scene.GetContacts().size();
  const Eigen::VectorXd q_before = arm.GetQpos();
  ProximityQuery query(arm);
  std::vector<ShapeProximity> near = query.Query(0.2);
  bool found = false;
  for (const ShapeProximity& p : near) {
    EXPECT_EQ(p.shape0.articulation_id, arm.GetId());
    EXPECT_LT(p.distance, 0.2);
    if (p.shape1.actor_id == wall.GetId()) {
      found = true;
      EXPECT_EQ(p.shape0.link_index, 3);
      EXPECT_NEAR(p.distance, 0.6 - 0.05 - 0.5, 1e-3);
    }
  }
  EXPECT_TRUE(found);
  // a smaller margin leaves the wall out; only link 1 queried leaves it out too
  for (const ShapeProximity& p : query.Query(0.01)) EXPECT_NE(p.shape1.actor_id, wall.GetId());
  for (const ShapeProximity& p : query.Query(0.2, {false, true, false, false}))
    EXPECT_NE(p.shape1.actor_id, wall.GetId());
  // turning the copy's arm away clears it; the scene itself has not moved
  Eigen::VectorXd q = Eigen::VectorXd::Zero(arm.Dof());
  q[0] = M_PI / 2;
  query.GetArticulation().SetQpos(q);
  for (const ShapeProximity& p : query.Query(0.2)) EXPECT_NE(p.shape1.actor_id, wall.GetId());
  EXPECT_EQ(arm.GetQpos(), q_before);
  EXPECT_EQ(scene.GetContacts().size(), contacts_before);
  EXPECT_THROW(query.Query(-1), Error);
  EXPECT_THROW(query.Query(0.1, {true}), Error);
  EXPECT_THROW(ProximityQuery{Articulation()}, Error);
}

}  // namespace
}  // namespace partsim
