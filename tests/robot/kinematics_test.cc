// Forward kinematics against the physics engine's link poses, Jacobians against finite
// differences and against Articulation::ComputeLinkJacobian, and inverse kinematics round trips.
#include "partsim/robot/kinematics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "physics/test_worlds.h"
#include "robot/test_robots.h"

namespace partsim {
namespace {

Eigen::VectorXd RandomQ(const Eigen::MatrixX2d& limits, std::mt19937& rng) {
  Eigen::VectorXd q(limits.rows());
  for (Eigen::Index k = 0; k < q.size(); ++k) {
    double lo = std::isfinite(limits(k, 0)) ? limits(k, 0) : -M_PI;
    double hi = std::isfinite(limits(k, 1)) ? limits(k, 1) : M_PI;
    q[k] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

double RotationDistance(const Pose& a, const Pose& b) { return a.q.angularDistance(b.q); }

// FK of every link equals the pose MuJoCo computes for it.
void ExpectFkMatchesScene(Articulation art, int samples) {
  KinematicModel model = KinematicModel::FromArticulation(art);
  ASSERT_EQ(model.Dof(), art.Dof());
  ASSERT_EQ(model.NumLinks(), static_cast<int>(art.GetLinks().size()));
  std::mt19937 rng(7);
  for (int s = 0; s < samples; ++s) {
    Eigen::VectorXd q = RandomQ(model.Limits(), rng);
    art.SetQpos(q);
    std::vector<Pose> fk = model.ForwardKinematics(q);
    for (int i = 0; i < model.NumLinks(); ++i) {
      Pose expected = art.GetLink(i).GetPose();
      EXPECT_LT((fk[i].p - expected.p).norm(), 1e-9) << "link " << i;
      EXPECT_LT(RotationDistance(fk[i], expected), 1e-9) << "link " << i;
    }
  }
}

TEST(KinematicModel, ForwardKinematicsMatchesSceneFor7DofArmWithPrismaticJoint) {
  Scene scene;
  Pose root(Eigen::Vector3d(0.3, -0.2, 0.1),
            Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ())));
  Articulation arm = testing::AddArm7(scene, root);
  ASSERT_EQ(arm.Dof(), 7);
  ExpectFkMatchesScene(arm, 50);
}

TEST(KinematicModel, ForwardKinematicsMatchesSceneWithScrewJoint) {
  Scene scene;
  ExpectFkMatchesScene(testing::AddArm(scene), 30);
}

TEST(KinematicModel, ForwardKinematicsMatchesKinematicArticulationAndCoupling) {
  Scene scene;
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.SetName("gripper");
  LinkBuilder* base = b.CreateLinkBuilder();
  base->SetName("palm").AddBoxCollision(Pose(), Eigen::Vector3d(0.05, 0.05, 0.02));
  LinkBuilder* f1 = b.CreateLinkBuilder(base);
  f1->SetName("f1").SetJointName("a").SetJointProperties(
      JointType::kPrismatic, Eigen::Vector2d(0, 0.04), Pose(Eigen::Vector3d(0, 0.02, 0.05)),
      Pose());
  f1->AddBoxCollision(Pose(), Eigen::Vector3d(0.01, 0.01, 0.03));
  LinkBuilder* f2 = b.CreateLinkBuilder(base);
  f2->SetName("f2").SetJointName("b").SetJointProperties(
      JointType::kPrismatic, Eigen::Vector2d(-0.04, 0), Pose(Eigen::Vector3d(0, -0.02, 0.05)),
      Pose());
  f2->AddBoxCollision(Pose(), Eigen::Vector3d(0.01, 0.01, 0.03));
  b.GetDesc().couplings.push_back({"b", "a", -1.0, 0.0});
  Articulation g = b.BuildKinematic();
  KinematicModel model = KinematicModel::FromArticulation(g);
  // the coupled joint keeps its dof, as in the articulation
  ASSERT_EQ(model.Dof(), 2);
  ASSERT_EQ(g.Dof(), 2);
  // its own entry is ignored: it moves as its source dictates, in both
  Eigen::VectorXd q(2);
  q << 0.03, 0.5;
  g.SetQpos(q);
  std::vector<Pose> fk = model.ForwardKinematics(q);
  for (int i = 0; i < 3; ++i) EXPECT_LT((fk[i].p - g.GetLink(i).GetPose().p).norm(), 1e-9);
  EXPECT_NEAR(fk[2].p.x(), -0.03, 1e-12);
  // the coupled joint's motion lands in its source's Jacobian column; its own column is zero
  Eigen::MatrixXd J = model.Jacobian(q, 2);
  EXPECT_NEAR(J(0, 0), -1.0, 1e-12);
  EXPECT_LT(J.col(1).norm(), 1e-12);
}

TEST(KinematicModel, JacobianMatchesFiniteDifferencesAndScene) {
  Scene scene;
  Articulation arm = testing::AddArm7(
      scene,
      Pose(Eigen::Vector3d(0.1, 0.2, 0.3),
           Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()))));
  KinematicModel model = KinematicModel::FromArticulation(arm);
  const int hand = model.LinkIndex("hand");
  const Pose tcp(Eigen::Vector3d(0.02, 0.01, 0.12),
                 Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX())));
  std::mt19937 rng(3);
  for (int s = 0; s < 20; ++s) {
    Eigen::VectorXd q = RandomQ(model.Limits(), rng);
    Eigen::MatrixXd J = model.Jacobian(q, hand, tcp);
    ASSERT_EQ(J.rows(), 6);
    ASSERT_EQ(J.cols(), 7);
    // central differences: linear rows from positions, angular rows from rotations
    const double h = 1e-6;
    for (int k = 0; k < 7; ++k) {
      Eigen::VectorXd qp = q, qm = q;
      qp[k] += h;
      qm[k] -= h;
      Pose a = model.LinkPose(qp, hand, tcp), b = model.LinkPose(qm, hand, tcp);
      Eigen::Vector3d v = (a.p - b.p) / (2 * h);
      Eigen::Vector3d w = PoseError(b, a).tail<3>() / (2 * h);
      EXPECT_LT((J.block<3, 1>(0, k) - v).norm(), 1e-6) << "dof " << k;
      EXPECT_LT((J.block<3, 1>(3, k) - w).norm(), 1e-6) << "dof " << k;
    }
    // at every link origin, the physics engine's Jacobian
    arm.SetQpos(q);
    for (int i = 0; i < model.NumLinks(); ++i)
      EXPECT_LT((model.Jacobian(q, i) - arm.ComputeLinkJacobian(i)).norm(), 1e-9) << "link " << i;
  }
}

TEST(KinematicModel, ScrewJacobianMatchesScene) {
  Scene scene;
  Articulation arm = testing::AddArm(scene);
  KinematicModel model = KinematicModel::FromArticulation(arm);
  Eigen::VectorXd q(4);
  q << 0.3, -0.5, 0.1, 2.0;
  arm.SetQpos(q);
  for (int i = 0; i < model.NumLinks(); ++i)
    EXPECT_LT((model.Jacobian(q, i) - arm.ComputeLinkJacobian(i)).norm(), 1e-9) << "link " << i;
}

TEST(KinematicModel, PlanarArmClosedForm) {
  Scene scene;
  KinematicModel model = KinematicModel::FromArticulation(testing::AddPlanar2(scene));
  int tip = model.LinkIndex("tip");
  Eigen::VectorXd q(2);
  q << 0.4, -1.1;
  Pose p = model.LinkPose(q, tip);
  EXPECT_NEAR(p.p.x(), 0.5 * std::cos(0.4) + 0.4 * std::cos(0.4 - 1.1), 1e-12);
  EXPECT_NEAR(p.p.y(), 0.5 * std::sin(0.4) + 0.4 * std::sin(0.4 - 1.1), 1e-12);
  EXPECT_NEAR(p.p.z(), 0.0, 1e-12);
  EXPECT_EQ(model.DofIndex("elbow"), 1);
  EXPECT_EQ(model.DofIndex("tip_joint"), -1);
}

TEST(KinematicModel, BadInputThrows) {
  Scene scene;
  KinematicModel model = KinematicModel::FromArticulation(testing::AddPlanar2(scene));
  EXPECT_THROW(model.ForwardKinematics(Eigen::VectorXd::Zero(3)), Error);
  EXPECT_THROW(model.ForwardKinematics(Eigen::Vector2d(0, NAN)), Error);
  EXPECT_THROW(model.LinkPose(Eigen::VectorXd::Zero(2), 9), Error);
  EXPECT_THROW(model.LinkIndex("nope"), Error);
  EXPECT_THROW(model.DofIndex("nope"), Error);
  try {
    model.LinkIndex("nope");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nope"), std::string::npos);
  }
}

TEST(PoseError, AxisAngleAndTranslation) {
  Pose a(Eigen::Vector3d(1, 2, 3),
         Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ())));
  Pose b(Eigen::Vector3d(1.5, 2, 3),
         Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ())));
  Eigen::Matrix<double, 6, 1> e = PoseError(a, b);
  EXPECT_NEAR((e.head<3>() - Eigen::Vector3d(0.5, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((e.tail<3>() - Eigen::Vector3d(0, 0, 0.5)).norm(), 0, 1e-12);
  // the short way round, also with a quaternion of the opposite sign
  Pose c(Eigen::Vector3d::Zero(),
         Eigen::Quaterniond(Eigen::AngleAxisd(3.0, Eigen::Vector3d::UnitX())));
  Pose d(Eigen::Vector3d::Zero(),
         Eigen::Quaterniond(Eigen::AngleAxisd(-3.0, Eigen::Vector3d::UnitX())));
  d.q.coeffs() *= -1;
  EXPECT_NEAR(PoseError(c, d).tail<3>().x(), 2 * M_PI - 6.0, 1e-9);
  EXPECT_EQ(PoseError(a, a).norm(), 0.0);
}

TEST(IkRoundTrip, RandomReachablePosesOf7DofArm) {
  Scene scene;
  KinematicModel model = KinematicModel::FromArticulation(testing::AddArm7(scene));
  const int hand = model.LinkIndex("hand");
  std::mt19937 rng(11);
  const int samples = 200;
  int successes = 0, iterations = 0, first_try = 0;
  IkOptions opt;
  opt.offset = Pose(Eigen::Vector3d(0, 0, 0.05));
  for (int s = 0; s < samples; ++s) {
    Eigen::VectorXd q_goal = RandomQ(model.Limits(), rng);
    Eigen::VectorXd q_init = RandomQ(model.Limits(), rng);
    Pose target = model.LinkPose(q_goal, hand, opt.offset);
    opt.seed = s;
    IkResult r = InverseKinematics(model, hand, target, q_init, opt);
    Pose reached = model.LinkPose(r.q, hand, opt.offset);
    // the reported errors are the true ones and the limits hold
    EXPECT_NEAR(r.position_error, (reached.p - target.p).norm(), 1e-12);
    for (int k = 0; k < 7; ++k) {
      EXPECT_GE(r.q[k], model.Limits()(k, 0));
      EXPECT_LE(r.q[k], model.Limits()(k, 1));
    }
    if (r.success) {
      ++successes;
      iterations += r.iterations;
      if (r.iterations <= opt.max_iterations) ++first_try;  // no restart needed
      EXPECT_LE(r.position_error, opt.position_tolerance);
      EXPECT_LE(r.rotation_error, opt.rotation_tolerance);
      EXPECT_LE(RotationDistance(reached, target), opt.rotation_tolerance + 1e-9);
    } else {
      EXPECT_FALSE(r.message.empty());
    }
  }
  double rate = static_cast<double>(successes) / samples;
  std::printf(
      "IK round trip (7 dof, %d samples): success rate %.3f, mean iterations %.1f, "
      "solved without restart %d\n",
      samples, rate, successes ? static_cast<double>(iterations) / successes : 0.0, first_try);
  EXPECT_GE(rate, 0.95);
}

TEST(IkRoundTrip, PlanarArmPositionOnlyMatchesClosedForm) {
  Scene scene;
  KinematicModel model = KinematicModel::FromArticulation(testing::AddPlanar2(scene));
  const int tip = model.LinkIndex("tip");
  IkOptions opt;
  opt.position_only = true;
  opt.position_tolerance = 1e-8;
  // a point at distance r: the elbow angle is fixed by the law of cosines
  Pose target(Eigen::Vector3d(0.3, 0.5, 0.0));
  IkResult r = InverseKinematics(model, tip, target, Eigen::Vector2d(0.1, 0.5), opt);
  ASSERT_TRUE(r.success) << r.message;
  double d2 = target.p.squaredNorm();
  double c2 = (d2 - 0.25 - 0.16) / (2 * 0.5 * 0.4);
  EXPECT_NEAR(std::abs(r.q[1]), std::acos(c2), 1e-6);
}

TEST(IkRoundTrip, UnreachableTargetFailsWithClosestQ) {
  Scene scene;
  KinematicModel model = KinematicModel::FromArticulation(testing::AddArm7(scene));
  const int hand = model.LinkIndex("hand");
  Pose target(Eigen::Vector3d(3.0, 0, 0.5));
  IkResult r = InverseKinematics(model, hand, target, Eigen::VectorXd::Zero(7));
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("out of reach"), std::string::npos) << r.message;
  EXPECT_NEAR(r.position_error, (model.LinkPose(r.q, hand).p - target.p).norm(), 1e-12);
  // position only: the closest q stretches the arm (1.26 m beyond the shoulder at z = 0.3)
  // towards the target
  IkOptions opt;
  opt.position_only = true;
  r = InverseKinematics(model, hand, target, Eigen::VectorXd::Zero(7), opt);
  EXPECT_FALSE(r.success);
  double expected = std::hypot(3.0, 0.2) - 1.26;
  EXPECT_GE(r.position_error, expected - 1e-3);
  EXPECT_LE(r.position_error, expected + 0.05);  // convergence is slow near full stretch
  EXPECT_NEAR(r.q[3], 0.15, 1e-3);               // telescope fully out
  for (int k = 0; k < 7; ++k) {
    EXPECT_GE(r.q[k], model.Limits()(k, 0));
    EXPECT_LE(r.q[k], model.Limits()(k, 1));
  }
}

TEST(IkRoundTrip, LimitsAndActiveMaskRespected) {
  Scene scene;
  KinematicModel model =
      KinematicModel::FromArticulation(testing::AddPlanar2(scene, 0.5, 0.4, 0.5));
  const int tip = model.LinkIndex("tip");
  IkOptions opt;
  opt.position_only = true;
  // reachable only with an elbow bend of 1.5 rad, beyond the 0.5 limit
  Eigen::VectorXd q_bent(2);
  q_bent << 0.0, 1.5;
  KinematicModel free_model =
      KinematicModel::FromArticulation(testing::AddPlanar2(scene, 0.5, 0.4, 3.0));
  Pose target = free_model.LinkPose(q_bent, tip);
  IkResult r = InverseKinematics(model, tip, target, Eigen::VectorXd::Zero(2), opt);
  EXPECT_FALSE(r.success);
  EXPECT_LE(r.q.cwiseAbs().maxCoeff(), 0.5 + 1e-12);
  EXPECT_NEAR(std::abs(r.q[1]), 0.5, 1e-6);  // the elbow bends as far as it can
  // only the shoulder may move: the elbow stays at its initial value
  opt.active = {true, false};
  Eigen::VectorXd q0(2);
  q0 << 0.0, 0.3;
  Pose target2 = model.LinkPose(Eigen::Vector2d(0.4, 0.3), tip);
  IkResult r2 = InverseKinematics(model, tip, target2, q0, opt);
  EXPECT_TRUE(r2.success) << r2.message;
  EXPECT_EQ(r2.q[1], 0.3);
  EXPECT_NEAR(r2.q[0], 0.4, 1e-4);
}

TEST(IkRoundTrip, BadInputThrows) {
  Scene scene;
  KinematicModel model = KinematicModel::FromArticulation(testing::AddPlanar2(scene));
  Pose ok(Eigen::Vector3d(0.5, 0.2, 0));
  EXPECT_THROW(InverseKinematics(model, 7, ok, Eigen::VectorXd::Zero(2)), Error);
  EXPECT_THROW(InverseKinematics(model, 3, ok, Eigen::VectorXd::Zero(3)), Error);
  EXPECT_THROW(
      InverseKinematics(model, 3, Pose(Eigen::Vector3d(NAN, 0, 0)), Eigen::VectorXd::Zero(2)),
      Error);
  IkOptions opt;
  opt.active = {true};
  EXPECT_THROW(InverseKinematics(model, 3, ok, Eigen::VectorXd::Zero(2), opt), Error);
}

}  // namespace
}  // namespace partsim
