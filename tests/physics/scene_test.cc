#include "partsim/physics/scene.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstring>
#include <memory>

#include "physics/test_worlds.h"

namespace partsim {
namespace {

using testing::AddArm;
using testing::AddBox;

constexpr double kG = 9.81;

double TotalNormalForceZ(const Scene& scene, int actor_id) {
  double fz = 0;
  for (const Contact& c : scene.GetContacts()) {
    for (const ContactPoint& p : c.points) {
      // force is on body0; flip it when the actor is body1
      if (c.body0.actor_id == actor_id)
        fz += p.force.z();
      else if (c.body1.actor_id == actor_id)
        fz -= p.force.z();
    }
  }
  return fz;
}

TEST(SceneTest, DroppedBoxComesToRestOnGround) {
  Scene scene;
  scene.AddGround(0.0);
  Actor box = AddBox(scene, 0.1, 0.6);
  scene.Step(1000);  // 2 s
  EXPECT_NEAR(box.GetPose().p.z(), 0.1, 2e-3);
  EXPECT_LT(box.GetVelocity().norm(), 1e-3);
  EXPECT_LT(box.GetAngularVelocity().norm(), 1e-3);
  EXPECT_NEAR(scene.GetTime(), 2.0, 1e-9);
}

TEST(SceneTest, ContactForceOfBoxAtRestEqualsWeight) {
  Scene scene;
  scene.AddGround(0.0);
  Actor box = AddBox(scene, 0.1, 0.1);
  scene.Step(500);
  double weight = box.GetMass() * kG;
  EXPECT_NEAR(box.GetMass(), 8.0, 1e-9);  // (0.2 m)^3 * 1000 kg/m^3
  EXPECT_NEAR(TotalNormalForceZ(scene, box.GetId()), weight, 0.01 * weight);
  // the contact names its bodies (the static ground second) and points up into the box
  auto contacts = scene.GetContacts();
  ASSERT_FALSE(contacts.empty());
  EXPECT_EQ(contacts[0].body0.name, "box");
  EXPECT_EQ(contacts[0].body1.name, "ground");
  EXPECT_GT(contacts[0].points[0].normal.z(), 0.99);
  EXPECT_GT(contacts[0].points[0].impulse.z(), 0.0);
  EXPECT_NEAR(contacts[0].points[0].impulse.z(),
              contacts[0].points[0].force.z() * scene.GetTimestep(), 1e-12);
}

// Velocity damping (1/s), as PhysX's: dv/dt = -c v, integrated implicitly (backward Euler gives
// v_n = v_0 / (1 + c dt)^n), about each body axis of a box whose inertia frame is turned.
TEST(SceneTest, ActorDampingDecaysVelocitiesAtItsRate) {
  Scene scene;
  scene.SetGravity(Eigen::Vector3d::Zero());
  const double dt = scene.GetTimestep();
  Actor box = scene.CreateActorBuilder()
                  .SetName("slab")
                  .AddBoxCollision(Pose(), Eigen::Vector3d(0.3, 0.1, 0.05))
                  .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 1)))
                  .Build();
  box.SetDamping(2.0, 5.0);
  EXPECT_EQ(box.GetLinearDamping(), 2.0);
  EXPECT_EQ(box.GetAngularDamping(), 5.0);
  // a second actor recompiles the model: the damping stays
  Actor other = AddBox(scene, 0.05, 3.0, "other");
  other.SetVelocity(Eigen::Vector3d(1, 0, 0));
  box.SetVelocity(Eigen::Vector3d(1, -2, 0.5));
  box.SetAngularVelocity(Eigen::Vector3d(0, 0, 3));  // about the slab's z: no precession
  const int n = 100;
  scene.Step(n);
  const double lin = std::pow(1 + 2.0 * dt, -n), ang = std::pow(1 + 5.0 * dt, -n);
  EXPECT_NEAR(box.GetVelocity().x(), lin, 1e-3);
  EXPECT_NEAR(box.GetVelocity().y(), -2 * lin, 2e-3);
  EXPECT_NEAR(box.GetAngularVelocity().z(), 3 * ang, 3e-3);
  EXPECT_NEAR(other.GetVelocity().x(), 1.0, 1e-9);  // undamped
  // clones carry it
  std::unique_ptr<Scene> copy = scene.Clone();
  Actor copied = copy->GetActors().front();
  EXPECT_EQ(copied.GetLinearDamping(), 2.0);
  const double v0 = copied.GetVelocity().x();
  copy->Step(n);
  EXPECT_NEAR(copied.GetVelocity().x(), v0 * lin, 1e-3);
}

// Backward Euler stays stable where an explicit decay (1 - c dt) would flip the sign and grow.
TEST(SceneTest, StiffActorDampingIsStableAtLargeSteps) {
  Scene scene;
  scene.SetGravity(Eigen::Vector3d::Zero());
  scene.SetTimestep(0.01);
  Actor box = AddBox(scene, 0.1, 1.0);
  box.SetDamping(1000.0, 1000.0);  // c dt = 10
  box.SetVelocity(Eigen::Vector3d(5, 0, 0));
  box.SetAngularVelocity(Eigen::Vector3d(0, 4, 0));
  for (int i = 0; i < 10; ++i) {
    scene.Step();
    EXPECT_GE(box.GetVelocity().x(), 0.0);
    EXPECT_LT(box.GetVelocity().norm(), 5.0 / std::pow(11.0, i + 1) + 1e-9);
    EXPECT_LT(box.GetAngularVelocity().norm(), 4.0 / std::pow(11.0, i + 1) + 1e-9);
  }
}

TEST(SceneTest, ActorDampingRefusesBadInput) {
  Scene scene;
  Actor ground = scene.AddGround(0.0);
  Actor box = AddBox(scene, 0.1, 1.0);
  EXPECT_THROW(ground.SetDamping(1, 1), Error);
  EXPECT_THROW(box.SetDamping(-1, 0), Error);
  EXPECT_THROW(box.SetDamping(0, std::nan("")), Error);
  EXPECT_EQ(box.GetLinearDamping(), 0.0);  // unchanged by the refused calls
  ActorDesc desc = box.GetDesc();
  desc.name = "bad";
  desc.linear_damping = -2;
  try {
    scene.AddActor(desc);
    FAIL() << "negative damping accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("actor 'bad' damping"), std::string::npos) << e.what();
  }
  EXPECT_EQ(scene.GetActors().size(), 2u);
}

TEST(SceneTest, RestitutionSetsTheReboundSpeed) {
  // drop a ball from 0.45 m above contact; effective restitution = sqrt(rebound / drop height)
  auto effective = [](double restitution) {
    Scene scene;
    PhysicalMaterial mat;
    mat.restitution = restitution;
    scene.AddGround(0.0, mat);
    Actor ball = scene.CreateActorBuilder()
                     .AddSphereCollision(Pose(), 0.05, mat)
                     .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 0.5)))
                     .Build();
    bool fell = false, rising = false;
    for (int i = 0; i < 1000; ++i) {
      scene.Step();
      double z = ball.GetPose().p.z(), vz = ball.GetVelocity().z();
      if (z < 0.06) fell = true;
      if (fell && vz > 0) rising = true;
      if (rising && vz < 0) return std::sqrt(std::max(0.0, z - 0.05) / 0.45);
    }
    return 0.0;
  };
  EXPECT_LT(effective(0.0), 0.05);
  EXPECT_NEAR(effective(0.3), 0.3, 0.06);
  EXPECT_NEAR(effective(0.5), 0.5, 0.06);
}

TEST(SceneTest, KinematicActorPushesAndIsNotPushed) {
  Scene scene;
  scene.AddGround(0.0);
  Actor box = AddBox(scene, 0.05, 0.05);
  Actor pusher = scene.CreateActorBuilder()
                     .AddBoxCollision(Pose(), Eigen::Vector3d(0.05, 0.2, 0.05))
                     .SetInitialPose(Pose(Eigen::Vector3d(-0.2, 0, 0.06)))
                     .BuildKinematic();
  for (int i = 0; i < 500; ++i) {
    Pose p = pusher.GetPose();
    p.p.x() += 0.0006;  // 0.3 m/s
    pusher.SetPose(p);
    scene.Step();
  }
  EXPECT_NEAR(pusher.GetPose().p.x(), -0.2 + 0.3, 1e-9);
  EXPECT_NEAR(pusher.GetPose().p.z(), 0.06, 1e-12);
  EXPECT_GT(box.GetPose().p.x(), 0.05);  // pushed along
}

TEST(SceneTest, ForceAtOffsetPointSpinsTheBody) {
  Scene scene(SceneConfig{1.0 / 500, Eigen::Vector3d::Zero()});
  Actor box = AddBox(scene, 0.1, 1.0);
  box.AddForceAtPoint(Eigen::Vector3d(0, 100, 0), Eigen::Vector3d(0.1, 0, 1.0));
  scene.Step();
  // linear impulse F dt / m, torque about z = r x F = 0.1 * 100
  EXPECT_NEAR(box.GetVelocity().y(), 100 * scene.GetTimestep() / box.GetMass(), 1e-6);
  EXPECT_GT(box.GetAngularVelocity().z(), 0.0);
  // the force lasts one step only
  Eigen::Vector3d v = box.GetVelocity();
  scene.Step();
  EXPECT_NEAR((box.GetVelocity() - v).norm(), 0.0, 1e-9);
}

TEST(SceneTest, PdDriveReachesTarget) {
  Scene scene;
  Articulation arm = AddArm(scene);
  ASSERT_EQ(arm.Dof(), 4);
  arm.SetDriveProperty(2000, 200);
  Eigen::VectorXd target(4);
  target << 0.5, -0.4, 0.1, 1.0;
  arm.SetDriveTarget(target);
  scene.Step(2000);
  Eigen::VectorXd q = arm.GetQpos();
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(q[k], target[k], 0.01) << "dof " << k;
  // the screw's translation follows its rotation
  Pose cap = arm.GetLink(4).GetPose(), l3 = arm.GetLink(3).GetPose();
  Eigen::Vector3d rel = l3.Inverse().Transform(cap.p);
  EXPECT_NEAR(rel.x(), 0.2 + 0.01 * q[3], 1e-3);
}

TEST(SceneTest, VelocityDriveTracksVelocityTarget) {
  Scene scene(SceneConfig{1.0 / 500, Eigen::Vector3d::Zero()});
  Articulation arm = AddArm(scene);
  Joint j1 = arm.FindJointByName("j1");
  j1.SetDriveProperty(0.0, 50.0);
  j1.SetDriveVelocityTarget(0.8);
  scene.Step(500);
  EXPECT_NEAR(j1.GetQvel(), 0.8, 0.01);
  EXPECT_NEAR(j1.GetQpos(), 0.8 * 1.0, 0.1);  // about 1 s at the target speed
  EXPECT_DOUBLE_EQ(arm.GetDriveVelocityTarget()[0], 0.8);
}

TEST(SceneTest, JointLimitStopsADrivePushingPastIt) {
  Scene scene;
  Articulation arm = AddArm(scene);
  Joint j3 = arm.FindJointByName("j3");  // prismatic, limits (-0.1, 0.2)
  j3.SetDriveProperty(5000, 100);
  j3.SetDriveTarget(0.5);  // 0.3 m beyond the upper limit: about 1500 N against the stop
  scene.Step(500);
  EXPECT_LT(j3.GetQpos(), 0.2 + 1e-3);
  EXPECT_GT(j3.GetQpos(), 0.2 - 1e-3);
}

TEST(SceneTest, ForceLimitCapsDriveForce) {
  Scene scene;
  Articulation arm = AddArm(scene);
  Joint j1 = arm.FindJointByName("j1");
  j1.SetDriveProperty(1e5, 100, /*force_limit=*/2.0);
  j1.SetDriveTarget(2.0);
  scene.Step(10);
  const mjData* d = scene.GetMjData();
  const mjModel* m = scene.GetMjModel();
  const std::string name = "r" + std::to_string(arm.GetId()) + "_d1";
  int act = mj_name2id(m, mjOBJ_ACTUATOR, name.c_str());
  ASSERT_GE(act, 0);
  EXPECT_NEAR(std::abs(d->actuator_force[act]), 2.0, 1e-9);
  EXPECT_LT(arm.GetQpos()[0], 0.5);  // a 2 N m motor turns the arm slowly
}

TEST(SceneTest, InverseDynamicsOfForwardDynamicsReturnsTheForce) {
  Scene scene;
  Articulation arm = AddArm(scene);
  Eigen::VectorXd q(4), v(4), f(4);
  q << 0.3, -0.7, 0.05, 0.4;
  v << 0.5, -1.0, 0.2, 3.0;
  f << 1.0, -2.0, 3.0, 0.1;
  arm.SetQpos(q);
  arm.SetQvel(v);
  Eigen::VectorXd qacc = arm.ComputeForwardDynamics(f);
  Eigen::VectorXd back = arm.ComputeInverseDynamics(qacc);
  EXPECT_LT((back - f).norm(), 1e-8);
  // mass matrix is symmetric positive definite
  Eigen::MatrixXd M = arm.ComputeManipulatorInertiaMatrix();
  EXPECT_LT((M - M.transpose()).norm(), 1e-12);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff(), 0);
}

TEST(SceneTest, ForwardDynamicsMatchesSimulatedAcceleration) {
  SceneConfig cfg;
  cfg.integrator = Integrator::kEuler;
  Scene scene(cfg);
  Articulation arm = AddArm(scene, false, /*with_screw=*/false);
  Eigen::VectorXd q(3), v(3), f(3);
  q << 0.3, -0.7, 0.05;
  v << 0.5, -1.0, 0.2;
  f << 1.0, -2.0, 3.0;
  arm.SetQpos(q);
  arm.SetQvel(v);
  arm.SetQf(f);
  Eigen::VectorXd predicted = arm.ComputeForwardDynamics(f);
  scene.Step();
  EXPECT_LT((arm.GetQacc() - predicted).norm(), 1e-8 * (1 + predicted.norm()));
  EXPECT_LT((arm.GetQf() - f).norm(), 1e-12);
}

TEST(SceneTest, PassiveForceHoldsArmStill) {
  Scene scene;
  Articulation arm = AddArm(scene);
  Eigen::VectorXd q(4);
  q << 0.3, 0.9, 0.1, 0.0;
  arm.SetQpos(q);
  for (int i = 0; i < 200; ++i) {
    arm.SetQf(arm.ComputePassiveForce(true, true));
    scene.Step();
  }
  EXPECT_LT((arm.GetQpos() - q).norm(), 1e-3);
  // without compensation it sags
  arm.SetQf(Eigen::VectorXd::Zero(4));
  scene.Step(200);
  EXPECT_GT((arm.GetQpos() - q).norm(), 0.05);
}

TEST(SceneTest, JacobianAgreesWithFiniteDifferences) {
  Scene scene;
  Articulation arm = AddArm(scene);
  Eigen::VectorXd q(4);
  q << 0.4, -0.5, 0.08, 0.7;
  arm.SetQpos(q);
  for (int link = 1; link <= 4; ++link) {
    Eigen::MatrixXd J = arm.ComputeLinkJacobian(link);
    ASSERT_EQ(J.rows(), 6);
    ASSERT_EQ(J.cols(), 4);
    for (int k = 0; k < 4; ++k) {
      const double eps = 1e-6;
      Eigen::VectorXd qp = q, qm = q;
      qp[k] += eps;
      qm[k] -= eps;
      arm.SetQpos(qp);
      Pose pp = arm.GetLink(link).GetPose();
      arm.SetQpos(qm);
      Pose pm = arm.GetLink(link).GetPose();
      Eigen::Vector3d dp = (pp.p - pm.p) / (2 * eps);
      Eigen::AngleAxisd daa(pp.q * pm.q.conjugate());
      Eigen::Vector3d dw = daa.axis() * daa.angle() / (2 * eps);
      EXPECT_LT((J.block<3, 1>(0, k) - dp).norm(), 1e-5) << "link " << link << " dof " << k;
      EXPECT_LT((J.block<3, 1>(3, k) - dw).norm(), 1e-5) << "link " << link << " dof " << k;
    }
    arm.SetQpos(q);
  }
  EXPECT_EQ(arm.ComputeWorldCartesianJacobian().rows(), 6 * 5);
}

TEST(SceneTest, PackUnpackIsBitExact) {
  Scene scene;
  scene.AddGround(0.0);
  AddBox(scene, 0.05, 0.5);
  Articulation arm = AddArm(scene);
  arm.SetDriveProperty(500, 50);
  Eigen::VectorXd target(4);
  target << 0.5, 0.5, 0.1, 0.3;
  arm.SetDriveTarget(target);
  scene.Step(150);
  std::vector<char> state = scene.Pack();
  scene.Step(100);
  std::vector<char> after = scene.Pack();
  scene.Unpack(state);
  scene.Step(100);
  std::vector<char> again = scene.Pack();
  ASSERT_EQ(after.size(), again.size());
  EXPECT_EQ(std::memcmp(after.data(), again.data(), after.size()), 0);
  // a corrupted state is refused and changes nothing
  std::vector<char> truncated(state.begin(), state.begin() + state.size() / 2);
  EXPECT_THROW(scene.Unpack(truncated), Error);
  EXPECT_EQ(scene.Pack(), again);
  std::vector<char> longer = state;
  longer.push_back(0);
  EXPECT_THROW(scene.Unpack(longer), Error);
  EXPECT_EQ(scene.Pack(), again);
}

TEST(SceneTest, TwoRunsAreBitIdentical) {
  auto run = [] {
    Scene scene;
    scene.AddGround(0.0);
    for (int i = 0; i < 4; ++i)
      AddBox(scene, 0.05, 0.2 + 0.12 * i, "box" + std::to_string(i))
          .SetPose(Pose(Eigen::Vector3d(0.02 * i, 0.01 * i, 0.2 + 0.12 * i)));
    Articulation arm = AddArm(scene);
    arm.SetDriveProperty(300, 30);
    arm.SetDriveTarget(Eigen::VectorXd::Constant(4, 0.3));
    scene.Step(300);
    return scene.Pack();
  };
  EXPECT_EQ(run(), run());
}

TEST(SceneTest, AddingAndRemovingKeepsOtherState) {
  Scene scene;
  scene.AddGround(0.0);
  Actor box = AddBox(scene, 0.05, 1.0);
  Articulation arm = AddArm(scene);
  arm.SetQvel(Eigen::VectorXd::Constant(4, 0.2));
  scene.Step(100);
  Pose pose = box.GetPose();
  Eigen::Vector3d vel = box.GetVelocity();
  Eigen::VectorXd q = arm.GetQpos(), v = arm.GetQvel();
  double t = scene.GetTime();
  Actor other = AddBox(scene, 0.05, 2.0, "other");
  EXPECT_EQ(box.GetPose().p, pose.p);
  EXPECT_EQ(box.GetVelocity(), vel);
  EXPECT_EQ(arm.GetQpos(), q);
  EXPECT_EQ(arm.GetQvel(), v);
  EXPECT_EQ(scene.GetTime(), t);
  scene.RemoveActor(other);
  EXPECT_EQ(box.GetPose().p, pose.p);
  EXPECT_EQ(arm.GetQvel(), v);
  EXPECT_THROW(other.GetPose(), Error);
  EXPECT_EQ(scene.GetActors().size(), 2u);
  // adding is invisible to the trajectory: compare with a scene that never had the extra actor
  scene.Step(10);
  EXPECT_LT(box.GetPose().p.z(), pose.p.z());
}

TEST(SceneTest, KinematicArticulationFollowsQposAndPushes) {
  Scene scene;
  scene.AddGround(0.0);
  Articulation arm = AddArm(scene, /*kinematic=*/true);
  ASSERT_TRUE(arm.IsKinematic());
  Eigen::VectorXd q(4);
  q << M_PI / 2, 0.0, 0.1, 0.0;
  arm.SetQpos(q);
  // j1 turns about world z by 90 degrees: l2's box (along its x) now points along world y
  Pose l3 = arm.GetLink(3).GetPose();
  EXPECT_NEAR(l3.p.x(), 0.0, 1e-9);
  EXPECT_NEAR(l3.p.y(), 0.3 + 0.1, 1e-9);
  EXPECT_NEAR(l3.p.z(), 0.4, 1e-9);
  scene.Step(10);
  EXPECT_EQ(arm.GetQpos(), q);  // gravity does not move it
  EXPECT_THROW(arm.ComputeManipulatorInertiaMatrix(), Error);
}

TEST(SceneTest, FreeRootArticulationFalls) {
  Scene scene;
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  LinkBuilder* root = b.CreateLinkBuilder();
  root->AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.05));
  LinkBuilder* child = b.CreateLinkBuilder(root);
  child
      ->SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-1, 1),
                           Pose(Eigen::Vector3d(0.1, 0, 0)), Pose())
      .AddSphereCollision(Pose(Eigen::Vector3d(0.05, 0, 0)), 0.03);
  b.SetInitialPose(Pose(Eigen::Vector3d(0, 0, 2)));
  Articulation art = b.Build(/*fix_root_link=*/false);
  EXPECT_EQ(art.Dof(), 1);
  scene.Step(250);  // 0.5 s of free fall: z = 2 - g t^2 / 2
  EXPECT_NEAR(art.GetRootPose().p.z(), 2 - 0.5 * kG * 0.25, 0.01);
  EXPECT_NEAR(art.GetRootVelocity().z(), -kG * 0.5, 0.02);
}

TEST(SceneTest, MimicCouplingMakesJointFollow) {
  Scene scene(SceneConfig{1.0 / 500, Eigen::Vector3d::Zero()});
  ArticulationDesc desc;
  desc.name = "gripper";
  LinkDesc base;
  base.name = "base";
  base.collisions.push_back(CollisionShape());
  base.collisions[0].half_size = Eigen::Vector3d(0.05, 0.05, 0.02);
  desc.links.push_back(base);
  for (int i = 0; i < 2; ++i) {
    LinkDesc finger;
    finger.name = "finger" + std::to_string(i);
    finger.parent = 0;
    finger.joint.name = "finger_joint" + std::to_string(i);
    finger.joint.type = JointType::kPrismatic;
    finger.joint.lower = 0;
    finger.joint.upper = 0.04;
    finger.joint.pose_in_parent = Pose(Eigen::Vector3d(0, i == 0 ? 0.03 : -0.03, 0.05));
    finger.collisions.push_back(CollisionShape());
    finger.collisions[0].half_size = Eigen::Vector3d(0.01, 0.01, 0.03);
    desc.links.push_back(finger);
  }
  desc.couplings.push_back({"finger_joint1", "finger_joint0", -1.0, 0.04});
  Articulation art = scene.AddArticulation(desc);
  // the coupled finger is a dof of its own (as in SAPIEN), with its own drive
  EXPECT_EQ(art.Dof(), 2);
  EXPECT_EQ(art.FindJointByName("finger_joint1").GetDof(), 1);
  EXPECT_EQ(art.GetActiveJoints()[1].GetName(), "finger_joint1");
  // only the source is driven; the engine makes the other follow
  Joint j0 = art.FindJointByName("finger_joint0");
  j0.SetDriveProperty(1000, 50);
  j0.SetDriveTarget(0.03);
  scene.Step(1000);
  EXPECT_NEAR(art.GetQpos()[0], 0.03, 1e-3);
  EXPECT_NEAR(art.GetQpos()[1], -1.0 * 0.03 + 0.04, 2e-3);
  double x1 = art.GetLink(2).GetPose().p.x();
  EXPECT_NEAR(x1, -1.0 * 0.03 + 0.04, 2e-3);
  // set_qpos places the coupled joint from its source, whatever its own entry says
  art.SetQpos(Eigen::Vector2d(0.01, 0.5));
  EXPECT_NEAR(art.GetQpos()[1], 0.03, 1e-12);
}

TEST(SceneTest, BadInputThrowsNamedErrorsAndSceneSurvives) {
  Scene scene;
  scene.AddGround(0.0);
  Actor box = AddBox(scene, 0.1, 0.1);
  box.SetPose(Pose(Eigen::Vector3d(1, 0, 0.1)));
  Articulation arm = AddArm(scene);
  Pose nan_pose(Eigen::Vector3d(NAN, 0, 0));
  try {
    box.SetPose(nan_pose);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pose"), std::string::npos) << e.what();
  }
  try {
    arm.SetQpos(Eigen::VectorXd::Zero(3));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("qpos has 3 entries"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'arm'"), std::string::npos) << e.what();
  }
  Eigen::VectorXd q = Eigen::VectorXd::Zero(4);
  q[2] = NAN;
  EXPECT_THROW(arm.SetQpos(q), Error);
  EXPECT_THROW(arm.GetLink(17), IndexError);
  EXPECT_THROW(arm.GetJoint(0), IndexError);
  EXPECT_THROW(arm.FindLinkByName("nope"), Error);
  EXPECT_THROW(arm.GetJoint(1).SetLimits(1, -1), Error);
  EXPECT_THROW(scene.Step(-1), Error);
  // an actor with a bad shape is refused and nothing is added
  ActorDesc bad;
  bad.name = "bad";
  bad.collisions.push_back(CollisionShape());
  bad.collisions[0].half_size = Eigen::Vector3d(0.1, -1, 0.1);
  try {
    scene.AddActor(bad);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("actor 'bad' collision shape 0 (box) half_size"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(scene.GetActors().size(), 2u);
  ActorDesc nan_actor;
  nan_actor.pose.p.x() = NAN;
  EXPECT_THROW(scene.AddActor(nan_actor), Error);
  ArticulationDesc two_roots;
  two_roots.links.resize(2);
  EXPECT_THROW(scene.AddArticulation(two_roots), Error);
  // the scene still steps and the box still rests
  scene.Step(100);
  EXPECT_NEAR(box.GetPose().p.z(), 0.1, 2e-3);
  EXPECT_TRUE(arm.GetQpos().allFinite());
}

TEST(SceneTest, SetTimestepKeepsStateAndChangesStep) {
  Scene scene;
  Actor box = AddBox(scene, 0.1, 5.0);
  scene.Step(10);
  Eigen::Vector3d v = box.GetVelocity();
  scene.SetTimestep(0.001);
  EXPECT_EQ(box.GetVelocity(), v);
  EXPECT_NE(scene.GetMjcf().find("timestep=\"0.001\""), std::string::npos);
  scene.Step(10);
  EXPECT_NEAR(scene.GetTime(), 10 * 0.002 + 10 * 0.001, 1e-12);
  EXPECT_NEAR(box.GetVelocity().z(), v.z() - 9.81 * 0.01, 1e-9);
  EXPECT_THROW(scene.SetTimestep(0.0), Error);
}

TEST(SceneTest, CloneCopiesDescriptionAndState) {
  Scene scene;
  scene.AddGround(0.0);
  AddBox(scene, 0.05, 0.5);
  Articulation arm = AddArm(scene);
  arm.SetDriveProperty(500, 50);
  arm.SetDriveTarget(Eigen::VectorXd::Constant(4, 0.2));
  scene.Step(50);
  std::unique_ptr<Scene> copy = scene.Clone();
  scene.Step(50);
  copy->Step(50);
  EXPECT_EQ(scene.Pack(), copy->Pack());
}

TEST(SceneTest, ConvexMeshRestsAtItsExtent) {
  Scene scene;
  scene.AddGround(0.0);
  auto mesh = std::make_shared<MeshData>();
  // a tetrahedron-ish wedge: bottom face at z = -0.05 in the shape frame
  mesh->vertices = {{-0.1f, -0.1f, -0.05f},
                    {0.1f, -0.1f, -0.05f},
                    {-0.1f, 0.1f, -0.05f},
                    {0.1f, 0.1f, -0.05f},
                    {0.0f, 0.0f, 0.15f}};
  // the shape straight into the description (AddConvexCollisionFromMesh, which checks the
  // piece first, belongs to the assets layer)
  ActorDesc desc;
  desc.name = "wedge";
  desc.pose = Pose(Eigen::Vector3d(0, 0, 0.5));
  CollisionShape shape;
  shape.type = ShapeType::kConvexMesh;
  shape.mesh = mesh;
  shape.pose = Pose(Eigen::Vector3d(0, 0, 0.02));
  desc.collisions.push_back(shape);
  Actor a = scene.AddActor(desc);
  scene.Step(1000);
  // body origin sits 0.05 - 0.02 = 0.03 above the ground
  EXPECT_NEAR(a.GetPose().p.z(), 0.03, 2e-3);
}

}  // namespace
}  // namespace partsim
