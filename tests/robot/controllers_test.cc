// Controllers run from the ControlLoop: each reaches a reachable target and reports kFailed on
// an unreachable one; bad input throws and leaves the scene usable; the control rate divides
// the physics rate. And the IMU: gravity at rest, spin rate, free fall.
#include "partsim/robot/controllers.h"

#include <gtest/gtest.h>

#include <cmath>

#include "robot/test_robots.h"

namespace partsim {
namespace {

using testing::V;

const Eigen::VectorXd kHome = V({0.2, 0.4, -0.3, 0.05, 0.8, 0.3, 0.5});

// A scene at 500 Hz with the 7-dof arm at home and at rest.
struct ArmWorld {
  Scene scene;
  Articulation arm;
  ArmWorld() {
    arm = testing::AddArm7(scene);
    arm.SetQpos(kHome);
  }
};

class Counter : public Controller {
 public:
  using Controller::Controller;
  std::vector<double> times;
  void Update() override { times.push_back(robot_.GetScene()->GetTime()); }
};

TEST(Controller, JointLookupAndPeriod) {
  ArmWorld w;
  JointControllerOptions opt;
  opt.control_rate = 100;
  Counter all(w.arm, {}, opt);
  EXPECT_EQ(all.NumJoints(), 7);
  EXPECT_EQ(all.Period(), 5);
  Counter some(w.arm, {"j5", "j2"}, opt);
  EXPECT_EQ(some.GetDofs(), (std::vector<int>{4, 1}));
  EXPECT_THROW(Counter(w.arm, {"nope"}, opt), Error);
  EXPECT_THROW(Counter(w.arm, {"hand_joint"}, opt), Error);
  opt.control_rate = 2000;  // faster than physics: every step
  EXPECT_EQ(Counter(w.arm, {}, opt).Period(), 1);
}

TEST(ControlLoop, ControlRateBelowPhysicsRate) {
  ArmWorld w;
  JointControllerOptions opt;
  opt.control_rate = 100;  // physics at 500 Hz: an update every 5 steps
  auto slow = std::make_shared<Counter>(w.arm, std::vector<std::string>{}, opt);
  opt.control_rate = 250;
  auto fast = std::make_shared<Counter>(w.arm, std::vector<std::string>{}, opt);
  ControlLoop loop(&w.scene);
  loop.Add(slow);
  loop.Add(fast);
  loop.Step(3);
  loop.Step(47);
  ASSERT_EQ(slow->times.size(), 10u);
  ASSERT_EQ(fast->times.size(), 25u);
  for (size_t i = 0; i < slow->times.size(); ++i)
    EXPECT_NEAR(slow->times[i], i * 5 * 0.002, 1e-9);  // the first at the first step
  EXPECT_NEAR(w.scene.GetTime(), 0.1, 1e-9);
  loop.Remove(fast);
  loop.Step(10);
  EXPECT_EQ(fast->times.size(), 25u);
  EXPECT_EQ(slow->times.size(), 12u);
  EXPECT_THROW(loop.Add(slow), Error);  // twice
}

TEST(JointPositionController, ReachesTargetWithGravityCompensation) {
  ArmWorld w;
  auto c = std::make_shared<JointPositionController>(w.arm, std::vector<std::string>{},
                                                     JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  Eigen::VectorXd target = V({-0.5, 0.7, 0.4, 0.1, 1.2, -0.6, -0.4});
  c->SetTarget(target);
  EXPECT_EQ(c->GetStatus().state, ControllerState::kRunning);
  EXPECT_TRUE(loop.RunUntilDone(5.0)) << c->GetStatus().message;
  EXPECT_EQ(c->GetStatus().state, ControllerState::kReached);
  loop.Step(500);  // holds
  double err = (w.arm.GetQpos() - target).cwiseAbs().maxCoeff();
  std::printf("position controller: steady-state error %.2e rad after 1 s of hold\n", err);
  EXPECT_LT(err, 1e-3);
}

TEST(JointPositionController, TargetBeyondLimitsIsClampedAndFails) {
  ArmWorld w;
  auto c = std::make_shared<JointPositionController>(w.arm, std::vector<std::string>{"j2", "j4"},
                                                     JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  c->SetTarget(V({2.5, 0.1}));  // j2's upper limit is 1.8
  EXPECT_EQ(c->GetStatus().state, ControllerState::kFailed);
  EXPECT_NE(c->GetStatus().message.find("j2"), std::string::npos) << c->GetStatus().message;
  EXPECT_EQ(c->GetTarget(), V({1.8, 0.1}));
  EXPECT_FALSE(loop.RunUntilDone(2.0));  // failed already
  loop.Step(1000);
  EXPECT_NEAR(w.arm.GetQpos()[1], 1.8, 2e-2);  // went as far as it could
  EXPECT_NEAR(w.arm.GetQpos()[3], 0.1, 1e-2);
}

TEST(JointPositionController, TwoControllersShareOneRobot) {
  ArmWorld w;
  auto a = std::make_shared<JointPositionController>(
      w.arm, std::vector<std::string>{"j1", "j2", "j3"}, JointControllerOptions());
  JointControllerOptions opt;
  opt.control_rate = 50;
  auto b = std::make_shared<JointPositionController>(
      w.arm, std::vector<std::string>{"j4", "j5", "j6", "j7"}, opt);
  ControlLoop loop(&w.scene);
  loop.Add(a);
  loop.Add(b);
  a->SetTarget(V({0.5, -0.3, 0.2}));
  b->SetTarget(V({0.12, -0.5, 0.4, 0.9}));
  EXPECT_TRUE(loop.RunUntilDone(5.0));
  Eigen::VectorXd expected = V({0.5, -0.3, 0.2, 0.12, -0.5, 0.4, 0.9});
  EXPECT_LT((w.arm.GetQpos() - expected).cwiseAbs().maxCoeff(), 1e-2);
  // each wrote only its own dofs of qf: together they cancel gravity on every joint
  Eigen::VectorXd qf = w.arm.GetQf(), passive = w.arm.ComputePassiveForce();
  EXPECT_LT((qf - passive).cwiseAbs().maxCoeff(), 0.5);
  EXPECT_GT(qf.cwiseAbs().maxCoeff(), 1.0);
}

TEST(JointPositionController, BadInputThrowsAndSceneStillSteps) {
  ArmWorld w;
  auto c = std::make_shared<JointPositionController>(w.arm, std::vector<std::string>{},
                                                     JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  Eigen::VectorXd nan_target = kHome;
  nan_target[2] = NAN;
  try {
    c->SetTarget(nan_target);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("j3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(c->SetTarget(V({0, 0})), Error);
  EXPECT_EQ(c->GetStatus().state, ControllerState::kIdle);
  loop.Step(250);
  EXPECT_TRUE(w.scene.GetWarnings().empty());
  EXPECT_LT((w.arm.GetQpos() - kHome).cwiseAbs().maxCoeff(), 1e-3);  // held where it was
  EXPECT_THROW(JointPositionController(w.arm, {"j1"},
                                       [] {
                                         JointControllerOptions o;
                                         o.control_rate = -1;
                                         return o;
                                       }()),
               Error);
}

TEST(JointVelocityController, ReachesVelocity) {
  Scene scene;
  Articulation planar = testing::AddPlanar2(scene);
  JointControllerOptions opt;
  opt.damping = 50;
  auto c =
      std::make_shared<JointVelocityController>(planar, std::vector<std::string>{"shoulder"}, opt);
  ControlLoop loop(&scene);
  loop.Add(c);
  c->SetTarget(V({0.5}));
  EXPECT_TRUE(loop.RunUntilDone(1.0)) << c->GetStatus().message;
  loop.Step(250);
  EXPECT_NEAR(planar.GetQvel()[0], 0.5, 1e-2);
  EXPECT_EQ(c->GetStatus().state, ControllerState::kReached);
  EXPECT_THROW(c->SetTarget(V({INFINITY})), Error);
}

TEST(JointVelocityController, VelocityIntoLimitFailsAfterTimeout) {
  Scene scene;
  Articulation slider = testing::AddSlider(scene);
  JointControllerOptions opt;
  opt.timeout = 1.0;
  auto c = std::make_shared<JointVelocityController>(slider, std::vector<std::string>{}, opt);
  ControlLoop loop(&scene);
  loop.Add(c);
  c->SetTarget(V({0.5}));  // reaches the upper limit (0.5 m) after about 1 s
  EXPECT_TRUE(loop.RunUntilDone(0.5));
  EXPECT_EQ(c->GetStatus().state, ControllerState::kReached);
  while (c->GetStatus().state != ControllerState::kFailed && scene.GetTime() < 5.0) loop.Step(5);
  EXPECT_EQ(c->GetStatus().state, ControllerState::kFailed);
  EXPECT_NE(c->GetStatus().message.find("limit"), std::string::npos) << c->GetStatus().message;
  EXPECT_GT(scene.GetTime(), 2.0);  // not before the timeout
  EXPECT_LT(scene.GetTime(), 2.5);
  EXPECT_NEAR(slider.GetQpos()[0], 0.5, 1e-2);
}

TEST(JointTrajectoryController, FollowsTimedPath) {
  ArmWorld w;
  auto c = std::make_shared<JointTrajectoryController>(w.arm, std::vector<std::string>{},
                                                       JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  std::vector<Eigen::VectorXd> path = {kHome, V({0.6, 0.2, 0.0, 0.1, 1.0, 0.0, 0.0}),
                                       V({-0.4, 0.6, 0.3, 0.0, 0.5, -0.5, 0.6})};
  c->SetPath(path, Eigen::VectorXd::Constant(7, 1.0), Eigen::VectorXd::Constant(7, 2.0));
  const JointTrajectory& t = c->GetTrajectory();
  double worst = 0;
  while (w.scene.GetTime() < t.Duration()) {
    loop.Step(5);
    Eigen::VectorXd q;
    t.Sample(w.scene.GetTime(), &q);
    worst = std::max(worst, (w.arm.GetQpos() - q).cwiseAbs().maxCoeff());
  }
  std::printf("trajectory (%.2f s): max tracking error %.2e rad\n", t.Duration(), worst);
  EXPECT_LT(worst, 0.02);
  EXPECT_TRUE(loop.RunUntilDone(2.0)) << c->GetStatus().message;
  EXPECT_LT((w.arm.GetQpos() - path.back()).cwiseAbs().maxCoeff(), 1e-2);
}

TEST(JointTrajectoryController, WaypointOutsideLimitsFailsAndNothingMoves) {
  ArmWorld w;
  auto c = std::make_shared<JointTrajectoryController>(w.arm, std::vector<std::string>{},
                                                       JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  JointTrajectory t;
  t.times = {0.0, 1.0, 2.0};
  t.positions = {kHome, V({0.6, 0.2, 0.0, 0.3, 1.0, 0.0, 0.0}), kHome};  // j4 beyond 0.15
  c->SetTrajectory(t);
  EXPECT_EQ(c->GetStatus().state, ControllerState::kFailed);
  EXPECT_NE(c->GetStatus().message.find("j4"), std::string::npos);
  EXPECT_NE(c->GetStatus().message.find("waypoint 1"), std::string::npos);
  loop.Step(500);
  EXPECT_LT((w.arm.GetQpos() - kHome).cwiseAbs().maxCoeff(), 1e-3);
  t.positions.pop_back();  // wrong sizes throw
  EXPECT_THROW(c->SetTrajectory(t), Error);
}

TEST(JointTrajectoryController, BlockedJointExceedsPathTolerance) {
  Scene scene;
  Articulation slider = testing::AddSlider(scene);
  JointControllerOptions opt;
  opt.force_limit = 5.0;  // too weak to lift the carriage quickly
  opt.gravity_compensation = false;
  auto c = std::make_shared<JointTrajectoryController>(slider, std::vector<std::string>{}, opt);
  c->path_tolerance = 0.05;
  ControlLoop loop(&scene);
  loop.Add(c);
  JointTrajectory t;
  t.times = {0.0, 0.5};
  t.positions = {V({0.0}), V({0.4})};
  c->SetTrajectory(t);
  EXPECT_FALSE(loop.RunUntilDone(3.0));
  EXPECT_NE(c->GetStatus().message.find("path_tolerance"), std::string::npos);
}

TEST(JointEffortController, HoldsWithGravityCompensationAndAccelerates) {
  Scene scene;
  Articulation slider = testing::AddSlider(scene);
  JointControllerOptions opt;
  opt.force_limit = 3.0;
  auto c = std::make_shared<JointEffortController>(slider, std::vector<std::string>{}, opt);
  ControlLoop loop(&scene);
  loop.Add(c);
  loop.Step(500);  // no target: gravity compensation alone holds the carriage
  EXPECT_NEAR(slider.GetQpos()[0], 0.0, 1e-3);
  c->SetTarget(V({2.0}));  // 2 N on 1 kg: 2 m/s^2 upwards
  EXPECT_EQ(c->GetStatus().state, ControllerState::kReached);
  loop.Step(250);
  EXPECT_NEAR(slider.GetQpos()[0], 0.5 * 2.0 * 0.25, 5e-3);
  EXPECT_NEAR(slider.GetQvel()[0], 2.0 * 0.5, 1e-2);
  c->SetTarget(V({-10.0}));
  EXPECT_NE(c->GetStatus().message.find("clamped"), std::string::npos);
  EXPECT_THROW(c->SetTarget(V({1.0, 2.0})), Error);
}

TEST(EndEffectorController, ReachesPoseAndFollowsTwist) {
  ArmWorld w;
  auto c = std::make_shared<EndEffectorController>(w.arm, std::vector<std::string>{}, "hand",
                                                   Pose(Eigen::Vector3d(0, 0, 0.05)),
                                                   JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  KinematicModel model = KinematicModel::FromArticulation(w.arm);
  Pose target = model.LinkPose(V({-0.3, 0.6, 0.2, 0.08, 0.9, -0.2, 0.3}), model.LinkIndex("hand"),
                               Pose(Eigen::Vector3d(0, 0, 0.05)));
  c->SetTargetPose(target);
  ASSERT_EQ(c->GetStatus().state, ControllerState::kRunning) << c->GetStatus().message;
  EXPECT_TRUE(loop.RunUntilDone(8.0)) << c->GetStatus().message;
  const double reached_at = w.scene.GetTime();
  loop.Step(250);  // settle
  Pose reached = c->GetEndEffectorPose();
  double dp = (reached.p - target.p).norm(), dr = reached.q.angularDistance(target.q);
  std::printf(
      "end-effector pose: kReached at t = %.2f s; %.2e m, %.2e rad from the target 0.5 s later\n",
      reached_at, dp, dr);
  EXPECT_LT(dp, 2e-3);
  EXPECT_LT(dr, M_PI / 180);
  // a target in the base frame (the base is at the origin here: the same pose)
  c->SetTargetPose(target, ControlFrame::kBase);
  EXPECT_NE(c->GetStatus().state, ControllerState::kFailed);
  // twist: 5 cm/s along x for 1 s
  Pose start = c->GetEndEffectorPose();
  Eigen::Matrix<double, 6, 1> twist;
  twist << 0.05, 0, 0, 0, 0, 0;
  c->SetTargetTwist(twist);
  loop.Step(500);
  twist.setZero();
  c->SetTargetTwist(twist);
  loop.Step(250);
  Pose end = c->GetEndEffectorPose();
  std::printf("twist: moved %.4f m along x (commanded 0.05), %.2e m across\n",
              end.p.x() - start.p.x(),
              (end.p - start.p - Eigen::Vector3d(end.p.x() - start.p.x(), 0, 0)).norm());
  EXPECT_NEAR(end.p.x() - start.p.x(), 0.05, 3e-3);
  EXPECT_LT((end.p - start.p).tail<2>().norm(), 3e-3);
  EXPECT_LT(end.q.angularDistance(start.q), 1e-2);
}

TEST(EndEffectorController, UnreachablePoseFailsAndArmStays) {
  ArmWorld w;
  auto c = std::make_shared<EndEffectorController>(w.arm, std::vector<std::string>{}, "hand",
                                                   Pose(), JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  loop.Step(50);
  Eigen::VectorXd before = w.arm.GetQpos();
  c->SetTargetPose(Pose(Eigen::Vector3d(3.0, 0.0, 0.5)));
  EXPECT_EQ(c->GetStatus().state, ControllerState::kFailed);
  EXPECT_NE(c->GetStatus().message.find("out of reach"), std::string::npos);
  EXPECT_FALSE(loop.RunUntilDone(1.0));
  EXPECT_LT((w.arm.GetQpos() - before).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_THROW(c->SetTargetPose(Pose(Eigen::Vector3d(NAN, 0, 0))), Error);
  EXPECT_THROW(EndEffectorController(w.arm, {}, "nope", Pose(), JointControllerOptions()), Error);
}

TEST(Imu, ReadsGravityAtRest) {
  Scene scene;
  scene.AddGround(0);
  Actor box = scene.CreateActorBuilder()
                  .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1))
                  .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 0.1)))
                  .Build();
  scene.Step(500);
  // sensor tilted by 90 degrees about x: world up is its -y... its y axis points down
  Imu imu(box, Pose(Eigen::Vector3d(0.05, 0, 0),
                    Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()))));
  ImuReading r = imu.Read();
  EXPECT_LT((r.linear_acceleration - Eigen::Vector3d(0, 9.81, 0)).norm(), 0.05)
      << r.linear_acceleration.transpose();
  EXPECT_LT(r.angular_velocity.norm(), 1e-3);
  EXPECT_NEAR(r.time, 1.0, 1e-9);
  EXPECT_NEAR(std::abs(r.orientation[0]), std::cos(M_PI / 4), 1e-3);
  // on a link of a fixed robot at rest too
  Articulation arm = testing::AddArm7(scene, Pose(Eigen::Vector3d(1, 0, 0)));
  arm.SetDriveProperty(1e4, 1e3);
  arm.SetDriveTarget(Eigen::VectorXd::Zero(7));
  arm.SetQf(arm.ComputePassiveForce());
  ImuReading l = Imu(arm.FindLinkByName("link3")).Read();
  EXPECT_LT((l.linear_acceleration - Eigen::Vector3d(0, 0, 9.81)).norm(), 0.05);
}

TEST(Imu, ReadsSpinRateAndCentripetalAcceleration) {
  SceneConfig cfg;
  cfg.gravity.setZero();
  Scene scene(cfg);
  Actor ball = scene.CreateActorBuilder()
                   .AddSphereCollision(Pose(), 0.1)
                   .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 1)))
                   .Build();
  ball.SetAngularVelocity(Eigen::Vector3d(0, 0, 2.0));
  scene.Step(100);
  const double r = 0.05;
  Imu imu(ball, Pose(Eigen::Vector3d(r, 0, 0)));
  ImuReading reading = imu.Read();
  // the sensor turns with the ball: the rate about its own z is the same
  EXPECT_LT((reading.angular_velocity - Eigen::Vector3d(0, 0, 2.0)).norm(), 1e-6);
  // proper acceleration points to the axis: -w^2 r along the sensor's x
  EXPECT_LT((reading.linear_acceleration - Eigen::Vector3d(-4.0 * r, 0, 0)).norm(), 1e-3)
      << reading.linear_acceleration.transpose();
}

TEST(Imu, FreeFallReadsZero) {
  Scene scene;
  Actor box = scene.CreateActorBuilder()
                  .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1))
                  .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 10)))
                  .Build();
  scene.Step(100);
  ImuReading r = Imu(box).Read();
  EXPECT_LT(r.linear_acceleration.norm(), 0.05) << r.linear_acceleration.transpose();
  EXPECT_LT(box.GetPose().p.z(), 9.9);  // it does fall
}

}  // namespace
}  // namespace partsim
