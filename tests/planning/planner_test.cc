#include "partsim/planning/planner.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "partsim/core/error.h"
#include "partsim/robot/controllers.h"
#include "partsim/robot/kinematics.h"
#include "partsim/robot/robots.h"

namespace partsim {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

/// A Panda on the ground with a post (a static box) where its hand passes at joint1 = 0, so that
/// turning joint1 from -1 to +1 with the arm at home sweeps the hand through the post.
struct PandaWorld {
  Scene scene;
  RobotModel robot = BuildPanda();
  Articulation arm;
  Actor post;
  VectorXd start, goal, middle;  ///< arm joints only

  PandaWorld() {
    scene.AddGround(0.0);
    arm = scene.AddArticulation(robot.articulation);
    VectorXd home(7);
    for (int i = 0; i < 7; ++i) home[i] = robot.home[i];
    start = goal = middle = home;
    start[0] = -1.0;
    goal[0] = 1.0;
    arm.SetQpos(Full(middle));
    // the post around the hand at the middle configuration
    KinematicModel km = KinematicModel::FromArticulation(arm);
    Pose tcp = km.LinkPose(Full(middle), km.LinkIndex(robot.ee_link), robot.tcp_in_ee);
    post = scene.CreateActorBuilder()
               .SetName("post")
               .AddBoxCollision(Pose(), Vector3d(0.04, 0.04, 0.12))
               .SetInitialPose(Pose(tcp.p))
               .BuildStatic();
    arm.SetQpos(Full(start));
    arm.SetDriveTarget(Full(start));
  }
  /// Articulation qpos (arm joints, then the fingers open) from arm joints.
  VectorXd Full(const VectorXd& q) const {
    VectorXd full = VectorXd::Constant(arm.Dof(), 0.04);
    for (int i = 0; i < 7; ++i) full[arm.FindJointByName(robot.arm_joints[i]).GetDofIndex()] = q[i];
    return full;
  }
  Eigen::VectorXd VelocityLimits() const {
    return Eigen::Map<const VectorXd>(robot.arm_velocity_limits.data(), 7) * 0.5;
  }
};

/// Independent collision check: a clone of the scene stepped once from each state; reports
/// whether any link of the arm touches the post.
class ContactProbe {
 public:
  explicit ContactProbe(const PandaWorld& w)
      : clone_(w.scene.Clone()), arm_(clone_.get(), w.arm.GetId()), w_(w) {}
  bool Touches(const VectorXd& q) {
    arm_.SetQpos(w_.Full(q));
    arm_.SetQvel(VectorXd::Zero(arm_.Dof()));
    clone_->Step(1);
    return ArmTouchesPost(*clone_, w_.arm.GetId(), w_.post.GetId());
  }
  static bool ArmTouchesPost(const Scene& scene, int arm, int post) {
    for (const Contact& c : scene.GetContacts()) {
      bool a0 = c.body0.kind == ContactBody::Kind::kLink && c.body0.articulation_id == arm;
      bool a1 = c.body1.kind == ContactBody::Kind::kLink && c.body1.articulation_id == arm;
      bool p0 = c.body0.kind == ContactBody::Kind::kActor && c.body0.actor_id == post;
      bool p1 = c.body1.kind == ContactBody::Kind::kActor && c.body1.actor_id == post;
      if ((a0 && p1) || (a1 && p0)) return true;
    }
    return false;
  }

 private:
  std::unique_ptr<Scene> clone_;
  Articulation arm_;
  const PandaWorld& w_;
};

/// States every `step` rad along the polyline through `path`.
std::vector<VectorXd> Interpolate(const std::vector<VectorXd>& path, double step) {
  std::vector<VectorXd> out = {path.front()};
  for (size_t i = 1; i < path.size(); ++i) {
    int n = std::max(
        1, static_cast<int>(std::ceil((path[i] - path[i - 1]).cwiseAbs().maxCoeff() / step)));
    for (int k = 1; k <= n; ++k)
      out.push_back(path[i - 1] + (path[i] - path[i - 1]) * (static_cast<double>(k) / n));
  }
  return out;
}

TEST(MotionPlanner, PlansAroundThePostAndTheArmFollowsWithoutContact) {
  PandaWorld w;
  ContactProbe probe(w);
  // the straight joint-space line hits the post
  int hits = 0;
  for (const VectorXd& q : Interpolate({w.start, w.goal}, M_PI / 180)) hits += probe.Touches(q);
  ASSERT_GT(hits, 0);

  MotionPlanner planner(w.arm, w.robot.arm_joints, w.VelocityLimits(), VectorXd::Constant(7, 2.0));
  EXPECT_FALSE(planner.IsStateValid(w.middle));
  EXPECT_TRUE(planner.IsStateValid(w.start));
  PlannerOptions opt;
  opt.clearance = 0.02;
  const std::vector<char> before = w.scene.Pack();
  PlanResult r = planner.PlanToJoints(w.goal, opt);
  EXPECT_EQ(w.scene.Pack(), before);
  ASSERT_TRUE(r.success) << r.message;
  std::printf("planned in %.3f s: %zu waypoints, trajectory %.2f s\n", r.planning_time,
              r.path.size(), r.trajectory.Duration());
  EXPECT_LT((r.path.front() - w.start).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((r.path.back() - w.goal).cwiseAbs().maxCoeff(), 1e-9);
  // every state along the path and along the timed trajectory is free
  for (const VectorXd& q : Interpolate(r.path, M_PI / 180)) ASSERT_FALSE(probe.Touches(q));
  VectorXd q;
  for (double t = 0; t <= r.trajectory.Duration(); t += 0.01) {
    r.trajectory.Sample(t, &q);
    ASSERT_FALSE(probe.Touches(q)) << "t = " << t;
  }

  // executed in the real scene, the arm never touches the post
  auto c = std::make_shared<JointTrajectoryController>(w.arm, w.robot.arm_joints,
                                                       JointControllerOptions());
  ControlLoop loop(&w.scene);
  loop.Add(c);
  c->SetTrajectory(r.trajectory);
  int steps = 0, touching = 0;
  const double end = w.scene.GetTime() + r.trajectory.Duration() + 1.0;
  while (w.scene.GetTime() < end) {
    loop.Step(1);
    ++steps;
    touching += ContactProbe::ArmTouchesPost(w.scene, w.arm.GetId(), w.post.GetId());
  }
  EXPECT_EQ(touching, 0) << "of " << steps << " steps";
  EXPECT_EQ(c->GetStatus().state, ControllerState::kReached) << c->GetStatus().message;
  EXPECT_LT((planner.GetCurrentPositions() - w.goal).cwiseAbs().maxCoeff(), 1e-2);
}

TEST(MotionPlanner, PoseGoal) {
  PandaWorld w;
  KinematicModel km = KinematicModel::FromArticulation(w.arm);
  const int hand = km.LinkIndex(w.robot.ee_link);
  const Pose target = km.LinkPose(w.Full(w.goal), hand, w.robot.tcp_in_ee);
  MotionPlanner planner(w.arm, w.robot.arm_joints);
  PlannerOptions opt;
  opt.clearance = 0.02;
  PlanResult r = planner.PlanToPose(w.robot.ee_link, w.robot.tcp_in_ee, target, opt);
  ASSERT_TRUE(r.success) << r.message;
  std::printf("pose goal planned in %.3f s\n", r.planning_time);
  Pose reached = km.LinkPose(w.Full(r.path.back()), hand, w.robot.tcp_in_ee);
  Eigen::Matrix<double, 6, 1> e = PoseError(reached, target);
  EXPECT_LT(e.head<3>().norm(), 1e-3);
  EXPECT_LT(e.tail<3>().norm(), 1e-2);
  ContactProbe probe(w);
  for (const VectorXd& q : Interpolate(r.path, M_PI / 180)) ASSERT_FALSE(probe.Touches(q));
}

TEST(MotionPlanner, GoalInsideTheObstacleFailsCleanly) {
  PandaWorld w;
  MotionPlanner planner(w.arm, w.robot.arm_joints);
  const std::vector<char> before = w.scene.Pack();
  PlanResult r = planner.PlanToJoints(w.middle);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("goal"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("post"), std::string::npos) << r.message;
  EXPECT_TRUE(r.path.empty());
  // a pose inside the post: no collision-free IK solution
  KinematicModel km = KinematicModel::FromArticulation(w.arm);
  Pose inside = km.LinkPose(w.Full(w.middle), km.LinkIndex(w.robot.ee_link), w.robot.tcp_in_ee);
  r = planner.PlanToPose(w.robot.ee_link, w.robot.tcp_in_ee, inside);
  EXPECT_FALSE(r.success);
  EXPECT_FALSE(r.message.empty());
  EXPECT_EQ(w.scene.Pack(), before);
}

// RRT* improves its path until the time limit: a cancel from another thread ends it at once
// (a server shutting down must not wait for a 20 s plan).
TEST(MotionPlanner, CancelStopsPlanningWithinTheTimeLimit) {
  PandaWorld w;
  MotionPlanner planner(w.arm, w.robot.arm_joints, w.VelocityLimits(), VectorXd::Constant(7, 2.0));
  std::atomic<bool> cancel{false};
  PlannerOptions opt;
  opt.algorithm = "RRTstar";
  opt.time_limit = 20.0;
  opt.cancel = &cancel;
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    cancel = true;
  });
  PlanResult r = planner.PlanToJoints(w.goal, opt);
  canceller.join();
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.message, "cancelled");
  EXPECT_LT(r.planning_time, 10.0);
  // cancelled before it starts: a pose goal gives up too
  KinematicModel km = KinematicModel::FromArticulation(w.arm);
  Pose reachable = km.LinkPose(w.Full(w.goal), km.LinkIndex(w.robot.ee_link), w.robot.tcp_in_ee);
  r = planner.PlanToPose(w.robot.ee_link, w.robot.tcp_in_ee, reachable, opt);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("cancelled"), std::string::npos) << r.message;
}

TEST(MotionPlanner, BadRequests) {
  PandaWorld w;
  MotionPlanner planner(w.arm, w.robot.arm_joints);
  EXPECT_THROW(planner.PlanToJoints(VectorXd::Zero(6)), Error);
  VectorXd nan = w.goal;
  nan[2] = std::nan("");
  EXPECT_THROW(planner.PlanToJoints(nan), Error);
  PlannerOptions bad;
  bad.algorithm = "Teleport";
  EXPECT_THROW(planner.PlanToJoints(w.goal, bad), Error);
  EXPECT_THROW(planner.PlanToPose("no_such_link", Pose(), Pose()), Error);
  EXPECT_THROW(MotionPlanner(w.arm, {"no_such_joint"}), Error);
  // beyond a limit: no plan, the joint is named
  VectorXd far = w.goal;
  far[3] = 1.0;  // panda_joint4 lies in [-3.07, -0.07]
  PlanResult r = planner.PlanToJoints(far);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("panda_joint4"), std::string::npos) << r.message;
}

TEST(MotionPlanner, AGoalAHairOutsideALimitIsPulledIn) {
  // a goal read from a state that rests on a limit (physics holds limits a hair softly)
  PandaWorld w;
  MotionPlanner planner(w.arm, w.robot.arm_joints);
  VectorXd goal = w.start;
  goal[3] = -0.0698 + 5e-4;  // panda_joint4's upper limit is -0.0698
  goal[0] = -0.5;
  PlanResult r = planner.PlanToJoints(goal);
  EXPECT_TRUE(r.success) << r.message;
  ASSERT_FALSE(r.path.empty());
  EXPECT_LE(r.path.back()[3], -0.0698 + 1e-12);
  goal[3] = -0.0698 + 0.01;  // clearly beyond: refused
  EXPECT_FALSE(planner.PlanToJoints(goal).success);
}

TEST(MotionPlanner, OtherAlgorithmsFindAPath) {
  PandaWorld w;
  MotionPlanner planner(w.arm, w.robot.arm_joints);
  for (const char* name : {"RRT", "KPIECE1"}) {
    PlannerOptions opt;
    opt.algorithm = name;
    opt.time_limit = 5.0;
    PlanResult r = planner.PlanToJoints(w.goal, opt);
    EXPECT_TRUE(r.success) << name << ": " << r.message;
    std::printf("%s: %.3f s\n", name, r.planning_time);
  }
}

}  // namespace
}  // namespace partsim
