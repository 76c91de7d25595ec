// ServedRobot: trajectory goals and how they end (success, preemption, cancel, invalid goals,
// tolerances), feedback, command checks, effort control, planning off the simulation thread, and
// the frames it reads. Most tests step a paused SimServer by hand, so that which command lands
// at which step does not depend on the machine's speed; planning runs with the server stepping.
#include "partsim/server/served_robot.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/scene_render.h"
#include "partsim/robot/robots.h"
#include "server/wait_for.h"

namespace partsim {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;
using testing::WaitFor;

/// Runs `f` on the simulation thread and returns what it returns (throws if it never runs).
template <class F>
auto OnSim(SimServer& sim, F f) -> decltype(f()) {
  using R = decltype(f());
  auto p = std::make_shared<std::promise<R>>();
  std::future<R> fut = p->get_future();
  sim.Post([p, f] { p->set_value(f()); });
  if (fut.wait_for(std::chrono::seconds(10)) != std::future_status::ready)
    throw std::runtime_error("the simulation thread did not run the command");
  return fut.get();
}

/// Records how a goal ended, and how often it was told.
class DoneRecorder {
 public:
  ServedRobot::DoneCallback Callback() {
    return [this](TrajectoryOutcome o, const std::string& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++calls_;
      outcome_ = o;
      message_ = m;
    };
  }
  int Calls() {
    std::lock_guard<std::mutex> lock(mutex_);
    return calls_;
  }
  bool Done() { return Calls() > 0; }
  TrajectoryOutcome Outcome() {
    std::lock_guard<std::mutex> lock(mutex_);
    return outcome_;
  }
  std::string Message() {
    std::lock_guard<std::mutex> lock(mutex_);
    return message_;
  }

 private:
  std::mutex mutex_;
  int calls_ = 0;
  TrajectoryOutcome outcome_ = TrajectoryOutcome::kSucceeded;
  std::string message_;
};

/// Expects `f` to throw partsim::Error whose message contains `part`.
template <class F>
void ExpectError(F f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no partsim::Error; expected one naming \"" << part << "\"";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
        << "\"" << e.what() << "\" does not name \"" << part << "\"";
  }
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// A robot on the ground behind a ServedRobot, its SimServer started (paused unless asked).
class World {
 public:
  struct Options {
    bool panda = false;
    bool camera = false;
    bool paused = true;
  };
  explicit World(const Options& o) {
    scene.AddGround(0);
    model = o.panda ? BuildPanda() : BuildFlyingGripper();
    if (!o.panda) model.articulation.root_pose = Pose(Vector3d(0, 0, 0.5));
    robot = scene.AddArticulation(model.articulation);
    if (o.panda) {
      // home, fingers half open (q = 0 lies outside joint 4's limits)
      VectorXd q = VectorXd::Constant(robot.Dof(), 0.02);
      for (size_t i = 0; i < model.arm_joints.size(); ++i)
        q[robot.FindJointByName(model.arm_joints[i]).GetDofIndex()] = model.home[i];
      robot.SetQpos(q);
    }
    if (o.camera) {
      camera = AddCamera(scene, "cam", 32, 24, 1.0, 0.05, 20.0);
      camera.SetLocalPose(CameraLookAt(eye, target));
    }
    loop = std::make_unique<ControlLoop>(&scene);
    SimServerOptions so;
    so.fast = true;
    sim = std::make_unique<SimServer>(&scene, loop.get(), so);
    ServedRobotOptions ro;
    ro.ee_link = model.ee_link;
    ro.tcp_in_ee = model.tcp_in_ee;
    served = std::make_unique<ServedRobot>(sim.get(), &scene, loop.get(), robot,
                                           model.articulation.name, ro);
    sim->Start(o.paused);
  }
  ~World() {
    sim->Stop();
    served.reset();
  }

  /// Steps `seconds` of simulated time on the paused server and waits for them.
  void Advance(double seconds) {
    const long long n = std::lround(seconds / scene.GetTimestep());
    const long long until = sim->GetClockSteps() + n;
    sim->StepN(static_cast<int>(n));
    ASSERT_TRUE(WaitFor([&] { return sim->GetClockSteps() >= until; }));
    OnSim(*sim, [] { return 0; });  // the last step's callbacks have run
  }
  /// Index of a commanded joint.
  int Index(const std::string& joint) const {
    const std::vector<std::string>& names = served->GetJointNames();
    auto it = std::find(names.begin(), names.end(), joint);
    EXPECT_NE(it, names.end()) << joint;
    return static_cast<int>(it - names.begin());
  }
  VectorXd Qpos() {
    return OnSim(*sim, [this] { return robot.GetQpos(); });
  }
  VectorXd Qvel() {
    return OnSim(*sim, [this] { return robot.GetQvel(); });
  }
  std::vector<double> QposVector() {
    VectorXd q = Qpos();
    return std::vector<double>(q.data(), q.data() + q.size());
  }

  const Vector3d eye{1.2, -0.8, 1.0}, target{0, 0, 0.4};  // of the camera
  Scene scene;
  RobotModel model;
  Articulation robot;
  Camera camera;
  std::unique_ptr<ControlLoop> loop;
  std::unique_ptr<SimServer> sim;
  std::unique_ptr<ServedRobot> served;
};

/// A one-point trajectory of the x slide of the flying gripper to `x` at time `t`.
TrajectoryCommand MoveX(double x, double t) {
  TrajectoryCommand c;
  c.joint_names = {"x"};
  c.times = {t};
  c.positions = {{x}};
  return c;
}

// ---- trajectory goals ----

TEST(ServedRobotTest, TrajectoryGoalSucceedsAtItsLastPointAndOtherJointsHold) {
  World w({});
  const VectorXd q0 = w.Qpos();
  TrajectoryCommand c;
  c.joint_names = {"yaw", "z", "x"};  // a subset, in another order than the robot's
  c.times = {0.4, 0.8};
  c.positions = {{0.1, 0.55, 0.05}, {0.3, 0.6, 0.15}};
  DoneRecorder done;
  w.served->CommandTrajectory(c, "test", done.Callback());
  w.Advance(0.4);
  EXPECT_FALSE(done.Done()) << "ended before the trajectory's end: " << done.Message();
  w.Advance(1.0);
  ASSERT_TRUE(done.Done());
  EXPECT_EQ(done.Outcome(), TrajectoryOutcome::kSucceeded) << done.Message();
  EXPECT_EQ(done.Calls(), 1);
  const VectorXd q = w.Qpos();
  EXPECT_NEAR(q[w.Index("yaw")], 0.3, 1e-2);
  EXPECT_NEAR(q[w.Index("z")], 0.6, 1e-2);
  EXPECT_NEAR(q[w.Index("x")], 0.15, 1e-2);
  for (const char* held : {"y", "pitch", "roll"})
    EXPECT_NEAR(q[w.Index(held)], q0[w.Index(held)], 1e-2) << held;
}

TEST(ServedRobotTest, SecondGoalPreemptsTheFirst) {
  World w({});
  DoneRecorder first, second;
  w.served->CommandTrajectory(MoveX(0.4, 2.0), "first", first.Callback());
  w.Advance(0.5);
  EXPECT_FALSE(first.Done());
  w.served->CommandTrajectory(MoveX(-0.1, 1.0), "second", second.Callback());
  w.Advance(0.05);
  ASSERT_TRUE(first.Done());
  EXPECT_EQ(first.Outcome(), TrajectoryOutcome::kPreempted) << first.Message();
  EXPECT_FALSE(second.Done());
  w.Advance(1.5);
  ASSERT_TRUE(second.Done());
  EXPECT_EQ(second.Outcome(), TrajectoryOutcome::kSucceeded) << second.Message();
  EXPECT_NEAR(w.Qpos()[w.Index("x")], -0.1, 1e-2);
  EXPECT_EQ(first.Calls(), 1);  // told once, not again when the second ends
  EXPECT_EQ(second.Calls(), 1);
}

TEST(ServedRobotTest, PositionCommandPreemptsARunningGoalAndTakesOver) {
  World w({});
  DoneRecorder done;
  w.served->CommandTrajectory(MoveX(0.4, 2.0), "goal", done.Callback());
  w.Advance(0.3);
  std::vector<double> q = w.QposVector();
  q[w.Index("y")] = 0.1;
  w.served->CommandPositions(q, "positions");
  w.Advance(0.05);
  ASSERT_TRUE(done.Done());
  EXPECT_EQ(done.Outcome(), TrajectoryOutcome::kPreempted);
  w.Advance(1.0);
  EXPECT_NEAR(w.Qpos()[w.Index("y")], 0.1, 1e-2);
  EXPECT_NEAR(w.Qpos()[w.Index("x")], q[w.Index("x")], 1e-2);  // not on to 0.4
}

TEST(ServedRobotTest, CancelPreemptsAndTheRobotHoldsWhereItIs) {
  World w({});
  DoneRecorder done;
  const long long id = w.served->CommandTrajectory(MoveX(0.6, 1.0), "goal", done.Callback());
  w.Advance(0.4);
  ASSERT_FALSE(done.Done());
  EXPECT_GT(std::abs(w.Qvel()[w.Index("x")]), 0.1);  // moving when cancelled
  // an id that is not the running goal's changes nothing
  w.served->CancelTrajectory(id + 100);
  w.Advance(0.02);
  EXPECT_FALSE(done.Done());
  w.served->CancelTrajectory(id);
  w.Advance(0.02);
  ASSERT_TRUE(done.Done());
  EXPECT_EQ(done.Outcome(), TrajectoryOutcome::kPreempted);
  const double x_cancelled = w.Qpos()[w.Index("x")];
  w.Advance(1.0);
  EXPECT_LT(w.Qvel().cwiseAbs().maxCoeff(), 0.02);
  const double x = w.Qpos()[w.Index("x")];
  EXPECT_NEAR(x, x_cancelled, 0.05);
  EXPECT_LT(x, 0.5);  // did not go on to the goal
  EXPECT_EQ(done.Calls(), 1);
}

TEST(ServedRobotTest, WaypointOutsideTheLimitsIsAnInvalidGoalNamingTheJoint) {
  World w({});
  TrajectoryCommand c = MoveX(0.1, 0.5);
  c.times.push_back(1.0);
  c.positions.push_back({6.0});  // the slides reach +-5 m
  DoneRecorder bad;
  w.served->CommandTrajectory(c, "goal", bad.Callback());
  w.Advance(0.05);
  ASSERT_TRUE(bad.Done());
  EXPECT_EQ(bad.Outcome(), TrajectoryOutcome::kInvalidGoal);
  EXPECT_TRUE(Contains(bad.Message(), "'x'")) << bad.Message();
  w.Advance(0.5);
  EXPECT_NEAR(w.Qpos()[w.Index("x")], 0.0, 1e-2);  // refused whole: did not start towards 0.1
  // and the next goal runs
  DoneRecorder good;
  w.served->CommandTrajectory(MoveX(0.1, 0.5), "goal", good.Callback());
  w.Advance(1.0);
  ASSERT_TRUE(good.Done());
  EXPECT_EQ(good.Outcome(), TrajectoryOutcome::kSucceeded) << good.Message();
  EXPECT_EQ(bad.Calls(), 1);
}

TEST(ServedRobotTest, MalformedCommandsThrowNamingTheProblemAndTheRobotKeepsWorking) {
  World w({});
  ServedRobot& r = *w.served;
  DoneRecorder never;
  auto send = [&](const TrajectoryCommand& c) { r.CommandTrajectory(c, "cmd", never.Callback()); };
  TrajectoryCommand c;

  c = MoveX(0.1, 1.0);
  c.joint_names = {"x", "nope"};
  c.positions = {{0.1, 0.2}};
  ExpectError([&] { send(c); }, "unknown joint 'nope'");
  c.joint_names = {"x", "x"};
  ExpectError([&] { send(c); }, "'x' is named twice");
  c = MoveX(0.1, 1.0);
  c.joint_names.clear();
  c.positions = {{}};
  ExpectError([&] { send(c); }, "no joint_names");
  c = MoveX(0.1, 1.0);
  c.positions = {{0.1, 0.2}};  // two values for one joint
  ExpectError([&] { send(c); }, "2 values for 1 joints");
  c = MoveX(0.1, 1.0);
  c.times = {0.5, 1.0};  // two times, one point
  ExpectError([&] { send(c); }, "1 points with positions for 2 times");
  c = MoveX(0.1, 1.0);
  c.times.clear();
  c.positions.clear();
  ExpectError([&] { send(c); }, "at least one point");
  c = MoveX(0.1, 1.0);
  c.velocities = {{0.0}, {0.0}};
  ExpectError([&] { send(c); }, "velocities given for 2 of 1 points");
  c = MoveX(std::nan(""), 1.0);
  ExpectError([&] { send(c); }, "not finite");
  c = MoveX(0.1, std::numeric_limits<double>::infinity());
  ExpectError([&] { send(c); }, "time_from_start");
  c = MoveX(0.1, -1.0);
  ExpectError([&] { send(c); }, "time_from_start");
  // finite but far off: a spline over 1e200 s has no finite targets
  c = MoveX(0.1, 1e200);
  ExpectError([&] { send(c); }, "time_from_start must be from 0 to 86400 s");
  c = MoveX(0.1, 1.0);
  c.times = {0.5, 0.5};
  c.positions = {{0.1}, {0.2}};
  ExpectError([&] { send(c); }, "point 1: time_from_start does not come after");
  c = MoveX(0.1, 1.0);
  c.goal_time_tolerance = -0.5;
  ExpectError([&] { send(c); }, "goal_time_tolerance");
  c = MoveX(0.1, 1.0);
  c.goal_tolerance = {{"nope", 0.1}};
  ExpectError([&] { send(c); }, "unknown joint 'nope'");
  c = MoveX(0.1, 1.0);
  c.path_tolerance = {{"x", std::nan("")}};
  ExpectError([&] { send(c); }, "tolerance of 'x' is not finite");

  const size_t n = r.GetJointNames().size();
  ExpectError([&] { r.CommandPositions(std::vector<double>(n - 1, 0.0), "pos"); },
              "pos: " + std::to_string(n - 1) + " values for " + std::to_string(n) + " joints");
  std::vector<double> v(n, 0.0);
  v[2] = std::nan("");
  ExpectError([&] { r.CommandVelocities(v, "vel"); }, "vel: value 2 is not finite");
  ExpectError([&] { r.CommandEfforts(std::vector<double>(n + 1, 0.0), "eff"); }, "eff: ");

  // nothing was queued; the robot still takes a goal
  w.Advance(0.1);
  EXPECT_EQ(r.GetCommandStats().commands, 0);
  EXPECT_EQ(never.Calls(), 0);
  DoneRecorder good;
  r.CommandTrajectory(MoveX(0.1, 0.5), "cmd", good.Callback());
  w.Advance(1.0);
  ASSERT_TRUE(good.Done());
  EXPECT_EQ(good.Outcome(), TrajectoryOutcome::kSucceeded) << good.Message();
  EXPECT_EQ(r.GetCommandStats().commands, 1);
}

TEST(ServedRobotTest, TinyGoalToleranceEndsInGoalToleranceViolated) {
  World w({});
  TrajectoryCommand c = MoveX(0.3, 0.3);
  c.goal_tolerance = {{"x", 1e-9}};
  c.goal_time_tolerance = 0.05;
  DoneRecorder done;
  w.served->CommandTrajectory(c, "goal", done.Callback());
  w.Advance(0.3);
  EXPECT_FALSE(done.Done()) << done.Message();  // nothing is judged before the end
  w.Advance(0.5);
  ASSERT_TRUE(done.Done());
  EXPECT_EQ(done.Outcome(), TrajectoryOutcome::kGoalToleranceViolated) << done.Message();
  EXPECT_TRUE(Contains(done.Message(), "'x'")) << done.Message();
}

TEST(ServedRobotTest, TinyPathToleranceOnAFastTrajectoryEndsInPathToleranceViolated) {
  World w({});
  TrajectoryCommand c = MoveX(0.5, 0.3);
  c.path_tolerance = {{"x", 1e-9}};
  DoneRecorder done;
  w.served->CommandTrajectory(c, "goal", done.Callback());
  w.Advance(0.1);
  ASSERT_TRUE(done.Done());
  EXPECT_EQ(done.Outcome(), TrajectoryOutcome::kPathToleranceViolated) << done.Message();
  EXPECT_TRUE(Contains(done.Message(), "'x'")) << done.Message();
  // aborted: the robot holds short of the goal
  w.Advance(1.0);
  EXPECT_LT(w.Qpos()[w.Index("x")], 0.25);
  EXPECT_LT(w.Qvel().cwiseAbs().maxCoeff(), 0.05);
}

TEST(ServedRobotTest, FeedbackComesWhileRunningWithErrorEqualToDesiredMinusActual) {
  World w({});
  std::mutex mutex;
  std::vector<TrajectoryFeedback> feedback;
  bool after_done = false;
  DoneRecorder done;
  auto on_feedback = [&](const TrajectoryFeedback& f) {
    std::lock_guard<std::mutex> lock(mutex);
    if (done.Done()) after_done = true;
    feedback.push_back(f);
  };
  w.served->CommandTrajectory(MoveX(0.2, 0.5), "goal", done.Callback(), on_feedback);
  w.Advance(1.0);
  ASSERT_TRUE(done.Done());
  EXPECT_EQ(done.Outcome(), TrajectoryOutcome::kSucceeded) << done.Message();
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_FALSE(after_done);
  ASSERT_GE(feedback.size(), 10u);  // 50 Hz over 0.5 s
  const size_t n = w.served->GetJointNames().size();
  const int x = w.Index("x");
  double last_time = -1, max_error = 0;
  for (const TrajectoryFeedback& f : feedback) {
    EXPECT_EQ(f.joint_names, w.served->GetJointNames());
    ASSERT_EQ(static_cast<size_t>(f.desired.size()), n);
    ASSERT_EQ(static_cast<size_t>(f.actual.size()), n);
    ASSERT_EQ(static_cast<size_t>(f.error.size()), n);
    EXPECT_EQ(static_cast<size_t>(f.desired_velocity.size()), n);
    EXPECT_EQ(static_cast<size_t>(f.actual_velocity.size()), n);
    EXPECT_LT((f.error - (f.desired - f.actual)).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_GT(f.time, last_time);
    last_time = f.time;
    max_error = std::max(max_error, std::abs(f.error[x]));
  }
  // the desired path goes from the start to the goal; the robot follows closely
  EXPECT_NEAR(feedback.front().desired[x], 0.0, 0.02);
  EXPECT_GT(feedback.back().desired[x], 0.15);
  EXPECT_GT(feedback.back().actual[x], 0.1);
  EXPECT_LT(max_error, 0.05);
}

// ---- effort control ----

TEST(ServedRobotTest, ZeroEffortHoldsUnderGravityCompensation) {
  World w({});
  const size_t n = w.served->GetJointNames().size();
  const VectorXd q0 = w.Qpos();
  w.served->CommandEfforts(std::vector<double>(n, 0.0), "effort");
  w.Advance(0.5);
  const VectorXd q1 = w.Qpos();
  for (const char* j : {"x", "y", "z"})
    EXPECT_NEAR(q1[w.Index(j)], q0[w.Index(j)], 0.02) << j;  // does not fall
  EXPECT_EQ(w.served->GetCommandStats().commands, 1);
}

TEST(ServedRobotTest, EffortMovesTheJointInTheEffortsDirection) {
  World w({});
  const size_t n = w.served->GetJointNames().size();
  const VectorXd q0 = w.Qpos();
  w.served->CommandEfforts(std::vector<double>(n, 0.0), "effort");
  w.Advance(0.2);
  const VectorXd q1 = w.Qpos();
  std::vector<double> e(n, 0.0);
  e[w.Index("x")] = 10.0;  // N
  e[w.Index("y")] = -10.0;
  w.served->CommandEfforts(e, "effort");
  w.Advance(0.3);
  const VectorXd q2 = w.Qpos(), qd2 = w.Qvel();
  EXPECT_GT(q2[w.Index("x")] - q1[w.Index("x")], 0.05);
  EXPECT_LT(q2[w.Index("y")] - q1[w.Index("y")], -0.05);
  EXPECT_GT(qd2[w.Index("x")], 0.1);
  EXPECT_LT(qd2[w.Index("y")], -0.1);
  EXPECT_NEAR(q2[w.Index("z")], q0[w.Index("z")], 0.05);
  // a position command takes the robot back
  w.served->CommandPositions(std::vector<double>(q0.data(), q0.data() + q0.size()), "positions");
  w.Advance(1.5);
  EXPECT_NEAR(w.Qpos()[w.Index("x")], q0[w.Index("x")], 1e-2);
}

// ---- planning ----

/// What a Plan call produced.
struct PlanRecorder {
  std::mutex mutex;
  bool got = false;
  PlanResult result;
  long long clock = -1;  ///< clock steps when the result came
  ServedRobot::PlanCallback Callback(SimServer* sim) {
    return [this, sim](const PlanResult& r) {
      std::lock_guard<std::mutex> lock(mutex);
      got = true;
      result = r;
      clock = sim->GetClockSteps();
    };
  }
  bool Got() {
    std::lock_guard<std::mutex> lock(mutex);
    return got;
  }
};

TEST(ServedRobotTest, PlanToAJointGoalRunsWhileTheServerStepsAndExecutes) {
  World w({/*panda=*/true, /*camera=*/false, /*paused=*/false});
  ASSERT_TRUE(WaitFor([&] { return w.sim->GetClockSteps() > 50; }));
  const VectorXd start = w.Qpos();
  VectorXd goal = start;
  goal[w.Index("panda_joint1")] += 0.6;
  goal[w.Index("panda_joint4")] += 0.3;
  PlanRequest req;
  req.joint_goal.assign(goal.data(), goal.data() + goal.size());
  req.options.time_limit = 2.0;
  PlanRecorder plan;
  DoneRecorder done;
  const long long clock_asked = w.sim->GetClockSteps();
  w.served->Plan(req, plan.Callback(w.sim.get()), done.Callback());
  ASSERT_TRUE(WaitFor([&] { return plan.Got(); }));
  {
    std::lock_guard<std::mutex> lock(plan.mutex);
    const PlanResult& r = plan.result;
    ASSERT_TRUE(r.success) << r.message;
    EXPECT_GT(plan.clock, clock_asked);  // the simulation kept stepping while planning
    ASSERT_GE(r.trajectory.positions.size(), 2u);
    ASSERT_EQ(r.trajectory.positions.front().size(), goal.size());
    EXPECT_LT((r.trajectory.positions.front() - start).cwiseAbs().maxCoeff(), 1e-2);
    EXPECT_LT((r.trajectory.positions.back() - goal).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_GT(r.trajectory.Duration(), 0.0);
  }
  ASSERT_TRUE(WaitFor([&] { return done.Done(); }));
  EXPECT_EQ(done.Outcome(), TrajectoryOutcome::kSucceeded) << done.Message();
  EXPECT_LT((w.Qpos() - goal).cwiseAbs().maxCoeff(), 1e-2);
}

TEST(ServedRobotTest, PlanWithoutExecuteLeavesTheRobotWhereItIs) {
  World w({/*panda=*/true, /*camera=*/false, /*paused=*/false});
  const VectorXd start = w.Qpos();
  VectorXd goal = start;
  goal[w.Index("panda_joint2")] += 0.4;
  PlanRequest req;
  req.joint_goal.assign(goal.data(), goal.data() + goal.size());
  req.execute = false;
  PlanRecorder plan;
  DoneRecorder done;
  w.served->Plan(req, plan.Callback(w.sim.get()), done.Callback());
  ASSERT_TRUE(WaitFor([&] { return plan.Got(); }));
  {
    std::lock_guard<std::mutex> lock(plan.mutex);
    EXPECT_TRUE(plan.result.success) << plan.result.message;
  }
  const long long clock = w.sim->GetClockSteps();
  ASSERT_TRUE(WaitFor([&] { return w.sim->GetClockSteps() > clock + 500; }));
  EXPECT_FALSE(done.Done());
  EXPECT_LT((w.Qpos() - start).cwiseAbs().maxCoeff(), 1e-2);
}

TEST(ServedRobotTest, MalformedPlanRequestsThrowAndAnUnreachablePoseFails) {
  World w({/*panda=*/true, /*camera=*/false, /*paused=*/false});
  const size_t n = w.served->GetJointNames().size();
  PlanRecorder never;
  auto plan = [&](const PlanRequest& r) { w.served->Plan(r, never.Callback(w.sim.get())); };
  PlanRequest req;
  req.joint_goal.assign(n - 2, 0.0);
  ExpectError([&] { plan(req); }, "joint_goal: " + std::to_string(n - 2) + " values");
  req.joint_goal.assign(n, 0.0);
  req.joint_goal[0] = std::nan("");
  ExpectError([&] { plan(req); }, "not finite");
  req.joint_goal.clear();
  req.pose_goal = Pose(Vector3d(0.4, 0, 0.4), Eigen::Quaterniond(2, 0, 0, 0));
  ExpectError([&] { plan(req); }, "unit quaternion");
  req.pose_goal = Pose(Vector3d(0.4, 0, std::nan("")), Eigen::Quaterniond::Identity());
  ExpectError([&] { plan(req); }, "pose_goal");
  req.pose_goal = Pose(Vector3d(0.4, 0, 0.4), Eigen::Quaterniond::Identity());
  req.options.time_limit = 0;
  ExpectError([&] { plan(req); }, "time_limit");
  req.options.time_limit = 1.0;
  req.options.algorithm = "Nope";
  ExpectError([&] { plan(req); }, "algorithm");
  // one worker plans for every client: no request may hold it for long
  req.options.algorithm = "RRTConnect";
  for (double t : {1e6, 1e308}) {
    req.options.time_limit = t;
    ExpectError([&] { plan(req); }, "time_limit must be at most 30 s");
  }

  // a pose far out of reach: an answer with success = false and a reason, nothing executed
  const VectorXd start = w.Qpos();
  req.options = PlannerOptions();
  req.options.time_limit = 1.0;
  req.pose_goal = Pose(Vector3d(3.0, 0, 0.5), Eigen::Quaterniond::Identity());
  PlanRecorder result;
  DoneRecorder done;
  w.served->Plan(req, result.Callback(w.sim.get()), done.Callback());
  ASSERT_TRUE(WaitFor([&] { return result.Got(); }));
  {
    std::lock_guard<std::mutex> lock(result.mutex);
    EXPECT_FALSE(result.result.success);
    EXPECT_FALSE(result.result.message.empty());
  }
  EXPECT_FALSE(never.Got());
  const long long clock = w.sim->GetClockSteps();
  ASSERT_TRUE(WaitFor([&] { return w.sim->GetClockSteps() > clock + 200; }));
  EXPECT_FALSE(done.Done());
  EXPECT_LT((w.Qpos() - start).cwiseAbs().maxCoeff(), 1e-2);
}

// Close (a server shutting down on SIGTERM) cancels a plan under way instead of waiting out its
// time limit: RRT* would use all of its 25 s.
TEST(ServedRobotTest, CloseCancelsAPlanUnderWay) {
  World w({/*panda=*/true, /*camera=*/false, /*paused=*/false});
  PlanRequest req;
  const VectorXd q = w.Qpos();
  req.joint_goal = std::vector<double>(q.data(), q.data() + q.size());
  req.joint_goal[w.Index("panda_joint1")] += 0.5;
  req.options.algorithm = "RRTstar";
  req.options.time_limit = 25.0;
  PlanRecorder result;
  const long long commands = w.sim->GetCommandsRun();
  w.served->Plan(req, result.Callback(w.sim.get()));
  // planning once the worker's snapshot command has run on the simulation thread
  ASSERT_TRUE(WaitFor([&] { return w.sim->GetCommandsRun() > commands; }))
      << "the plan's snapshot never ran";
  const auto t0 = std::chrono::steady_clock::now();
  w.served->Close();
  const double closing =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(closing, 5.0);
  ASSERT_TRUE(result.Got());
  std::lock_guard<std::mutex> lock(result.mutex);
  EXPECT_FALSE(result.result.success);
  EXPECT_EQ(result.result.message, "cancelled");
}

/// A plan request for the Panda that RRT* works on for its whole `seconds`, owned by `owner`.
PlanRequest LongPlan(World& w, const void* owner, double seconds = 25.0) {
  PlanRequest req;
  const VectorXd q = w.Qpos();
  req.joint_goal = std::vector<double>(q.data(), q.data() + q.size());
  req.joint_goal[w.Index("panda_joint1")] += 0.5;
  req.options.algorithm = "RRTstar";
  req.options.time_limit = seconds;
  req.execute = false;
  req.owner = owner;
  return req;
}

// Four 30 s plans of one client and a disconnect once held another client's 1 s plan for two
// minutes: plans are bounded per owner and in all, and refused beyond with the bound named.
TEST(ServedRobotTest, PlansAreBoundedPerOwnerAndInAll) {
  World w({/*panda=*/true, /*camera=*/false, /*paused=*/false});
  int owners[5];
  std::vector<std::unique_ptr<PlanRecorder>> results;
  auto plan = [&](const void* owner) {
    results.push_back(std::make_unique<PlanRecorder>());
    w.served->Plan(LongPlan(w, owner), results.back()->Callback(w.sim.get()));
  };
  plan(&owners[0]);
  plan(&owners[0]);
  ExpectError([&] { plan(&owners[0]); }, "at most " + std::to_string(kMaxPlansPerOwner));
  for (int k = 1; k < 4; ++k)
    for (size_t n = 0; n < kMaxPlansPerOwner; ++n) plan(&owners[k]);
  ASSERT_EQ(kMaxPlans, 4 * kMaxPlansPerOwner);
  ExpectError([&] { plan(&owners[4]); }, "at most " + std::to_string(kMaxPlans) + " in all");
  ExpectError([&] { plan(nullptr); }, "at most " + std::to_string(kMaxPlans) + " in all");
  // cancelled, every plan answers "cancelled" at once, and a place is free again
  for (int k = 0; k < 4; ++k) w.served->CancelPlans(&owners[k]);
  size_t answered = 0;
  ASSERT_TRUE(WaitFor([&] {
    answered = 0;
    for (auto& r : results) answered += r->Got();
    return answered == 4 * kMaxPlansPerOwner;
  })) << answered;
  for (auto& r : results) {
    if (!r->Got()) continue;  // refused: never answers
    std::lock_guard<std::mutex> lock(r->mutex);
    EXPECT_FALSE(r->result.success);
    EXPECT_EQ(r->result.message, "cancelled");
  }
  PlanRecorder later;
  PlanRequest quick = LongPlan(w, &owners[4], 2.0);
  quick.options.algorithm = "RRTConnect";
  w.served->Plan(quick, later.Callback(w.sim.get()));
  ASSERT_TRUE(WaitFor([&] { return later.Got(); }));
  std::lock_guard<std::mutex> lock(later.mutex);
  EXPECT_TRUE(later.result.success) << later.result.message;
}

// A client's plans are cancelled when it leaves: the one running stops (its own cancel flag, not
// the server's), the one waiting is dropped, both answer "cancelled", none executes, and another
// owner's plan waiting behind them runs at once instead of after 50 s.
TEST(ServedRobotTest, CancelPlansStopsAnOwnersPlansAndTheNextOwnerPlansAtOnce) {
  World w({/*panda=*/true, /*camera=*/false, /*paused=*/false});
  int gone = 0, other = 0, nobody = 0;
  PlanRecorder running, waiting, next;
  DoneRecorder running_done;
  PlanRequest long_req = LongPlan(w, &gone);
  long_req.execute = true;
  const long long commands = w.sim->GetCommandsRun();
  w.served->Plan(long_req, running.Callback(w.sim.get()), running_done.Callback());
  w.served->Plan(LongPlan(w, &gone), waiting.Callback(w.sim.get()));
  PlanRequest quick = LongPlan(w, &other, 2.0);
  quick.options.algorithm = "RRTConnect";
  w.served->Plan(quick, next.Callback(w.sim.get()));
  // the first is under way once its snapshot command has run on the simulation thread
  ASSERT_TRUE(WaitFor([&] { return w.sim->GetCommandsRun() > commands; }))
      << "the first plan's snapshot never ran";
  w.served->CancelPlans(&nobody);  // an owner with no plans: nothing happens
  EXPECT_FALSE(running.Got());
  w.served->CancelPlans(&gone);
  for (PlanRecorder* r : {&running, &waiting}) {
    ASSERT_TRUE(WaitFor([&] { return r->Got(); }));
    std::lock_guard<std::mutex> lock(r->mutex);
    EXPECT_FALSE(r->result.success);
    EXPECT_EQ(r->result.message, "cancelled");
  }
  // WaitFor's 30 s: the two RRT* plans would take 50 s
  ASSERT_TRUE(WaitFor([&] { return next.Got(); }));
  {
    std::lock_guard<std::mutex> lock(next.mutex);
    EXPECT_TRUE(next.result.success) << next.result.message;
  }
  EXPECT_FALSE(running_done.Done());  // nothing executed
}

// ---- readings ----

TEST(ServedRobotTest, FramesHoldEveryLinkAndTheCameraOpticalFrame) {
  World w({/*panda=*/false, /*camera=*/true});
  ASSERT_EQ(w.served->GetCameras().size(), 1u);
  EXPECT_EQ(w.served->GetCameras()[0].frame, "cam_optical_frame");
  const std::vector<FrameReading> frames = OnSim(*w.sim, [&] { return w.served->ReadFrames(); });
  std::set<std::string> children;
  for (const FrameReading& f : frames) children.insert(f.child);
  EXPECT_EQ(children.size(), frames.size());  // no frame twice
  for (const Link& l : w.robot.GetLinks()) EXPECT_TRUE(children.count(l.GetName())) << l.GetName();
  EXPECT_TRUE(children.count("cam_optical_frame"));
  // link poses are the links' own
  for (const FrameReading& f : frames) {
    if (f.child == "cam_optical_frame") continue;
    const Pose X = OnSim(*w.sim, [&] { return w.robot.FindLinkByName(f.child).GetPose(); });
    EXPECT_LT((X.p - f.pose.p).norm(), 1e-9) << f.child;
    EXPECT_GT(std::abs(X.q.dot(f.pose.q)), 1 - 1e-9) << f.child;
  }
}

TEST(ServedRobotTest, CameraOpticalFrameLooksAlongTheViewWithYDown) {
  World w({/*panda=*/false, /*camera=*/true});
  const std::vector<FrameReading> frames = OnSim(*w.sim, [&] { return w.served->ReadFrames(); });
  auto it = std::find_if(frames.begin(), frames.end(),
                         [](const FrameReading& f) { return f.child == "cam_optical_frame"; });
  ASSERT_NE(it, frames.end());
  const Eigen::Matrix3d R = it->pose.q.toRotationMatrix();
  const Vector3d view = (w.target - w.eye).normalized();
  const Pose X_WC = CameraLookAt(w.eye, w.target);
  const Vector3d up = X_WC.q * Vector3d::UnitZ();  // the image's up
  EXPECT_LT((it->pose.p - w.eye).norm(), 1e-9);
  EXPECT_LT((R.col(2) - view).norm(), 1e-6) << "z: " << R.col(2).transpose();
  EXPECT_LT((R.col(1) + up).norm(), 1e-6) << "y: " << R.col(1).transpose();
  EXPECT_LT(R.col(1).z(), 0.0);  // down in the image is down in the world
  // the renderer's own world-to-optical rotation (OpenCV extrinsics) agrees
  const Eigen::Matrix3d R_OW = w.camera.GetExtrinsicMatrix().leftCols<3>();
  EXPECT_LT((R.transpose() - R_OW).norm(), 1e-6);
}

// ---- the sensor schedule ----

TEST(ServedRobotTest, SensorScheduleKeepsItsRatesInSimulatedTimeAndServesOnlyListeners) {
  World w({/*panda=*/false, /*camera=*/true});
  ASSERT_EQ(w.served->GetOptions().camera_rate, 10.0);  // pictures every 0.1 s
  ASSERT_EQ(w.served->GetOptions().imu_rate, 0.0);      // the IMU every step
  SensorSchedule schedule(w.served.get());
  int imu = 0, images = 0, points = 0, infos = 0;
  std::vector<double> picture_times;
  double now = 0;
  SensorSchedule::Output out;
  out.imu = [&](const ImuReading&) { ++imu; };
  out.picture = [&](size_t i, const Camera& cam, bool image, bool pts) {
    EXPECT_EQ(i, 0u);
    EXPECT_EQ(cam.GetWidth(), 32);
    images += image;
    points += pts;
    picture_times.push_back(now);
  };
  out.camera_info = [&](size_t, const Camera&) { ++infos; };
  // `t` in steps of 2 ms from `from` to `to` (inclusive), the listeners given by `listened`
  auto run = [&](int from, int to, const SensorSchedule::Listened& listened) {
    OnSim(*w.sim, [&] {
      for (int k = from; k <= to; ++k) {
        now = k * 0.002;
        schedule.Publish(now, listened, out);
      }
      return 0;
    });
  };

  // nobody listens: nothing is read, and the clock of each stream stands still
  run(0, 100, [](SensorStream, size_t) { return false; });
  EXPECT_EQ(imu + images + points + infos, 0);

  // everything listened from t = 0.202 s to 0.7 s: the IMU every step, a picture (image and
  // points at once) and camera_info at once, then every 0.1 s
  run(101, 350, [](SensorStream, size_t) { return true; });
  EXPECT_EQ(imu, 250);
  EXPECT_EQ(images, 5);
  EXPECT_EQ(points, 5);
  EXPECT_EQ(infos, 5);
  ASSERT_EQ(picture_times.size(), 5u);
  for (size_t k = 0; k < picture_times.size(); ++k)
    EXPECT_NEAR(picture_times[k], 0.202 + 0.1 * k, 1e-9);

  // only the image listened: pictures without points, at the same rate, no IMU or camera_info
  imu = images = points = infos = 0;
  run(351, 400, [](SensorStream s, size_t) { return s == SensorStream::kImage; });
  EXPECT_EQ(images, 1);  // at 0.702 s; the next falls due at 0.802 s
  EXPECT_EQ(points, 0);
  EXPECT_EQ(imu + infos, 0);
}

TEST(ServedRobotTest, SensorTopicsAreNamedAfterTheCamera) {
  World w({/*panda=*/false, /*camera=*/true});
  const ServedRobot& r = *w.served;
  EXPECT_EQ(SensorTopic(r, SensorStream::kImu), "/imu");
  EXPECT_EQ(SensorTopic(r, SensorStream::kImage, 0), "/cam/image_raw");
  EXPECT_EQ(SensorTopic(r, SensorStream::kPoints, 0), "/cam/points");
  EXPECT_EQ(SensorTopic(r, SensorStream::kCameraInfo, 0), "/cam/camera_info");
  EXPECT_THROW(SensorTopic(r, SensorStream::kImage, 1), std::out_of_range);
}

}  // namespace
}  // namespace partsim
