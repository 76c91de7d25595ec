// Where the page's joint commands (/partsim/set_joint_target) go: to Viewer::SetJointCommand for
// the articulations it serves (partsim serve --viewer: the served robot's controllers), else to
// a JointPositionController of the joint with the robot layer's default gains; a command the
// route refuses fails naming why. Synchronous mode, on a two-joint URDF cabinet.
#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"
#include "partsim/robot/controllers.h"
#include "partsim/viewer/viewer.h"
#include "server/ws_test_client.h"

namespace partsim {
namespace {

using json = nlohmann::json;

constexpr char kCabinet[] = R"(<robot name="cabinet">
  <link name="body"><inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.5 0.6 0.8"/></geometry></collision></link>
  <link name="drawer"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.3 0 0.2"/><geometry><box size="0.1 0.5 0.2"/></geometry></collision></link>
  <link name="door"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.3 0.1 -0.2"/><geometry><box size="0.02 0.2 0.3"/></geometry></collision></link>
  <joint name="slide" type="prismatic"><parent link="body"/><child link="drawer"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="0.4" effort="100" velocity="1"/></joint>
  <joint name="hinge" type="revolute"><parent link="body"/><child link="door"/>
    <origin xyz="0.3 0 -0.2"/><axis xyz="0 0 1"/><limit lower="0" upper="1.5" effort="100" velocity="1"/></joint>
</robot>)";

/// A logged client that logs in and moves joints.
class Client : public testing::LoggedWsClient {
 public:
  using LoggedWsClient::LoggedWsClient;
  bool Login(const std::string& token) {
    if (!WaitOpen()) return false;
    Send(json{{"op", "auth"}, {"mac", token}});
    return !Wait([](const json& m) { return m.value("msg", "") == "authenticated"; }).is_null();
  }
  /// Calls set_joint_target and renders until the answer comes (30 s at most).
  json Move(Viewer& v, const std::string& joint, double position, const std::string& id) {
    Send(json{{"op", "call_service"},
              {"service", "/partsim/set_joint_target"},
              {"args", {{"articulation", 0}, {"joint", joint}, {"position", position}}},
              {"id", id}});
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < deadline) {
      v.Render();
      for (const json& m : Messages())
        if (m.value("id", "") == id && m.value("op", "") == "service_response") return m;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return json();
  }
};

class ViewerJointCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    UrdfLoader loader = CreateUrdfLoader(scene_);
    loader.fix_root_link = true;
    cabinet_ = scene_.AddArticulation(loader.Parse(kCabinet, ".", "cabinet"));
  }
  Joint JointNamed(const std::string& name) {
    for (const Joint& j : cabinet_.GetActiveJoints())
      if (j.GetName() == name) return j;
    ADD_FAILURE() << "no joint " << name;
    return {};
  }
  Scene scene_;
  Articulation cabinet_;
};

TEST_F(ViewerJointCommandTest, TheServedArticulationsJointsGoToTheRoute) {
  Viewer v(&scene_);
  struct Call {
    std::string joint;
    double position;
  };
  std::vector<Call> calls;
  v.SetJointCommand([&](const Articulation& a, const std::string& joint, double position) {
    if (!(a == cabinet_)) return false;
    if (position > 1.0) throw Error("the served robot refuses " + std::to_string(position));
    calls.push_back({joint, position});  // the scene's thread: Render() here
    return true;
  });
  v.Start();
  EXPECT_THROW(v.SetJointCommand({}), Error) << "before Start() only";
  Client c(v.GetPort());
  ASSERT_TRUE(c.Login(v.GetToken()));
  const double stiffness = JointNamed("slide").GetDriveStiffness();

  const json r = c.Move(v, "slide", 0.25, "a");
  ASSERT_FALSE(r.is_null());
  EXPECT_TRUE(r["result"].get<bool>()) << r;
  EXPECT_NE(r["values"]["message"].get<std::string>().find("served robot"), std::string::npos);
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_EQ(calls[0].joint, "slide");
  EXPECT_DOUBLE_EQ(calls[0].position, 0.25);
  EXPECT_EQ(JointNamed("slide").GetDriveStiffness(), stiffness) << "no controller of its own";

  // what the route throws is the call's failure
  const json refused = c.Move(v, "hinge", 1.2, "b");
  ASSERT_FALSE(refused.is_null());
  EXPECT_FALSE(refused["result"].get<bool>());
  EXPECT_NE(refused["values"].get<std::string>().find("refuses"), std::string::npos) << refused;
}

TEST_F(ViewerJointCommandTest, OtherJointsGetAPositionControllerWithTheRobotLayersGains) {
  Viewer v(&scene_);
  v.SetJointCommand([](const Articulation&, const std::string&, double) { return false; });
  v.Start();
  Client c(v.GetPort());
  ASSERT_TRUE(c.Login(v.GetToken()));
  const json r = c.Move(v, "slide", 0.3, "a");
  ASSERT_FALSE(r.is_null());
  EXPECT_TRUE(r["result"].get<bool>()) << r;
  const Joint slide = JointNamed("slide");
  const JointControllerOptions defaults;
  EXPECT_DOUBLE_EQ(slide.GetDriveStiffness(), defaults.stiffness);
  EXPECT_DOUBLE_EQ(slide.GetDriveDamping(), defaults.damping);
  EXPECT_DOUBLE_EQ(slide.GetDriveTarget(), 0.3);
  EXPECT_EQ(JointNamed("hinge").GetDriveStiffness(), 0) << "only the moved joint is controlled";
  for (int i = 0; i < 1500; ++i) {
    scene_.Step();
    v.Render();
  }
  EXPECT_NEAR(slide.GetQpos(), 0.3, 0.01);
  // past the limit: clamped, and the answer says so
  const json far = c.Move(v, "slide", 0.9, "b");
  ASSERT_FALSE(far.is_null());
  EXPECT_TRUE(far["result"].get<bool>());
  EXPECT_NE(far["values"]["message"].get<std::string>().find("clamped to 0.4"), std::string::npos)
      << far;
  EXPECT_DOUBLE_EQ(slide.GetDriveTarget(), 0.4);
}

}  // namespace
}  // namespace partsim
