// `partsim serve --ros1` against ROS 1 tools nobody here wrote, started the way users start
// them: Debian's rosmaster, `rostopic` (list, hz, echo, pub) and a rospy + actionlib client
// (tests/server/rospy_client.py) that measures the rates, drives trajectories through the
// command topic and the follow_joint_trajectory action, plans through /<robot>/plan and steps
// a paused simulation. Skipped when partsim is built without ROS 1.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#ifndef PARTSIM_CLI_PATH
#error "PARTSIM_CLI_PATH must name the partsim executable"
#endif
#include "server/process_util.h"

namespace partsim {
namespace {

using json = nlohmann::json;

#ifdef PARTSIM_ROS1_PYTHON_DIR
/// A ROS master on a free port, and `partsim serve --ros1` talking to it.
class Ros1ServeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const int port = FreePort();
    ASSERT_GT(port, 0);
    uri_ = "http://127.0.0.1:" + std::to_string(port);
    env_ = "ROS_MASTER_URI=" + uri_ + " ROS_HOSTNAME=127.0.0.1 PYTHONPATH='" +
           std::string(PARTSIM_ROS1_PYTHON_DIR) + "'";
    master_ = std::make_unique<ChildProcess>(
        "rosmaster --core -p " + std::to_string(port) + " >/dev/null 2>&1", false);
    serve_ = std::make_unique<ServeProcess>("--ros1 --port 0 --robot panda --duration 300",
                                            "ROS_MASTER_URI=" + uri_ + " ROS_HOSTNAME=127.0.0.1");
    ASSERT_GT(serve_->Port(), 0) << "partsim serve printed: " << serve_->FirstLine();
    ASSERT_NE(serve_->FirstLine().find("ROS 1 node"), std::string::npos) << serve_->FirstLine();
  }
  void TearDown() override {
    serve_.reset();
    master_.reset();
  }
  /// Runs a shell command with the master's environment.
  std::string Run(const std::string& cmd, int* code) {
    return RunShell("env " + env_ + " " + cmd + " 2>&1", code);
  }
  /// The positions of the panda's arm joints from one /joint_states message.
  std::vector<double> ArmPositions() {
    int code = 0;
    std::string out = Run("timeout 20 rostopic echo -n 1 /joint_states/position", &code);
    std::vector<double> q;
    size_t open = out.find('['), close = out.find(']');
    if (open == std::string::npos || close == std::string::npos) return q;
    std::stringstream ss(out.substr(open + 1, close - open - 1));
    std::string item;
    while (std::getline(ss, item, ',')) q.push_back(std::stod(item));
    return q;
  }

  std::string uri_, env_;
  std::unique_ptr<ChildProcess> master_;
  std::unique_ptr<ServeProcess> serve_;
};

TEST_F(Ros1ServeTest, RostopicListsEchoesMeasuresAndPublishes) {
  int code = 0;
  std::string out = Run("rostopic list", &code);
  ASSERT_EQ(code, 0) << out;
  for (const char* t :
       {"/clock", "/joint_states", "/tf", "/imu", "/front_camera/image_raw",
        "/front_camera/camera_info", "/front_camera/points",
        "/panda/joint_position_controller/command", "/panda/joint_trajectory_controller/command",
        "/panda/joint_trajectory_controller/follow_joint_trajectory/goal"})
    EXPECT_NE(out.find(std::string(t) + "\n"), std::string::npos) << t << " missing:\n" << out;
  out = Run("rostopic type /joint_states", &code);
  EXPECT_NE(out.find("sensor_msgs/JointState"), std::string::npos) << out;

  // rostopic hz over ~200 messages (rostopic follows /use_sim_time: simulated seconds)
  out = Run("timeout 8 rostopic hz -w 200 /joint_states", &code);
  size_t at = out.rfind("average rate: ");
  ASSERT_NE(at, std::string::npos) << out;
  const double hz = std::stod(out.substr(at + 14));
  std::printf("rostopic hz /joint_states: %.1f Hz\n", hz);
  EXPECT_GT(hz, 400.0) << out;  // one message per 500 Hz step
  EXPECT_LT(hz, 520.0) << out;

  out = Run("timeout 20 rostopic echo -n 1 /clock", &code);
  EXPECT_NE(out.find("secs:"), std::string::npos) << out;
  out = Run("timeout 20 rostopic echo -n 1 /front_camera/camera_info/K", &code);
  // cx, cy of the 640x480 camera (pixel centres at integers)
  EXPECT_NE(out.find("319.5"), std::string::npos) << out;
  EXPECT_NE(out.find("239.5"), std::string::npos) << out;
  out = Run("timeout 20 rostopic echo -n 1 /tf", &code);
  EXPECT_NE(out.find("front_camera_optical_frame"), std::string::npos);
  EXPECT_NE(out.find("panda_hand"), std::string::npos);

  // a position command from rostopic pub moves the arm there
  std::vector<double> q = ArmPositions();
  ASSERT_GE(q.size(), 9u) << "joint states of the scene";
  std::vector<double> target(q.end() - 9, q.end());  // the panda comes after the cabinet
  target[0] += 0.2;
  target[1] += 0.1;
  std::string data;
  for (double v : target) data += (data.empty() ? "" : ", ") + std::to_string(v);
  out =
      Run("rostopic pub -1 /panda/joint_position_controller/command "
          "std_msgs/Float64MultiArray \"{data: [" +
              data + "]}\"",
          &code);
  ASSERT_EQ(code, 0) << out;
  double err = 1;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (err > 0.01 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    std::vector<double> now = ArmPositions();
    if (now.size() != q.size()) continue;
    err =
        std::max(std::abs(now[q.size() - 9] - target[0]), std::abs(now[q.size() - 8] - target[1]));
  }
  EXPECT_LT(err, 0.01);

  // a command of the wrong size is refused (logged) and the node keeps serving
  out =
      Run("rostopic pub -1 /panda/joint_position_controller/command "
          "std_msgs/Float64MultiArray \"{data: [1.0, 2.0]}\"",
          &code);
  EXPECT_EQ(code, 0) << out;
  out = Run("timeout 20 rostopic echo -n 1 /clock", &code);
  EXPECT_NE(out.find("secs:"), std::string::npos) << out;
  std::vector<double> after = ArmPositions();
  ASSERT_EQ(after.size(), q.size());
  EXPECT_NEAR(after[q.size() - 9], target[0], 0.02);  // still where it was sent, not moved
}

TEST_F(Ros1ServeTest, RospyAndActionlibClientDrivesTheRobot) {
  int code = 0;
  std::string out = Run("/usr/bin/python3 '" + std::string(PARTSIM_SOURCE_DIR) +
                            "/tests/server/rospy_client.py' panda",
                        &code);
  std::string last = out.substr(0, out.find_last_not_of('\n') + 1);
  last = last.substr(last.rfind('\n') == std::string::npos ? 0 : last.rfind('\n') + 1);
  json r = json::parse(last, nullptr, false);
  ASSERT_FALSE(r.is_discarded()) << out;
  EXPECT_EQ(code, 0) << out;
  ASSERT_FALSE(r.contains("error")) << out;
  std::printf(
      "rospy client: /clock %.1f Hz, /joint_states %.1f Hz, %.2f sim s per wall s; action %s "
      "with %d feedback messages, final error %.2g; plan %.3f s, final error %.2g\n",
      r["clock_hz"].get<double>(), r["joint_states_hz"].get<double>(),
      r["sim_seconds_per_wall_second"].get<double>(), r["action_state"].dump().c_str(),
      r["action_feedback_messages"].get<int>(), r["action_final_error"].get<double>(),
      r["plan_time"].get<double>(), r["plan_final_error"].get<double>());
  // messages per simulated second (one per 2 ms step), not per wall-clock second: a loaded
  // machine steps more slowly but publishes as much for each step
  EXPECT_GT(r["joint_states_per_sim_second"].get<double>(), 50.0);
  EXPECT_LE(r["joint_states_per_sim_second"].get<double>(), 520.0);
  EXPECT_GT(r["clock_per_sim_second"].get<double>(), 50.0);
  EXPECT_LT(r["action_final_error"].get<double>(), 0.02);
  EXPECT_TRUE(r["plan_success"].get<bool>());
  EXPECT_NEAR(r["stepped_seconds"].get<double>(), 0.05, 1e-6);
}

// A follow_joint_trajectory goal of more points than the rosbridge server accepts
// (kMaxTrajectoryPoints, 10,000) was converted and executed; it is now rejected
// before any point is converted, with a message that names the bound.
TEST_F(Ros1ServeTest, TrajectoryOfTooManyPointsIsRejected) {
  const std::string script =
      ::testing::TempDir() + "partsim_ros1_many_points_" + std::to_string(::getpid()) + ".py";
  std::FILE* f = std::fopen(script.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(R"(import json, sys
import actionlib, rospy
from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryGoal
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectoryPoint
rospy.init_node("partsim_many_points", anonymous=True, disable_signals=True)
arm = ["panda_joint%d" % i for i in range(1, 8)]
js = rospy.wait_for_message("/joint_states", JointState, timeout=30)
q = [js.position[list(js.name).index(n)] for n in arm]
client = actionlib.SimpleActionClient(
    "/panda/joint_trajectory_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
assert client.wait_for_server(rospy.Duration(30.0))
g = FollowJointTrajectoryGoal()
g.trajectory.joint_names = arm
g.trajectory.points = [JointTrajectoryPoint(positions=q, time_from_start=rospy.Duration(0.01 * (k + 1)))
                       for k in range(10001)]
client.send_goal(g)
finished = client.wait_for_result(rospy.Duration(30.0))
r = client.get_result()
print(json.dumps({"finished": finished, "state": client.get_state(),
                  "error_code": r.error_code if r else None,
                  "error_string": r.error_string if r else ""}))
)",
             f);
  std::fclose(f);
  int code = 0;
  const std::string out = Run("timeout 120 /usr/bin/python3 '" + script + "'", &code);
  std::remove(script.c_str());
  std::string last = out.substr(0, out.find_last_not_of('\n') + 1);
  last = last.substr(last.rfind('\n') == std::string::npos ? 0 : last.rfind('\n') + 1);
  const json r = json::parse(last, nullptr, false);
  ASSERT_FALSE(r.is_discarded()) << out;
  EXPECT_TRUE(r["finished"].get<bool>()) << out;
  EXPECT_EQ(r["state"].get<int>(), 5) << out;        // actionlib_msgs/GoalStatus REJECTED
  EXPECT_EQ(r["error_code"].get<int>(), -1) << out;  // FollowJointTrajectoryResult INVALID_GOAL
  EXPECT_NE(r["error_string"].get<std::string>().find("10001 points, more than the 10000"),
            std::string::npos)
      << out;
}

TEST(Ros1ServeNoMasterTest, ServeFailsClearly) {
  int code = 0;
  std::string out = RunShell("env ROS_MASTER_URI=http://127.0.0.1:" + std::to_string(FreePort()) +
                                 " '" + PARTSIM_CLI_PATH + "' serve --ros1 --port 0 2>&1",
                             &code);
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("no master at"), std::string::npos) << out;
}
#else
TEST(Ros1ServeTest, BuiltWithoutRos1RefusesTheFlag) {
  int code = 0;
  std::string out =
      RunShell(std::string("'") + PARTSIM_CLI_PATH + "' serve --ros1 --port 0 2>&1", &code);
  EXPECT_EQ(code, 2) << out;
  EXPECT_NE(out.find("built without ROS 1"), std::string::npos) << out;
  GTEST_SKIP() << "partsim was built without ROS 1: the ROS 1 client tests did not run";
}
#endif

}  // namespace
}  // namespace partsim
