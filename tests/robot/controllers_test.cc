// Controllers run from the ControlLoop: each reaches a reachable target and reports kFailed on
// an unreachable one; bad input throws and leaves the scene usable; the control rate divides
// the physics rate; settings that make no sense throw naming the setting and its value.
#include "partsim/robot/controllers.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "error_of.h"
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

using partsim::testing::ErrorOf;

// A setting out of range, the text its value prints as, and how to apply it.
template <typename T>
struct BadSetting {
  std::string name, value;
  std::function<void(T&)> set;
};

TEST(Controller, EachBadOptionThrowsNamingItAndItsValue) {
  ArmWorld w;
  const std::vector<BadSetting<JointControllerOptions>> cases = {
      {"control_rate", "-100", [](auto& o) { o.control_rate = -100; }},
      {"control_rate", "0", [](auto& o) { o.control_rate = 0; }},
      {"control_rate", "inf", [](auto& o) { o.control_rate = kInf; }},
      {"stiffness", "-1", [](auto& o) { o.stiffness = -1; }},
      {"stiffness", "nan", [](auto& o) { o.stiffness = NAN; }},
      {"damping", "-2", [](auto& o) { o.damping = -2; }},
      {"damping", "inf", [](auto& o) { o.damping = kInf; }},
      {"force_limit", "0", [](auto& o) { o.force_limit = 0; }},
      {"force_limit", "nan", [](auto& o) { o.force_limit = NAN; }},
      {"position_tolerance", "-0.01", [](auto& o) { o.position_tolerance = -0.01; }},
      {"velocity_tolerance", "nan", [](auto& o) { o.velocity_tolerance = NAN; }},
      {"timeout", "-5", [](auto& o) { o.timeout = -5; }},
  };
  for (const auto& c : cases) {
    JointControllerOptions opt;
    c.set(opt);
    const std::string what = ErrorOf([&] { JointPositionController(w.arm, {}, opt); });
    EXPECT_NE(what.find(c.name), std::string::npos) << c.name << ": " << what;
    EXPECT_NE(what.find("got " + c.value), std::string::npos) << c.name << ": " << what;
    EXPECT_NE(ErrorOf([&] { opt.Validate("test"); }), "") << c.name;
  }
  // the limits that mean "none" are allowed
  JointControllerOptions unlimited;
  unlimited.force_limit = unlimited.timeout = unlimited.position_tolerance = kInf;
  EXPECT_NO_THROW(JointPositionController(w.arm, {}, unlimited));
}

TEST(JointTrajectoryController, BadPathToleranceThrowsWhereItIsUsed) {
  ArmWorld w;
  auto c = std::make_shared<JointTrajectoryController>(w.arm, std::vector<std::string>{},
                                                       JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  JointTrajectory t;
  t.times = {0.0, 1.0};
  t.positions = {kHome, kHome};
  for (double bad : {-0.1, 0.0, double(NAN)}) {
    c->path_tolerance = bad;
    const std::string what = ErrorOf([&] { c->SetTrajectory(t); });
    EXPECT_NE(what.find("path_tolerance must be > 0, got"), std::string::npos) << what;
    EXPECT_EQ(c->GetStatus().state, ControllerState::kIdle);  // nothing was taken
  }
  // set while following: the next update refuses it, and the loop steps on once it is fixed
  c->path_tolerance = 0.1;
  c->SetTrajectory(t);
  c->path_tolerance = -1;
  EXPECT_NE(ErrorOf([&] { loop.Step(10); }).find("path_tolerance must be > 0, got -1"),
            std::string::npos);
  c->path_tolerance = 0.1;
  EXPECT_TRUE(loop.RunUntilDone(3.0)) << c->GetStatus().message;
}

TEST(EndEffectorController, EachBadSettingThrowsNamingItAndItsValue) {
  Eigen::Matrix<double, 6, 1> twist;
  twist << 0.05, 0, 0, 0, 0, 0.1;
  const std::vector<BadSetting<EndEffectorController>> cases = {
      {"max_linear_speed", "-0.5", [](auto& e) { e.max_linear_speed = -0.5; }},
      {"max_linear_speed", "0", [](auto& e) { e.max_linear_speed = 0; }},
      {"max_linear_speed", "nan", [](auto& e) { e.max_linear_speed = NAN; }},
      {"max_angular_speed", "-1.5", [](auto& e) { e.max_angular_speed = -1.5; }},
      {"max_angular_speed", "nan", [](auto& e) { e.max_angular_speed = NAN; }},
      {"position_tolerance", "-0.002", [](auto& e) { e.position_tolerance = -0.002; }},
      {"rotation_tolerance", "nan", [](auto& e) { e.rotation_tolerance = NAN; }},
      {"ik.position_tolerance", "0", [](auto& e) { e.ik.position_tolerance = 0; }},
      {"ik.rotation_tolerance", "-1", [](auto& e) { e.ik.rotation_tolerance = -1; }},
      {"ik.max_step", "nan", [](auto& e) { e.ik.max_step = NAN; }},
      {"ik.damping", "-0.01", [](auto& e) { e.ik.damping = -0.01; }},
      {"ik.max_iterations", "0", [](auto& e) { e.ik.max_iterations = 0; }},
      {"ik.restarts", "-1", [](auto& e) { e.ik.restarts = -1; }},
      {"ik.active", "3 entries",
       [](auto& e) {
         e.ik.active = {true, true, true};
       }},
  };
  for (const auto& bad : cases) {
    ArmWorld w;
    auto c = std::make_shared<EndEffectorController>(w.arm, std::vector<std::string>{}, "hand",
                                                     Pose(), JointControllerOptions());
    ControlLoop loop(&w.scene);
    loop.Add(c);
    const Pose here = c->GetEndEffectorPose();
    // refused when a target is set, and at the next update of a target set before
    c->SetTargetTwist(Eigen::Matrix<double, 6, 1>::Zero());
    bad.set(*c);
    for (const std::string& what :
         {ErrorOf([&] { c->SetTargetTwist(twist); }), ErrorOf([&] { c->SetTargetPose(here); }),
          ErrorOf([&] { loop.Step(10); })}) {
      EXPECT_NE(what.find(bad.name), std::string::npos) << bad.name << ": " << what;
      EXPECT_NE(what.find(bad.value), std::string::npos) << bad.name << ": " << what;
    }
  }
}

TEST(EndEffectorController, ANegativeSpeedLimitDoesNotFlipTheTwist) {
  ArmWorld w;
  auto c = std::make_shared<EndEffectorController>(w.arm, std::vector<std::string>{}, "hand",
                                                   Pose(), JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  loop.Step(50);
  const Pose start = c->GetEndEffectorPose();
  Eigen::Matrix<double, 6, 1> twist;
  twist << 0.2, 0, 0, 0, 0, 0;
  c->max_linear_speed = -0.05;  // scaling by -0.05 / 0.2 would send the hand along -x
  EXPECT_THROW(c->SetTargetTwist(twist), Error);
  EXPECT_THROW(loop.Step(1), Error);  // and so do the updates while the limit stays negative
  // the twist was not taken: the hand holds
  c->max_linear_speed = 0.05;
  loop.Step(250);
  EXPECT_LT((c->GetEndEffectorPose().p - start.p).norm(), 2e-3);
  // a positive limit scales the twist down along its own direction
  c->SetTargetTwist(twist);
  EXPECT_NE(c->GetStatus().message.find("clamped to 0.05"), std::string::npos);
  loop.Step(250);  // 0.5 s, then stop and settle
  c->SetTargetTwist(Eigen::Matrix<double, 6, 1>::Zero());
  loop.Step(250);
  EXPECT_NEAR(c->GetEndEffectorPose().p.x() - start.p.x(), 0.025, 3e-3);
}

}  // namespace
}  // namespace partsim
