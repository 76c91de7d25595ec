// RosbridgeServer under faults: malformed JSON, unknown ops, wrong types, a huge message, a
// client that vanishes mid-frame, 50 clients at once, and a client that never reads. Clients are
// websocketpp's own client and raw TCP sockets.
#include "partsim/server/rosbridge.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <future>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/scene_render.h"
#include "partsim/robot/robots.h"
#include "server/wait_for.h"
#include "server/ws_test_client.h"

namespace partsim {
namespace {

using json = nlohmann::json;
using namespace std::chrono_literals;
using WsClient = testing::WsTestClient::Client;
using testing::RawSocket;

using testing::WaitFor;

/// A WebSocket client on its own thread that keeps every message it receives.
class TestClient {
 public:
  /// `origin`: the Origin header a browser would send ("" sends none).
  explicit TestClient(int port, const std::string& origin = "")
      : ws_(port, origin, [this](const WsClient::message_ptr& m) { OnMessage(m); }) {}
  bool WaitOpen() { return ws_.WaitOpen(); }
  void Send(const std::string& text) { ws_.Send(text); }
  void Send(const json& j) { Send(j.dump()); }
  void SendBinary(const std::string& bytes) { ws_.Send(bytes, websocketpp::frame::opcode::binary); }
  std::vector<json> Messages() { return log_.All(); }
  /// Waits for a message satisfying `pred`; returns it (null if none came).
  template <class F>
  json WaitMessage(F pred) {
    return log_.Wait(pred);
  }
  /// Last /clock time seen (s), or -1.
  double LastClock() {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_clock_;
  }
  long long TfCount() {
    std::lock_guard<std::mutex> lock(mutex_);
    return tf_count_;
  }
  /// Only count the messages of `topic` (set before subscribing).
  void CountOnly(const std::string& topic) {
    std::lock_guard<std::mutex> lock(mutex_);
    count_topic_ = topic;
  }
  long long Counted() {
    std::lock_guard<std::mutex> lock(mutex_);
    return counted_;
  }
  /// Keep /joint_states messages (set before subscribing).
  void KeepJointStates() { keep_joint_states_ = true; }
  /// Keep /tf messages (set before subscribing).
  void KeepTf() { keep_tf_ = true; }
  bool Closed() const { return ws_.Closed(); }
  /// Closes the connection and waits until it is closed.
  void Close() { ws_.Close(); }
  int CloseCode() const { return ws_.CloseCode(); }

 private:
  // published messages are counted (the clock and the last joint state kept); the others are
  // kept whole
  void OnMessage(const WsClient::message_ptr& m) {
    const std::string& text = m->get_payload();
    if (m->get_opcode() == websocketpp::frame::opcode::binary) {  // CBOR
      json j = json::from_cbor(text, true, false);
      if (!j.is_discarded()) j["cbor"] = true;
      log_.Add(j);
      return;
    }
    const size_t at = text.rfind("\"topic\":\"");
    const std::string topic = at == std::string::npos ? "" : text.substr(at + 9);
    std::lock_guard<std::mutex> lock(mutex_);
    if (!count_topic_.empty() && topic.rfind(count_topic_ + "\"", 0) == 0) {
      ++counted_;
    } else if (topic.rfind("/tf\"", 0) == 0) {
      ++tf_count_;
      if (keep_tf_) log_.Add(json::parse(text, nullptr, false));
    } else if (topic.rfind("/clock\"", 0) == 0) {
      json j = json::parse(text, nullptr, false);
      last_clock_ =
          j["msg"]["clock"]["secs"].get<double>() + 1e-9 * j["msg"]["clock"]["nsecs"].get<double>();
    } else if (topic.rfind("/joint_states\"", 0) == 0) {
      if (keep_joint_states_) log_.Add(json::parse(text, nullptr, false));
    } else {
      log_.Add(json::parse(text, nullptr, false));
    }
  }

  std::mutex mutex_;  // the counters and settings below
  testing::MessageLog log_;
  double last_clock_ = -1;
  long long tf_count_ = 0;
  std::string count_topic_;
  long long counted_ = 0;
  std::atomic<bool> keep_joint_states_{false};
  std::atomic<bool> keep_tf_{false};
  testing::WsTestClient ws_;  // last: its thread stops before the members above go
};

bool IsError(const json& m) {
  return m.value("op", "") == "status" && m.value("level", "") == "error";
}

/// The services that /rosapi/services lists, asked on `c`'s connection: when the answer comes,
/// the server has handled everything `c` sent before (one connection's messages are handled in
/// order). Null if no answer came.
json Sync(TestClient& c) {
  static std::atomic<int> calls{0};
  const std::string id = "sync" + std::to_string(calls++);
  c.Send(json{{"op", "call_service"}, {"service", "/rosapi/services"}, {"id", id}});
  json r = c.WaitMessage([&](const json& m) { return m.value("id", "") == id; });
  return r.is_null() ? r : r["values"]["services"];
}

/// Whether /rosapi/services, asked on `c`'s connection, lists `service` within 30 s (another
/// client's advertise_service handled).
bool WaitAdvertised(TestClient& c, const std::string& service) {
  return WaitFor([&] {
    const json names = Sync(c);
    return names.is_array() && std::find(names.begin(), names.end(), service) != names.end();
  });
}

/// Whether `value()` stays the same for `still` (a flow that stopped) within 60 s.
template <class F>
bool WaitStill(F value, std::chrono::milliseconds still = 1000ms) {
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  auto last = value();
  auto since = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(20ms);
    const auto now_value = value();
    if (now_value != last) {
      last = now_value;
      since = std::chrono::steady_clock::now();
    } else if (std::chrono::steady_clock::now() - since >= still) {
      return true;
    }
  }
  return false;
}

/// A flying gripper stepped in real time at 500 Hz behind a rosbridge server on a free port.
class RosbridgeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = std::make_unique<Scene>();
    scene_->AddGround(0);
    RobotModel m = BuildFlyingGripper();
    m.articulation.root_pose = Pose(Eigen::Vector3d(0, 0, 0.5));
    robot_ = scene_->AddArticulation(m.articulation);
    loop_ = std::make_unique<ControlLoop>(scene_.get());
    sim_ = std::make_unique<SimServer>(scene_.get(), loop_.get());
    served_ = std::make_unique<ServedRobot>(sim_.get(), scene_.get(), loop_.get(), robot_,
                                            robot_.GetName());
    RosbridgeOptions o = Options();
    o.port = 0;
    bridge_ = std::make_unique<RosbridgeServer>(served_.get(), o);
    bridge_->Start();
    sim_->Start();
    port_ = bridge_->GetPort();
  }
  void TearDown() override {
    sim_->Stop();
    bridge_->Stop();
  }
  /// The server's options (a fixture may set origins, a token, caps).
  virtual RosbridgeOptions Options() const { return RosbridgeOptions(); }
  /// A client subscribed to /clock, once the clock is flowing to it.
  std::unique_ptr<TestClient> ClockWatcher() {
    auto c = std::make_unique<TestClient>(port_);
    EXPECT_TRUE(c->WaitOpen());
    c->Send(json{{"op", "subscribe"}, {"topic", "/clock"}});
    EXPECT_TRUE(WaitFor([&] { return c->LastClock() >= 0; }));
    return c;
  }
  /// Whether `c` sees the clock advance by at least `seconds` of simulated time.
  static bool ClockAdvances(TestClient& c, double seconds) {
    double t0 = c.LastClock();
    return WaitFor([&] { return c.LastClock() > t0 + seconds; });
  }
  std::unique_ptr<Scene> scene_;
  Articulation robot_;
  std::unique_ptr<ControlLoop> loop_;
  std::unique_ptr<SimServer> sim_;
  std::unique_ptr<ServedRobot> served_;
  std::unique_ptr<RosbridgeServer> bridge_;
  int port_ = 0;
};

TEST_F(RosbridgeTest, MalformedJsonUnknownOpAndWrongTypesGetErrorsAndServerKeepsRunning) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  const std::string cmd = "/" + robot_.GetName() + "/joint_position_controller/command";
  c.Send(std::string("{\"op\": \"subscribe\", \"topic\": "));  // cut short
  c.Send(json{{"op", "fly"}, {"id", "u1"}});
  c.Send(json::array({1, 2}));
  c.Send(json{{"op", "advertise"}, {"topic", cmd}, {"type", "std_msgs/String"}, {"id", "w1"}});
  c.Send(json{{"op", "publish"}, {"topic", cmd}, {"msg", {{"data", "abc"}}}, {"id", "w2"}});
  c.Send(json{{"op", "publish"}, {"topic", cmd}, {"msg", {{"data", {1, 2}}}}, {"id", "w3"}});
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}, {"type", "std_msgs/Int8"}, {"id", "w4"}});
  c.Send(json{{"op", "call_service"}, {"service", "/nope"}, {"id", "w5"}});
  c.Send(json{{"op", "publish"}, {"topic", "/clock"}, {"msg", json::object()}, {"id", "w6"}});
  json malformed = c.WaitMessage([](const json& m) {
    return IsError(m) && m["msg"].get<std::string>().find("malformed JSON") != std::string::npos;
  });
  EXPECT_FALSE(malformed.is_null());
  for (std::string id : {"u1", "w1", "w2", "w3", "w4", "w5", "w6"}) {
    json e = c.WaitMessage([&](const json& m) { return IsError(m) && m.value("id", "") == id; });
    EXPECT_FALSE(e.is_null()) << id;
  }
  json unknown = c.WaitMessage([](const json& m) { return m.value("id", "") == "u1"; });
  EXPECT_NE(unknown["msg"].get<std::string>().find("unknown op 'fly'"), std::string::npos);
  // still serving the same client
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}});
  EXPECT_TRUE(ClockAdvances(c, 0.05));
  EXPECT_FALSE(c.Closed());
}

TEST_F(RosbridgeTest, NonUtf8AndDeeplyNestedMessagesGetErrorsAndServerKeepsRunning) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  // JSON-breaking non-ASCII text: the error quotes part of a UTF-8 sequence
  c.Send(std::string("[1,2,\xC3\xA9]"));
  c.Send(std::string("\xC3\xA9"));
  // a binary frame that is not UTF-8
  c.SendBinary(std::string("\xFF\xFE{", 3));
  // nesting 100,000 deep, alone and in a message's id
  const std::string open(100000, '['), close(100000, ']');
  c.Send(open + close);
  c.Send("{\"op\": \"subscribe\", \"topic\": \"/clock\", \"id\": " + open + "1" + close + "}");
  json deep = c.WaitMessage([](const json& m) {
    return IsError(m) &&
           m["msg"].get<std::string>().find("nested deeper than") != std::string::npos;
  });
  EXPECT_FALSE(deep.is_null());
  int malformed = 0;
  for (const json& m : c.Messages())
    malformed +=
        IsError(m) && m["msg"].get<std::string>().find("malformed JSON") != std::string::npos;
  EXPECT_GE(malformed, 3);
  // still serving the same client
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}});
  EXPECT_TRUE(ClockAdvances(c, 0.05));
  EXPECT_FALSE(c.Closed());
}

TEST_F(RosbridgeTest, RosapiAndServicesAnswer) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "call_service"}, {"service", "/rosapi/topics"}, {"id", "t"}});
  c.Send(json{{"op", "call_service"},
              {"service", "rosapi/topic_type"},
              {"args", {{"topic", "/tf"}}},
              {"id", "tt"}});
  json t = c.WaitMessage([](const json& m) { return m.value("id", "") == "t"; });
  ASSERT_FALSE(t.is_null());
  EXPECT_EQ(t["op"], "service_response");
  EXPECT_TRUE(t["result"].get<bool>());
  auto topics = t["values"]["topics"].get<std::vector<std::string>>();
  EXPECT_NE(std::find(topics.begin(), topics.end(), "/joint_states"), topics.end());
  json tt = c.WaitMessage([](const json& m) { return m.value("id", "") == "tt"; });
  ASSERT_FALSE(tt.is_null());
  EXPECT_EQ(tt["values"]["type"], "tf2_msgs/TFMessage");

  // a service offered by another client, answered through service_response
  TestClient provider(port_);
  ASSERT_TRUE(provider.WaitOpen());
  provider.Send(json{{"op", "advertise_service"}, {"service", "/add"}, {"type", "x/Add"}});
  ASSERT_TRUE(WaitAdvertised(c, "/add"));
  c.Send(json{{"op", "call_service"}, {"service", "/add"}, {"args", {{"a", 2}}}, {"id", "a1"}});
  json call =
      provider.WaitMessage([](const json& m) { return m.value("op", "") == "call_service"; });
  ASSERT_FALSE(call.is_null());
  EXPECT_EQ(call["args"]["a"], 2);
  provider.Send(json{{"op", "service_response"},
                     {"service", "/add"},
                     {"id", call["id"]},
                     {"values", {{"sum", 3}}},
                     {"result", true}});
  json r = c.WaitMessage([](const json& m) { return m.value("id", "") == "a1"; });
  ASSERT_FALSE(r.is_null());
  EXPECT_EQ(r["values"]["sum"], 3);

  // pause and step through services: the clock stops, then advances by exactly the steps
  c.Send(json{{"op", "call_service"}, {"service", "/partsim/pause"}, {"id", "p"}});
  ASSERT_FALSE(c.WaitMessage([](const json& m) { return m.value("id", "") == "p"; }).is_null());
  // a command runs between two steps: once it has, the paused thread takes no step of its own
  std::atomic<bool> between_steps{false};
  sim_->Post([&] { between_steps = true; });
  ASSERT_TRUE(WaitFor([&] { return between_steps.load(); }));
  const long long n = sim_->GetClockSteps();
  c.Send(json{{"op", "call_service"}, {"service", "/partsim/step"}, {"args", {{"n", 25}}}});
  EXPECT_TRUE(WaitFor([&] { return sim_->GetClockSteps() >= n + 25; }));
  std::this_thread::sleep_for(50ms);  // not one step more
  EXPECT_EQ(sim_->GetClockSteps(), n + 25);
}

TEST_F(RosbridgeTest, PositionCommandMovesTheRobotWithinAStep) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.KeepJointStates();
  c.Send(json{{"op", "subscribe"}, {"topic", "/joint_states"}, {"queue_length", 1}});
  std::vector<double> target(robot_.Dof(), 0.0);
  target[2] = 0.15;  // z slide (m)
  c.Send(
      json{{"op", "publish"},
           {"topic", "/" + robot_.GetName() + "/joint_position_controller/command"},
           {"msg", {{"layout", {{"dim", json::array()}, {"data_offset", 0}}}, {"data", target}}}});
  json reached = c.WaitMessage([](const json& m) {
    return m.value("topic", "") == "/joint_states" &&
           std::abs(m["msg"]["position"][2].get<double>() - 0.15) < 2e-3;
  });
  EXPECT_FALSE(reached.is_null());
  RosbridgeStats s = bridge_->GetStats();
  EXPECT_EQ(s.commands, 1);
  EXPECT_LE(s.max_latency_steps, 1);  // applied before the next step
}

/// Index of `joint` in a list of names (-1 if absent).
int IndexOf(const json& names, const std::string& joint) {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == joint) return static_cast<int>(i);
  return -1;
}

double Seconds(const json& duration) {
  return duration["secs"].get<double>() + 1e-9 * duration["nsecs"].get<double>();
}

TEST_F(RosbridgeTest, PlanServiceAnswersWithTheTrajectoryAndTheRobotReachesTheGoal) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.KeepJointStates();
  c.Send(json{{"op", "subscribe"}, {"topic", "/joint_states"}, {"queue_length", 1}});
  json first = c.WaitMessage([](const json& m) { return m.value("topic", "") == "/joint_states"; });
  ASSERT_FALSE(first.is_null());
  const json names = first["msg"]["name"];
  const int x = IndexOf(names, "x");
  ASSERT_GE(x, 0);
  std::vector<double> start = first["msg"]["position"].get<std::vector<double>>();
  std::vector<double> goal = start;
  goal[x] += 0.2;  // m
  c.Send(json{{"op", "call_service"},
              {"service", "/" + robot_.GetName() + "/plan"},
              {"args", {{"joint_goal", goal}, {"time_limit", 2.0}}},
              {"id", "plan1"}});
  json r = c.WaitMessage([](const json& m) { return m.value("id", "") == "plan1"; });
  ASSERT_FALSE(r.is_null());
  ASSERT_EQ(r["op"], "service_response") << r.dump();
  EXPECT_TRUE(r["result"].get<bool>());
  const json& v = r["values"];
  ASSERT_TRUE(v["success"].get<bool>()) << v["message"];
  EXPECT_EQ(v["message"], "");
  EXPECT_GE(v["planning_time"].get<double>(), 0.0);
  EXPECT_EQ(v["trajectory"]["joint_names"], names);
  const json& points = v["trajectory"]["points"];
  ASSERT_GE(points.size(), 2u);
  for (size_t i = 0; i < goal.size(); ++i) {
    EXPECT_NEAR(points.front()["positions"][i].get<double>(), start[i], 1e-2) << i;
    EXPECT_NEAR(points.back()["positions"][i].get<double>(), goal[i], 1e-6) << i;
  }
  EXPECT_EQ(Seconds(points.front()["time_from_start"]), 0.0);
  EXPECT_GT(Seconds(points.back()["time_from_start"]), 0.0);
  // executed: the joint states arrive at the goal
  json reached = c.WaitMessage([&](const json& m) {
    return m.value("topic", "") == "/joint_states" &&
           std::abs(m["msg"]["position"][x].get<double>() - goal[x]) < 1e-2;
  });
  EXPECT_FALSE(reached.is_null());
}

TEST_F(RosbridgeTest, PlanServiceRefusesBadArgsNamingTheProblem) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  const std::string plan = "/" + robot_.GetName() + "/plan";
  const size_t n = robot_.Dof();
  const std::vector<double> here(n, 0.0);
  const json position = {{"x", 0.2}, {"y", 0.0}, {"z", 0.5}};
  const std::vector<std::pair<json, std::string>> cases = {
      {json::object(), "joint_goal"},
      {{{"joint_goal", {0.1, 0.2}}}, "2 values for " + std::to_string(n) + " joints"},
      {{{"joint_goal", {0.1, "a"}}}, "joint_goal holds a value that is not a number"},
      {{{"joint_goal", here}, {"execute", "yes"}}, "execute must be a boolean"},
      {{{"joint_goal", here}, {"time_limit", "long"}}, "time_limit must be a number"},
      {{{"joint_goal", here}, {"time_limit", -1.0}}, "time_limit"},
      {{{"joint_goal", here}, {"algorithm", "Nope"}}, "algorithm"},
      {{{"pose_goal", {{"position", position}}}}, "orientation"},
      {{{"pose_goal",
         {{"position", position},
          {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}, {"w", 2.0}}}}}},
       "unit quaternion"},
      {{{"pose_goal",
         {{"position", {{"x", 0.2}, {"y", "a"}, {"z", 0.5}}},
          {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}, {"w", 1.0}}}}}},
       "'y'"},
  };
  for (size_t i = 0; i < cases.size(); ++i)
    c.Send(json{{"op", "call_service"},
                {"service", plan},
                {"args", cases[i].first},
                {"id", "bad" + std::to_string(i)}});
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string id = "bad" + std::to_string(i);
    json e = c.WaitMessage([&](const json& m) { return m.value("id", "") == id; });
    ASSERT_FALSE(e.is_null()) << id;
    EXPECT_TRUE(IsError(e)) << e.dump();
    const std::string msg = e.value("msg", "");
    EXPECT_NE(msg.find(cases[i].second), std::string::npos)
        << cases[i].first.dump() << ": \"" << msg << "\" does not name \"" << cases[i].second
        << "\"";
  }
  // a good request still plans; the bad ones never get an answer
  std::vector<double> goal(n, 0.0);
  goal[0] = 0.1;
  c.Send(json{{"op", "call_service"},
              {"service", plan},
              {"args", {{"joint_goal", goal}, {"execute", false}}},
              {"id", "good"}});
  json good = c.WaitMessage([](const json& m) {
    return m.value("id", "") == "good" && m.value("op", "") == "service_response";
  });
  ASSERT_FALSE(good.is_null());
  EXPECT_TRUE(good["values"]["success"].get<bool>()) << good["values"]["message"];
  for (const json& m : c.Messages())
    EXPECT_FALSE(m.value("op", "") == "service_response" && m.value("id", "").rfind("bad", 0) == 0)
        << m.dump();
}

TEST_F(RosbridgeTest, EffortCommandIsAcceptedAndAWrongLengthIsRefused) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  const std::string topic = "/" + robot_.GetName() + "/joint_effort_controller/command";
  std::vector<double> effort(robot_.Dof(), 0.0);
  c.Send(json{{"op", "publish"}, {"topic", topic}, {"msg", {{"data", effort}}}, {"id", "e1"}});
  c.Send(json{{"op", "publish"}, {"topic", topic}, {"msg", {{"data", {1.0, 2.0}}}}, {"id", "e2"}});
  c.Send(json{{"op", "publish"}, {"topic", topic}, {"msg", {{"data", "a"}}}, {"id", "e3"}});
  c.Send(json{{"op", "publish"}, {"topic", topic}, {"msg", json::object()}, {"id", "e4"}});
  json e2 = c.WaitMessage([](const json& m) { return m.value("id", "") == "e2"; });
  ASSERT_TRUE(IsError(e2)) << e2.dump();
  EXPECT_NE(e2["msg"].get<std::string>().find(topic + ": 2 values for " +
                                              std::to_string(robot_.Dof()) + " joints"),
            std::string::npos)
      << e2["msg"];
  json e3 = c.WaitMessage([](const json& m) { return m.value("id", "") == "e3"; });
  EXPECT_TRUE(IsError(e3)) << e3.dump();
  json e4 = c.WaitMessage([](const json& m) { return m.value("id", "") == "e4"; });
  ASSERT_TRUE(IsError(e4)) << e4.dump();
  EXPECT_NE(e4["msg"].get<std::string>().find("'data'"), std::string::npos) << e4["msg"];
  // the good one was applied (and only that one), without an error
  EXPECT_TRUE(WaitFor([&] { return bridge_->GetStats().commands == 1; }));
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(bridge_->GetStats().commands, 1);
  for (const json& m : c.Messages()) EXPECT_NE(m.value("id", ""), "e1") << m.dump();
}

TEST_F(RosbridgeTest, FragmentedCommandIsReassembledAndBadFragmentsAreRefused) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  const std::string topic = "/" + robot_.GetName() + "/joint_position_controller/command";
  std::vector<double> q(robot_.Dof(), 0.0);
  q[2] = 0.6;  // z of the flying gripper
  const std::string text =
      json{{"op", "publish"}, {"topic", topic}, {"msg", {{"data", q}}}, {"id", "whole"}}.dump();
  // three pieces, sent out of order
  const size_t n = 3, piece = (text.size() + n - 1) / n;
  for (size_t i : {2u, 0u, 1u})
    c.Send(json{{"op", "fragment"},
                {"id", "m1"},
                {"data", text.substr(i * piece, piece)},
                {"num", i},
                {"total", n}});
  EXPECT_TRUE(WaitFor([&] { return bridge_->GetStats().commands == 1; }));
  // bad fragments: each answered with an error, nothing applied
  c.Send(json{{"op", "fragment"}, {"id", "b1"}, {"data", "x"}, {"num", 3}, {"total", 3}});
  c.Send(json{{"op", "fragment"}, {"id", "b2"}, {"data", 5}, {"num", 0}, {"total", 2}});
  c.Send(json{{"op", "fragment"}, {"data", "x"}, {"num", 0}, {"total", 2}});
  c.Send(json{{"op", "fragment"}, {"id", "b4"}, {"data", "{\"op\":"}, {"num", 0}, {"total", 2}});
  c.Send(json{{"op", "fragment"}, {"id", "b4"}, {"data", "nonsense"}, {"num", 1}, {"total", 2}});
  for (const char* id : {"b1", "b2"}) {
    json e = c.WaitMessage([&](const json& m) { return m.value("id", "") == id; });
    ASSERT_TRUE(IsError(e)) << id << ": " << e.dump();
    EXPECT_NE(e["msg"].get<std::string>().find("fragment"), std::string::npos) << e["msg"];
  }
  json bad = c.WaitMessage([](const json& m) {
    return IsError(m) && m["msg"].get<std::string>().find("malformed JSON") != std::string::npos;
  });
  EXPECT_FALSE(bad.is_null()) << "the reassembled nonsense is reported as malformed JSON";
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(bridge_->GetStats().commands, 1);
}

// Fragments announcing 16,777,216 pieces once reserved ~0.5 GB each; now what is held follows
// the bytes received, and an absurd total is refused.
TEST_F(RosbridgeTest, FragmentsAnnouncingHugeTotalsAreRefusedAndHoldNoMemory) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  for (int k = 0; k < 4; ++k)
    c.Send(json{{"op", "fragment"},
                {"id", "huge" + std::to_string(k)},
                {"data", std::string(100, 'x')},
                {"num", 0},
                {"total", 16777216}});
  for (int k = 0; k < 4; ++k) {
    const std::string id = "huge" + std::to_string(k);
    json e = c.WaitMessage([&](const json& m) { return m.value("id", "") == id; });
    ASSERT_TRUE(IsError(e)) << id << ": " << e.dump();
    EXPECT_NE(e["msg"].get<std::string>().find("more than 65536 pieces"), std::string::npos)
        << e["msg"];
  }
  // allowed totals hold only what came: 16 messages of 65536 announced pieces, one piece each
  for (int k = 0; k < 16; ++k)
    c.Send(json{{"op", "fragment"},
                {"id", "many" + std::to_string(k)},
                {"data", "y"},
                {"num", 0},
                {"total", 65536}});
  // a 17th message in pieces at once is refused
  c.Send(json{{"op", "fragment"}, {"id", "many16"}, {"data", "y"}, {"num", 0}, {"total", 2}});
  json e = c.WaitMessage([](const json& m) { return m.value("id", "") == "many16"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("too many messages"), std::string::npos) << e["msg"];
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}});
  EXPECT_TRUE(ClockAdvances(c, 0.05));
}

// /partsim/step's n was read as an int: 2^32 + 1 ran 1 step, 2^32 + 2^31 - 1 queued 2^31 - 1
// steps that pause and reset did not cancel.
TEST_F(RosbridgeTest, StepServiceChecksTheWholeRangeOfN) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "call_service"}, {"service", "/partsim/pause"}, {"id", "p"}});
  ASSERT_FALSE(c.WaitMessage([](const json& m) { return m.value("id", "") == "p"; }).is_null());
  const std::vector<json> bad = {json(4294967297LL), json(6442450943LL), json(-3),     json(0),
                                 json(2.5),          json("7"),          json(1000001)};
  for (size_t k = 0; k < bad.size(); ++k) {
    const std::string id = "s" + std::to_string(k);
    c.Send(json{{"op", "call_service"},
                {"service", "/partsim/step"},
                {"args", {{"n", bad[k]}}},
                {"id", id}});
    json e = c.WaitMessage([&](const json& m) { return m.value("id", "") == id; });
    ASSERT_TRUE(IsError(e) || e.value("result", true) == false) << bad[k] << ": " << e.dump();
    EXPECT_NE(e.dump().find("from 1 to 1000000"), std::string::npos) << e.dump();
  }
  EXPECT_EQ(sim_->GetPendingSteps(), 0);
  // the largest request is taken, and a pause cancels what is left of it
  c.Send(json{{"op", "call_service"},
              {"service", "/partsim/step"},
              {"args", {{"n", 1000000}}},
              {"id", "big"}});
  ASSERT_FALSE(c.WaitMessage([](const json& m) { return m.value("id", "") == "big"; }).is_null());
  ASSERT_TRUE(WaitFor([&] { return sim_->GetClockSteps() > 10; }));
  c.Send(json{{"op", "call_service"}, {"service", "/partsim/pause"}, {"id", "p2"}});
  ASSERT_FALSE(c.WaitMessage([](const json& m) { return m.value("id", "") == "p2"; }).is_null());
  EXPECT_EQ(sim_->GetPendingSteps(), 0);
}

// A trajectory point 1e200 s away made the drive targets not finite on the simulation thread,
// which ended the process: now the command is refused naming the field, and the clock goes on.
TEST_F(RosbridgeTest, TrajectoryWithAFarTimeIsRefusedAndTheSimulationGoesOn) {
  auto c = ClockWatcher();
  const std::string topic = "/" + robot_.GetName() + "/joint_trajectory_controller/command";
  c->Send(json{{"op", "advertise"}, {"topic", topic}, {"type", "trajectory_msgs/JointTrajectory"}});
  std::vector<std::string> names;
  for (const Joint& j : robot_.GetActiveJoints()) names.push_back(j.GetName());
  json point = {{"positions", std::vector<double>(names.size(), 0.1)},
                {"time_from_start", {{"secs", 1e200}, {"nsecs", 0}}}};
  c->Send(json{{"op", "publish"},
               {"topic", topic},
               {"msg", {{"joint_names", names}, {"points", {point}}}},
               {"id", "far"}});
  json e = c->WaitMessage([](const json& m) { return m.value("id", "") == "far"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("points[0].time_from_start must be from 0 to 86400"),
            std::string::npos)
      << e["msg"];
  point["time_from_start"] = {{"secs", "soon"}};
  c->Send(json{{"op", "publish"},
               {"topic", topic},
               {"msg", {{"joint_names", names}, {"points", {point}}}},
               {"id", "word"}});
  e = c->WaitMessage([](const json& m) { return m.value("id", "") == "word"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("time_from_start.secs is not a number"),
            std::string::npos)
      << e["msg"];
  EXPECT_TRUE(ClockAdvances(*c, 0.05));
  EXPECT_EQ(sim_->GetErrorCount(), 0);
}

// ---- who may connect, and what one client may hold ----

/// A page on another site, opened in the user's browser, must not reach the server.
TEST_F(RosbridgeTest, PagesFromOtherOriginsAreRefusedAndLocalPagesAndToolsAreNot) {
  TestClient evil(port_, "http://evil.example.com");
  EXPECT_FALSE(evil.WaitOpen());
  TestClient evil_port(port_, "http://localhost.example.com:9090");
  EXPECT_FALSE(evil_port.WaitOpen());
  EXPECT_EQ(bridge_->GetStats().refused, 2);
  for (const char* origin : {"http://localhost:8000", "http://127.0.0.1", "https://[::1]:3000"}) {
    TestClient local(port_, origin);
    EXPECT_TRUE(local.WaitOpen()) << origin;
  }
  TestClient tool(port_);  // roslib in Node.js, rospy: no Origin at all
  ASSERT_TRUE(tool.WaitOpen());
  tool.Send(json{{"op", "subscribe"}, {"topic", "/clock"}});
  EXPECT_TRUE(ClockAdvances(tool, 0.05));
}

TEST_F(RosbridgeTest, ASubscriberCapsItsTopicsAndRequests) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  for (int k = 0; k < 256; ++k)
    c.Send(json{{"op", "subscribe"}, {"topic", "/t" + std::to_string(k)}});
  c.Send(json{{"op", "subscribe"}, {"topic", "/one_too_many"}, {"id", "over"}});
  json e = c.WaitMessage([](const json& m) { return m.value("id", "") == "over"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("at most 256"), std::string::npos) << e["msg"];
  for (int k = 0; k < 64; ++k)
    c.Send(json{{"op", "subscribe"}, {"topic", "/t0"}, {"id", "r" + std::to_string(k)}});
  c.Send(json{{"op", "subscribe"}, {"topic", "/t0"}, {"id", "r64"}});
  e = c.WaitMessage([](const json& m) { return m.value("id", "") == "r64"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("at most 64"), std::string::npos) << e["msg"];
}

TEST_F(RosbridgeTest, ServiceCallsGoToTheirProviderAloneAndNeverHang) {
  TestClient provider(port_), rival(port_), caller(port_);
  ASSERT_TRUE(provider.WaitOpen() && rival.WaitOpen() && caller.WaitOpen());
  provider.Send(json{{"op", "advertise_service"}, {"service", "/add"}, {"type", "x/Add"}});
  ASSERT_TRUE(WaitAdvertised(caller, "/add"));
  // no silent take-over of the name, and partsim's own services are not for advertising
  rival.Send(
      json{{"op", "advertise_service"}, {"service", "/add"}, {"type", "x/Add"}, {"id", "t"}});
  json e = rival.WaitMessage([](const json& m) { return m.value("id", "") == "t"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("another client provides"), std::string::npos);
  rival.Send(json{{"op", "advertise_service"}, {"service", "/partsim/pause"}, {"id", "p"}});
  e = rival.WaitMessage([](const json& m) { return m.value("id", "") == "p"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  // the call reaches the provider under an id no one can guess; only the provider answers it
  caller.Send(
      json{{"op", "call_service"}, {"service", "/add"}, {"args", {{"a", 1}}}, {"id", "c1"}});
  json call =
      provider.WaitMessage([](const json& m) { return m.value("op", "") == "call_service"; });
  ASSERT_FALSE(call.is_null());
  const std::string call_id = call["id"].get<std::string>();
  EXPECT_EQ(call_id.size(), std::string("partsim_call_").size() + 32) << call_id;
  rival.Send(json{
      {"op", "service_response"}, {"id", call_id}, {"values", {{"sum", 666}}}, {"result", true}});
  ASSERT_FALSE(rival
                   .WaitMessage([](const json& m) {
                     return IsError(m) &&
                            m["msg"].get<std::string>().find("to this client") != std::string::npos;
                   })
                   .is_null())
      << "the rival's answer was not refused";
  provider.Send(json{{"op", "service_response"},
                     {"service", "/add"},
                     {"id", call_id},
                     {"values", {{"sum", 2}}},
                     {"result", true}});
  json r = caller.WaitMessage([](const json& m) { return m.value("id", "") == "c1"; });
  ASSERT_FALSE(r.is_null());
  EXPECT_EQ(r["values"]["sum"], 2);  // the provider's answer, not the rival's
  bool rival_refused = false;
  for (const json& m : rival.Messages())
    rival_refused |=
        IsError(m) && m["msg"].get<std::string>().find("to this client") != std::string::npos;
  EXPECT_TRUE(rival_refused);
  // a provider that leaves mid-call: the caller is told, not left waiting
  caller.Send(
      json{{"op", "call_service"}, {"service", "/add"}, {"args", {{"a", 2}}}, {"id", "c2"}});
  ASSERT_TRUE(WaitFor([&] {
    int calls = 0;
    for (const json& m : provider.Messages()) calls += m.value("op", "") == "call_service";
    return calls == 2;
  }));
  provider.Close();
  json gone = caller.WaitMessage([](const json& m) { return m.value("id", "") == "c2"; });
  ASSERT_FALSE(gone.is_null());
  EXPECT_EQ(gone["result"], false);
  EXPECT_NE(gone.dump().find("the provider disconnected"), std::string::npos) << gone.dump();
  // the name is free again
  rival.Send(
      json{{"op", "advertise_service"}, {"service", "/add"}, {"type", "x/Add"}, {"id", "t2"}});
  const json names = Sync(rival);  // answered after the advertise was handled
  ASSERT_TRUE(names.is_array());
  EXPECT_NE(std::find(names.begin(), names.end(), "/add"), names.end()) << names.dump();
  for (const json& m : rival.Messages()) EXPECT_NE(m.value("id", ""), "t2") << m.dump();
}

/// A server with an origin allow-list, a token and room for two clients.
class RosbridgeGuardedTest : public RosbridgeTest {
 protected:
  RosbridgeOptions Options() const override {
    RosbridgeOptions o;
    o.allowed_origins = {"http://lab.example:8000"};
    o.auth_token = "s3cret";
    o.max_clients = 2;
    return o;
  }
};

TEST_F(RosbridgeGuardedTest, AllowListReplacesTheLocalOrigins) {
  TestClient local(port_, "http://localhost:8000");
  EXPECT_FALSE(local.WaitOpen());
  TestClient lab(port_, "http://LAB.example:8000");  // origins compare without case
  EXPECT_TRUE(lab.WaitOpen());
}

TEST_F(RosbridgeGuardedTest, NothingButAuthUntilTheTokenComesRight) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "call_service"}, {"service", "/partsim/pause"}, {"id", "early"}});
  json e = c.WaitMessage([](const json& m) { return m.value("id", "") == "early"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("authenticate first"), std::string::npos);
  EXPECT_FALSE(sim_->IsPaused());
  c.Send(json{{"op", "auth"}, {"mac", "s3cret"}, {"id", "a"}});
  json ok = c.WaitMessage([](const json& m) { return m.value("id", "") == "a"; });
  EXPECT_EQ(ok.value("level", ""), "info") << ok.dump();
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}});
  EXPECT_TRUE(ClockAdvances(c, 0.05));
  // a wrong token closes the connection
  TestClient w(port_);
  ASSERT_TRUE(w.WaitOpen());
  w.Send(json{{"op", "auth"}, {"mac", "s3cret!"}, {"id", "bad"}});
  EXPECT_TRUE(WaitFor([&] { return w.Closed(); }));
}

TEST_F(RosbridgeGuardedTest, LongMessagesBeforeAuthAreRefusedUnparsed) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  // the right token, padded past the pre-auth bound: refused without being read
  c.Send(json{{"op", "auth"}, {"mac", "s3cret"}, {"pad", std::string(5000, 'x')}, {"id", "long"}});
  json e = c.WaitMessage([](const json& m) { return IsError(m); });
  ASSERT_FALSE(e.is_null());
  EXPECT_NE(e["msg"].get<std::string>().find("messages are limited to 4096 bytes"),
            std::string::npos)
      << e.dump();
  EXPECT_FALSE(e.contains("id")) << e.dump();  // the message was not parsed for its id
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}, {"id", "s"}});
  json refused = c.WaitMessage([](const json& m) { return m.value("id", "") == "s"; });
  EXPECT_NE(refused.dump().find("authenticate first"), std::string::npos) << refused.dump();
  // the short auth op still works on the same connection
  c.Send(json{{"op", "auth"}, {"mac", "s3cret"}, {"id", "a"}});
  json ok = c.WaitMessage([](const json& m) { return m.value("id", "") == "a"; });
  EXPECT_EQ(ok.value("level", ""), "info") << ok.dump();
}

TEST_F(RosbridgeGuardedTest, ConnectionsBeyondTheCapAreRefused) {
  auto a = std::make_unique<TestClient>(port_);
  TestClient b(port_);
  ASSERT_TRUE(a->WaitOpen() && b.WaitOpen());
  {
    TestClient c(port_);
    EXPECT_FALSE(c.WaitOpen());
  }
  EXPECT_GE(bridge_->GetStats().refused, 1);
  a.reset();
  ASSERT_TRUE(WaitFor([&] { return bridge_->GetStats().clients == 1; }));
  TestClient d(port_);
  EXPECT_TRUE(d.WaitOpen());
}

/// `n` WebSocket handshakes sent at once on raw sockets (loopback), then their answers read:
/// the number answered 101 (switching protocols). The sockets stay open in `fds`.
int BurstOfHandshakes(int port, int n, std::vector<int>* fds) {
  for (int i = 0; i < n; ++i) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) break;
    timeval timeout{10, 0};  // a server that never answers fails the test instead of hanging
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
      ::close(fd);
      break;
    }
    fds->push_back(fd);
  }
  const std::string req = RawSocket::Handshake();
  for (int fd : *fds) ::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
  int accepted = 0;
  for (int fd : *fds) {
    std::string resp;
    char ch;
    while (resp.find("\r\n\r\n") == std::string::npos && ::read(fd, &ch, 1) == 1) resp += ch;
    accepted += resp.find(" 101 ") != std::string::npos;
  }
  return accepted;
}

/// A server with room for four clients.
class RosbridgeCappedTest : public RosbridgeTest {
 protected:
  RosbridgeOptions Options() const override {
    RosbridgeOptions o;
    o.max_clients = 4;
    return o;
  }
};

// Under a burst of handshakes the cap once let 34 clients in for 32: it counted clients opened,
// and handshakes accepted together did not see each other. It counts accepted handshakes now.
TEST_F(RosbridgeCappedTest, ABurstOfHandshakesNeverGetsPastTheCap) {
  for (int round = 0; round < 3; ++round) {
    std::vector<int> fds;
    const int accepted = BurstOfHandshakes(port_, 40, &fds);
    EXPECT_EQ(fds.size(), 40u);
    EXPECT_GE(accepted, 1) << "round " << round;
    EXPECT_LE(accepted, 4) << "round " << round;
    EXPECT_TRUE(WaitFor([&] { return bridge_->GetStats().clients == accepted; }))
        << bridge_->GetStats().clients << " clients, round " << round;
    for (int fd : fds) ::close(fd);
    // the slots come back with the connections
    ASSERT_TRUE(WaitFor([&] { return bridge_->GetStats().clients == 0; })) << "round " << round;
  }
  EXPECT_GE(bridge_->GetStats().refused, 90);  // 36 a round, unless a handshake failed
  auto c = ClockWatcher();
  EXPECT_TRUE(ClockAdvances(*c, 0.05));
}

/// A server with a token, room for one client, and two seconds to authenticate.
class RosbridgeAuthTimeoutTest : public RosbridgeTest {
 protected:
  RosbridgeOptions Options() const override {
    RosbridgeOptions o;
    o.auth_token = "s3cret";
    o.max_clients = 1;
    o.auth_timeout = 2.0;
    return o;
  }
};

// A socket that never authenticates held its slot for ever and locked the token holder out.
TEST_F(RosbridgeAuthTimeoutTest, ASilentClientIsClosedAndTheTokenHolderGetsIn) {
  TestClient silent(port_);
  ASSERT_TRUE(silent.WaitOpen());
  {
    TestClient locked_out(port_);
    EXPECT_FALSE(locked_out.WaitOpen());  // HTTP 503: the one slot is taken
  }
  ASSERT_TRUE(WaitFor([&] { return silent.Closed(); }));
  EXPECT_EQ(silent.CloseCode(), 1008);  // policy violation
  ASSERT_TRUE(WaitFor([&] { return bridge_->GetStats().clients == 0; }));
  TestClient holder(port_);
  ASSERT_TRUE(holder.WaitOpen());
  holder.Send(json{{"op", "auth"}, {"mac", "s3cret"}, {"id", "a"}});
  json ok = holder.WaitMessage([](const json& m) { return m.value("id", "") == "a"; });
  EXPECT_EQ(ok.value("level", ""), "info") << ok.dump();
  holder.Send(json{{"op", "subscribe"}, {"topic", "/clock"}});
  // authenticated, it stays past the time limit
  std::this_thread::sleep_for(3s);
  EXPECT_FALSE(holder.Closed());
  EXPECT_TRUE(ClockAdvances(holder, 0.05));
}

// Names and ids were unbounded: 100 subscriptions with 8 MB topic names held 818 MB.
TEST_F(RosbridgeTest, LongNamesAndIdsAreRefusedNamingTheFieldAndTheBound) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  const std::string long_name = "/" + std::string(300, 'n');
  const std::string longest = "/" + std::string(255, 'k');  // 256 bytes: accepted
  c.Send(json{{"op", "subscribe"}, {"topic", long_name}, {"id", "t"}});
  c.Send(json{{"op", "advertise"}, {"topic", "/ok"}, {"type", long_name}, {"id", "y"}});
  c.Send(json{{"op", "advertise_service"}, {"service", long_name}, {"type", "x/Y"}, {"id", "s"}});
  c.Send(json{{"op", "call_service"}, {"service", long_name}, {"id", "c"}});
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}, {"compression", long_name}, {"id", "z"}});
  c.Send(json{{"op", std::string(300, 'o')}, {"id", "o"}});
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"t", "'topic' is 301 bytes long (at most 256)"},
      {"y", "'type' is 301 bytes long (at most 256)"},
      {"s", "'service' is 301 bytes long (at most 256)"},
      {"c", "'service' is 301 bytes long (at most 256)"},
      {"z", "'compression' is 301 bytes long (at most 256)"},
      {"o", "'op' is 300 bytes long (at most 256)"}};
  for (const auto& [id, part] : cases) {
    json e = c.WaitMessage([&](const json& m) { return m.value("id", "") == id; });
    ASSERT_TRUE(IsError(e)) << id << ": " << e.dump();
    EXPECT_NE(e["msg"].get<std::string>().find(part), std::string::npos) << e["msg"];
  }
  // a long id is refused, and not echoed
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}, {"id", std::string(2000, 'i')}});
  c.Send(json{
      {"op", "subscribe"}, {"topic", "/clock"}, {"id", json::array({std::string(1100, 'j')})}});
  for (const char* part :
       {"'id' is 2000 bytes long (at most 1024)", "'id' is 1104 bytes long (at most 1024)"}) {
    json e = c.WaitMessage([&](const json& m) {
      return IsError(m) && m["msg"].get<std::string>().find(part) != std::string::npos;
    });
    ASSERT_FALSE(e.is_null()) << part;
    EXPECT_FALSE(e.contains("id"));
  }
  // nothing of the refused names was kept; a name of 256 bytes is fine
  c.Send(json{{"op", "advertise"}, {"topic", longest}, {"type", "std_msgs/String"}, {"id", "k"}});
  c.Send(json{{"op", "call_service"}, {"service", "/rosapi/topics"}, {"id", "list"}});
  json topics = c.WaitMessage([](const json& m) { return m.value("id", "") == "list"; });
  ASSERT_FALSE(topics.is_null());
  const std::string listed = topics["values"]["topics"].dump();
  EXPECT_NE(listed.find(longest), std::string::npos);
  EXPECT_EQ(listed.find(long_name), std::string::npos);
  EXPECT_EQ(listed.find("/ok"), std::string::npos);
  for (const json& m : c.Messages()) EXPECT_NE(m.value("id", ""), "k") << m.dump();
}

TEST_F(RosbridgeTest, ASubscriberCapsItsRequestsOnAllTopicsTogether) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  for (int t = 0; t < 16; ++t)
    for (int k = 0; k < 64; ++k)
      c.Send(json{{"op", "subscribe"},
                  {"topic", "/u" + std::to_string(t)},
                  {"id", "r" + std::to_string(k)}});
  c.Send(json{{"op", "subscribe"}, {"topic", "/u16"}, {"id", "over"}});
  json e = c.WaitMessage([](const json& m) { return m.value("id", "") == "over"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("at most 1024 on all its topics"), std::string::npos)
      << e["msg"];
  // a request already open may be renewed
  c.Send(json{{"op", "subscribe"}, {"topic", "/u3"}, {"id", "r7"}, {"throttle_rate", 10}});
  c.Send(json{{"op", "call_service"}, {"service", "/rosapi/services"}, {"id", "after"}});
  ASSERT_FALSE(c.WaitMessage([](const json& m) { return m.value("id", "") == "after"; }).is_null());
  for (const json& m : c.Messages()) EXPECT_NE(m.value("id", ""), "r7") << m.dump();
}

// Four 30 s RRT* plans and a disconnect once held another client's 1 s plan for two minutes.
TEST_F(RosbridgeTest, PlansAreBoundedPerClientAndCancelledWhenItLeaves) {
  const std::string plan = "/" + robot_.GetName() + "/plan";
  auto greedy = std::make_unique<TestClient>(port_);
  ASSERT_TRUE(greedy->WaitOpen());
  greedy->KeepJointStates();
  greedy->Send(json{{"op", "subscribe"}, {"topic", "/joint_states"}, {"queue_length", 1}});
  json first =
      greedy->WaitMessage([](const json& m) { return m.value("topic", "") == "/joint_states"; });
  ASSERT_FALSE(first.is_null());
  std::vector<double> goal = first["msg"]["position"].get<std::vector<double>>();
  goal[IndexOf(first["msg"]["name"], "x")] += 0.2;
  for (const char* id : {"p1", "p2", "p3"})
    greedy->Send(json{{"op", "call_service"},
                      {"service", plan},
                      {"args",
                       {{"joint_goal", goal},
                        {"algorithm", "RRTstar"},
                        {"time_limit", 25.0},
                        {"execute", false}}},
                      {"id", id}});
  json e = greedy->WaitMessage([](const json& m) { return m.value("id", "") == "p3"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("at most 2"), std::string::npos) << e["msg"];
  greedy->Close();
  greedy.reset();
  // the leaver's plans are cancelled: another client's plan answers within WaitMessage's 30 s,
  // not after 50 s of RRT*
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "call_service"},
              {"service", plan},
              {"args", {{"joint_goal", goal}, {"time_limit", 1.0}, {"execute", false}}},
              {"id", "quick"}});
  json r = c.WaitMessage([](const json& m) { return m.value("id", "") == "quick"; });
  ASSERT_FALSE(r.is_null()) << "the plan waited behind a departed client's";
  EXPECT_TRUE(r["values"]["success"].get<bool>()) << r.dump();
}

TEST_F(RosbridgeTest, SubscribeRequestsByIdAreUnsubscribedOneByOne) {
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}, {"id", "a"}});
  c.Send(json{{"op", "subscribe"}, {"topic", "/clock"}, {"id", "b"}, {"throttle_rate", 100}});
  ASSERT_TRUE(WaitFor([&] { return c.LastClock() > 0; }));
  // one message per step whatever the number of requests (the unthrottled one wins)
  c.Send(json{{"op", "unsubscribe"}, {"topic", "/clock"}, {"id", "a"}});
  ASSERT_TRUE(Sync(c).is_array());  // the unsubscribe handled
  const double t0 = c.LastClock();
  EXPECT_TRUE(WaitFor([&] { return c.LastClock() > t0; })) << "request b still subscribes";
  c.Send(json{{"op", "unsubscribe"}, {"topic", "/clock"}, {"id", "b"}});
  // b's messages come every 0.1 s: none for 1 s (within 60 s) means they stopped
  EXPECT_TRUE(WaitStill([&] { return c.LastClock(); })) << "/clock still comes: no request left";
}

TEST_F(RosbridgeTest, HugeMessageIsRejectedAndServerStaysUp) {
  auto watcher = ClockWatcher();
  TestClient big(port_);
  ASSERT_TRUE(big.WaitOpen());
  std::string payload = "{\"op\":\"publish\",\"topic\":\"/x\",\"msg\":{\"data\":\"" +
                        std::string(20u << 20, 'a') + "\"}}";
  big.Send(payload);
  EXPECT_TRUE(WaitFor([&] { return big.Closed(); }));
  // "message too big" (1009); when the server drops the socket while the client is still
  // writing the 20 MB, the client sees the connection end without a close frame (1006)
  EXPECT_TRUE(big.CloseCode() == 1009 || big.CloseCode() == 1006) << big.CloseCode();
  EXPECT_TRUE(ClockAdvances(*watcher, 0.05));
}

TEST_F(RosbridgeTest, ClientThatDisconnectsMidMessageIsForgotten) {
  auto watcher = ClockWatcher();
  for (int i = 0; i < 5; ++i) {
    RawSocket raw(port_);
    ASSERT_TRUE(raw.Ok());
    raw.Write(RawSocket::FrameHeader(1000) + "{\"op\":\"subscr");  // 1000 promised, 13 sent
    raw.Close();
  }
  EXPECT_TRUE(WaitFor([&] { return bridge_->GetStats().clients == 1; }));
  EXPECT_TRUE(ClockAdvances(*watcher, 0.05));
}

TEST_F(RosbridgeTest, FiftyClientsSubscribedToEverything) {
  std::vector<std::unique_ptr<TestClient>> clients;
  for (int i = 0; i < 50; ++i) {
    clients.push_back(std::make_unique<TestClient>(port_));
    ASSERT_TRUE(clients.back()->WaitOpen()) << i;
    for (const char* t : {"/clock", "/joint_states", "/tf"})
      clients.back()->Send(json{{"op", "subscribe"}, {"topic", t}});
  }
  EXPECT_TRUE(WaitFor([&] { return bridge_->GetStats().clients == 50; }));
  for (auto& c : clients) {
    EXPECT_TRUE(ClockAdvances(*c, 0.05));
    EXPECT_TRUE(WaitFor([&] { return c->TfCount() > 0; }));
  }
  const long long steps = sim_->GetClockSteps();
  std::this_thread::sleep_for(200ms);
  EXPECT_GT(sim_->GetClockSteps(), steps);
}

// One subscriber asking for /tf in one-character pieces once slowed the simulation from 500 to
// 110 steps/s for every client: the simulation thread cut the pieces. Now it queues one shared
// message, and the network thread fragments what the client can take.
TEST_F(RosbridgeTest, OneCharacterFragmentsCostTheSimulationNothing) {
  RawSocket greedy(port_);  // asks for everything in pieces and reads nothing
  ASSERT_TRUE(greedy.Ok());
  for (const char* t : {"/tf", "/joint_states", "/clock"})
    greedy.SendText(json{{"op", "subscribe"}, {"topic", t}, {"fragment_size", 1}}.dump());
  // the simulation thread's CPU time and clock, read on that thread
  auto sim_thread = [&]() -> std::pair<double, long long> {
    auto reading = std::make_shared<std::promise<std::pair<double, long long>>>();
    std::future<std::pair<double, long long>> f = reading->get_future();
    sim_->Post([this, reading] {
      timespec ts{};
      clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
      reading->set_value({ts.tv_sec + 1e-9 * ts.tv_nsec, sim_->GetClockSteps()});
    });
    if (f.wait_for(30s) != std::future_status::ready) return {-1.0, -1};
    return f.get();
  };
  const long long start = sim_->GetClockSteps();
  ASSERT_TRUE(WaitFor([&] { return sim_->GetClockSteps() > start + 50; }));  // subscribed
  const auto [cpu0, steps0] = sim_thread();
  ASSERT_GE(steps0, 0) << "the simulation thread ran no command in 30 s";
  ASSERT_TRUE(WaitFor([&] { return sim_->GetClockSteps() >= steps0 + 500; }))
      << "500 steps (1 s of simulated time) did not pass within 30 s";
  const auto [cpu1, steps1] = sim_thread();
  ASSERT_GE(steps1, steps0 + 500);
  // the thread's own CPU time, which other work on the machine hardly changes (0.25-0.36 ms a
  // step with both cores busy): cutting the pieces took about 9 ms a step (110 steps/s), more
  // than the 2 ms that a step of real time at 500 Hz leaves
  const double per_step = (cpu1 - cpu0) / static_cast<double>(steps1 - steps0);
  std::printf("simulation thread with a one-character subscriber: %.0f us of CPU per step\n",
              per_step * 1e6);
  EXPECT_LT(per_step, 2e-3) << "CPU seconds per step on the simulation thread";
}

// Random and mutated messages from one client (bounded in count and time, loopback only): the
// server answers or refuses each, another client's clock keeps advancing throughout, and nothing
// goes wrong on the simulation thread.
TEST_F(RosbridgeTest, FuzzedMessagesNeverStopTheServer) {
  auto watcher = ClockWatcher();
  TestClient fuzz(port_);
  ASSERT_TRUE(fuzz.WaitOpen());
  const std::string robot = "/" + robot_.GetName();
  const std::vector<std::string> seeds = {
      json{{"op", "subscribe"}, {"topic", "/joint_states"}, {"throttle_rate", 100}}.dump(),
      json{{"op", "subscribe"}, {"topic", "/tf"}, {"fragment_size", 50}, {"queue_length", 2}}
          .dump(),
      json{{"op", "unsubscribe"}, {"topic", "/tf"}}.dump(),
      json{{"op", "publish"},
           {"topic", robot + "/joint_position_controller/command"},
           {"msg", {{"data", std::vector<double>(robot_.Dof(), 0.05)}}}}
          .dump(),
      json{{"op", "publish"},
           {"topic", robot + "/joint_trajectory_controller/command"},
           {"msg",
            {{"joint_names", {"x", "y"}},
             {"points", {{{"positions", {0.1, 0.1}}, {"time_from_start", {{"secs", 1}}}}}}}}}
          .dump(),
      json{{"op", "call_service"}, {"service", "/rosapi/topics"}, {"id", "f"}}.dump(),
      json{{"op", "call_service"}, {"service", "/partsim/stats"}}.dump(),
      json{{"op", "call_service"},
           {"service", robot + "/plan"},
           {"args", {{"joint_goal", std::vector<double>(robot_.Dof(), 0.0)}, {"time_limit", 0.05}}}}
          .dump(),
      json{{"op", "advertise"}, {"topic", "/chat"}, {"type", "std_msgs/String"}}.dump(),
      json{{"op", "publish"}, {"topic", "/chat"}, {"msg", {{"data", "hi"}}}}.dump(),
      json{{"op", "advertise_service"}, {"service", "/svc"}, {"type", "x/Y"}}.dump(),
      json{{"op", "service_response"}, {"id", "partsim_call_0"}, {"result", true}}.dump(),
      json{{"op", "fragment"}, {"id", "q"}, {"data", "{\"op\":"}, {"num", 0}, {"total", 3}}.dump(),
      json{{"op", "auth"}, {"mac", "x"}}.dump()};
  const std::vector<std::string> junk = {"null",         "1e999",
                                         "-1",           "18446744073709551617",
                                         "[]",           "{}",
                                         "\"\xff\xfe\"", "[[[[[[[[[[1]]]]]]]]]]",
                                         "true",         "\"/partsim/resume\""};
  std::mt19937 rng(20261125);
  auto pick = [&](size_t n) { return static_cast<size_t>(rng() % n); };
  const auto t0 = std::chrono::steady_clock::now();
  double last_clock = watcher->LastClock();
  int sent = 0;
  for (int i = 0; i < 3000 && std::chrono::steady_clock::now() - t0 < 15s; ++i) {
    std::string m = seeds[pick(seeds.size())];
    switch (pick(5)) {
      case 0:  // flip bytes
        for (int k = 0; k < 3; ++k) m[pick(m.size())] = static_cast<char>(rng());
        break;
      case 1:  // cut
        m.resize(pick(m.size()));
        break;
      case 2: {  // a value replaced by junk
        const size_t colon = m.find(':', pick(m.size()));
        if (colon != std::string::npos) {
          const size_t end = m.find_first_of(",}", colon);
          m = m.substr(0, colon + 1) + junk[pick(junk.size())] +
              (end == std::string::npos ? "" : m.substr(end));
        }
        break;
      }
      case 3:  // bytes inserted
        m.insert(pick(m.size()), std::string(1 + pick(8), static_cast<char>(rng())));
        break;
      default:  // as it is, or as a binary frame
        if (pick(2)) {
          fuzz.SendBinary(m);
          ++sent;
          continue;
        }
    }
    fuzz.Send(m);
    ++sent;
    if (i % 500 == 499) {  // the clock keeps advancing throughout
      ASSERT_TRUE(WaitFor([&] { return watcher->LastClock() > last_clock; })) << "after " << i;
      last_clock = watcher->LastClock();
    }
  }
  EXPECT_GT(sent, 500);
  EXPECT_GT(bridge_->GetStats().errors, sent / 10);  // the handlers were reached and refused
  EXPECT_TRUE(ClockAdvances(*watcher, 0.05));
  EXPECT_FALSE(sim_->IsPaused());
  EXPECT_EQ(sim_->GetErrorCount(), 0) << sim_->GetLastError();
  // and it still answers a newcomer
  TestClient late(port_);
  ASSERT_TRUE(late.WaitOpen());
  late.Send(json{{"op", "call_service"}, {"service", "/rosapi/topics"}, {"id", "late"}});
  json r = late.WaitMessage([](const json& m) { return m.value("id", "") == "late"; });
  EXPECT_EQ(r.value("result", false), true) << r.dump();
}

// Out of file descriptors, websocketpp's accept loop retried at once and spun a core; partsim's
// waits 100 ms after a failed accept, so the process stays idle, and it accepts again once
// descriptors are free.
TEST_F(RosbridgeTest, OutOfFileDescriptorsTheAcceptLoopWaitsInsteadOfSpinning) {
  sim_->Pause();
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &old), 0);
  int open_fds = 0;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) {
    (void)e;
    ++open_fds;
  }
  rlimit low = old;
  low.rlim_cur = static_cast<rlim_t>(open_fds + 16);
  ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &low), 0);
  std::vector<int> socks;
  for (int i = 0; i < 64; ++i) {  // bounded: 64 loopback connections at most
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) break;
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(port_));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a));
    socks.push_back(fd);
  }
  const bool failed = WaitFor([&] { return bridge_->GetStats().accept_errors > 0; });
  rusage r0{}, r1{};
  getrusage(RUSAGE_SELF, &r0);
  std::this_thread::sleep_for(500ms);
  getrusage(RUSAGE_SELF, &r1);
  for (int fd : socks) ::close(fd);
  setrlimit(RLIMIT_NOFILE, &old);
  ASSERT_TRUE(failed) << "the descriptors never ran out (" << socks.size() << " sockets)";
  auto secs = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  const double cpu = secs(r1.ru_utime) - secs(r0.ru_utime) + secs(r1.ru_stime) - secs(r0.ru_stime);
  EXPECT_LT(cpu, 0.25) << "CPU seconds in 0.5 s out of descriptors";  // spinning: about 0.5
  EXPECT_LT(bridge_->GetStats().accept_errors, 20);
  TestClient c(port_);
  EXPECT_TRUE(c.WaitOpen());
  sim_->Resume();
}

TEST_F(RosbridgeTest, ClientThatNeverReadsDoesNotStallOthers) {
  RawSocket sleeper(port_);
  ASSERT_TRUE(sleeper.Ok());
  for (const char* t : {"/clock", "/joint_states", "/tf"})
    sleeper.SendText(json{{"op", "subscribe"}, {"topic", t}}.dump());
  auto watcher = ClockWatcher();
  // two seconds of simulated time pass for the reader while the sleeper's queue overflows
  EXPECT_TRUE(ClockAdvances(*watcher, 2.0));
  EXPECT_TRUE(WaitFor([&] { return bridge_->GetStats().messages_dropped > 0; }));
}

/// Decodes padded base64.
std::vector<uint8_t> DecodeBase64(const std::string& s) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::vector<uint8_t> out;
  uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    int v = val(c);
    if (v < 0) break;  // '=' padding
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<uint8_t>((acc >> bits) & 0xff));
    }
  }
  return out;
}

/// Whether `c` sees the clock advance by at least `seconds` of simulated time.
bool ClockMoves(TestClient& c, double seconds) {
  const double t0 = c.LastClock();
  return WaitFor([&] { return c.LastClock() > t0 + seconds; });
}

/// A flying gripper in front of a camera, with an IMU on its hand, behind a rosbridge server.
class RosbridgeSensorTest : public ::testing::Test {
 protected:
  void Start(int width, int height, double camera_rate, RosbridgeOptions o = RosbridgeOptions()) {
    scene_ = std::make_unique<Scene>();
    scene_->AddGround(0);
    RobotModel m = BuildFlyingGripper();
    m.articulation.root_pose = Pose(Eigen::Vector3d(0, 0, 0.5));
    robot_ = scene_->AddArticulation(m.articulation);
    SetAmbientLight(*scene_, Eigen::Vector3f(0.35f, 0.35f, 0.35f));
    AddDirectionalLight(*scene_, Eigen::Vector3d(-1, -0.5, -1), Eigen::Vector3f(0.8f, 0.8f, 0.8f));
    camera_ = AddCamera(*scene_, "cam", width, height, 1.0, 0.05, 20.0);
    camera_.SetLocalPose(CameraLookAt(Eigen::Vector3d(1.2, -0.8, 1.0), Eigen::Vector3d(0, 0, 0.4)));
    loop_ = std::make_unique<ControlLoop>(scene_.get());
    sim_ = std::make_unique<SimServer>(scene_.get(), loop_.get());
    ServedRobotOptions so;
    so.camera_rate = camera_rate;
    so.imu_link = m.ee_link;
    served_ = std::make_unique<ServedRobot>(sim_.get(), scene_.get(), loop_.get(), robot_,
                                            robot_.GetName(), so);
    o.port = 0;
    bridge_ = std::make_unique<RosbridgeServer>(served_.get(), o);
    bridge_->Start();
    sim_->Start();
    port_ = bridge_->GetPort();
  }
  void TearDown() override {
    if (sim_) sim_->Stop();
    if (bridge_) bridge_->Stop();
  }
  static json Published(TestClient& c, const std::string& topic) {
    return c.WaitMessage(
        [&](const json& m) { return m.value("op", "") == "publish" && m["topic"] == topic; });
  }
  std::unique_ptr<Scene> scene_;
  Articulation robot_;
  Camera camera_;
  std::unique_ptr<ControlLoop> loop_;
  std::unique_ptr<SimServer> sim_;
  std::unique_ptr<ServedRobot> served_;
  std::unique_ptr<RosbridgeServer> bridge_;
  int port_ = 0;
};

TEST_F(RosbridgeSensorTest, ImageCameraInfoAndPoints) {
  Start(160, 120, 10);
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "call_service"}, {"service", "/rosapi/topics"}, {"id", "t"}});
  json topics = c.WaitMessage([](const json& m) { return m.value("id", "") == "t"; });
  ASSERT_FALSE(topics.is_null());
  std::set<std::string> names(topics["values"]["topics"].begin(), topics["values"]["topics"].end());
  for (const char* t : {"/cam/image_raw", "/cam/camera_info", "/cam/points", "/imu"})
    EXPECT_TRUE(names.count(t)) << t;
  for (const char* t : {"/cam/image_raw", "/cam/camera_info", "/cam/points"})
    c.Send(json{{"op", "subscribe"}, {"topic", t}});

  json image = Published(c, "/cam/image_raw");
  ASSERT_FALSE(image.is_null());
  const json& im = image["msg"];
  EXPECT_EQ(im["width"], 160);
  EXPECT_EQ(im["height"], 120);
  EXPECT_EQ(im["step"], 160 * 3);
  EXPECT_EQ(im["encoding"], "rgb8");
  std::vector<uint8_t> rgb = DecodeBase64(im["data"].get<std::string>());
  ASSERT_EQ(rgb.size(), 160u * 120u * 3u);
  std::set<uint32_t> colours;
  for (size_t i = 0; i < rgb.size(); i += 3)
    colours.insert((uint32_t(rgb[i]) << 16) | (uint32_t(rgb[i + 1]) << 8) | rgb[i + 2]);
  EXPECT_GT(colours.size(), 10u);

  json info = Published(c, "/cam/camera_info");
  ASSERT_FALSE(info.is_null());
  Eigen::Matrix3d K = camera_.GetIntrinsicMatrix();
  ASSERT_EQ(info["msg"]["K"].size(), 9u);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(info["msg"]["K"][3 * r + k].get<double>(), K(r, k), 1e-9);
  EXPECT_EQ(info["msg"]["P"].size(), 12u);
  EXPECT_EQ(info["msg"]["distortion_model"], "plumb_bob");
  EXPECT_EQ(info["msg"]["width"], 160);
  EXPECT_EQ(info["msg"]["height"], 120);

  json points = Published(c, "/cam/points");
  ASSERT_FALSE(points.is_null());
  const json& pc = points["msg"];
  ASSERT_EQ(pc["fields"].size(), 3u);
  const char* field_names[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(pc["fields"][k]["name"], field_names[k]);
    EXPECT_EQ(pc["fields"][k]["offset"], 4 * k);
    EXPECT_EQ(pc["fields"][k]["datatype"], 7);  // FLOAT32
    EXPECT_EQ(pc["fields"][k]["count"], 1);
  }
  EXPECT_EQ(pc["point_step"], 12);
  EXPECT_EQ(pc["is_bigendian"], false);
  std::vector<uint8_t> bytes = DecodeBase64(pc["data"].get<std::string>());
  const size_t n = pc["width"].get<size_t>() * pc["height"].get<size_t>();
  ASSERT_EQ(bytes.size(), n * 12);
  EXPECT_EQ(pc["row_step"].get<size_t>(), pc["width"].get<size_t>() * 12);
  size_t in_front = 0;
  for (size_t i = 0; i < n; ++i) {
    float p[3];
    std::memcpy(p, bytes.data() + 12 * i, 12);
    if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && p[2] > 0.05f &&
        p[2] < 20.f)
      ++in_front;  // optical frame: z forward
  }
  EXPECT_GT(in_front, 1000u);
}

// fragment_size below kMinFragmentSize (1024) is raised to it: pieces of one character once
// made a point cloud a hundred times its size.
TEST_F(RosbridgeSensorTest, SmallFragmentSizesAreRaisedAndThePiecesRebuildTheMessage) {
  Start(32, 24, 10);
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "subscribe"}, {"topic", "/cam/image_raw"}, {"fragment_size", 64}});
  // the pieces of one message: same id, num 0..total-1, all but the last 1024 characters
  json first = c.WaitMessage([](const json& m) { return m.value("op", "") == "fragment"; });
  ASSERT_FALSE(first.is_null());
  const std::string id = first["id"];
  const size_t total = first["total"];
  ASSERT_GT(total, 1u);
  std::vector<std::string> pieces(total);
  ASSERT_TRUE(WaitFor([&] {
    size_t got = 0;
    for (const json& m : c.Messages())
      if (m.value("op", "") == "fragment" && m["id"] == id) {
        pieces[m["num"].get<size_t>()] = m["data"];
        ++got;
      }
    return got == total;
  }));
  std::string text;
  for (size_t i = 0; i < total; ++i) {
    if (i + 1 < total) EXPECT_EQ(pieces[i].size(), 1024u) << i;
    EXPECT_LE(pieces[i].size(), 1024u) << i;
    text += pieces[i];
  }
  json whole = json::parse(text, nullptr, false);
  ASSERT_FALSE(whole.is_discarded()) << text;
  EXPECT_EQ(whole["topic"], "/cam/image_raw");
  EXPECT_EQ(DecodeBase64(whole["msg"]["data"].get<std::string>()).size(), 32u * 24u * 3u);
}

/// Options with a small byte bound per client, so that a client that never reads reaches it
/// within a second.
RosbridgeOptions SmallClientBuffer() {
  RosbridgeOptions o;
  o.max_client_buffered = 256u << 10;
  return o;
}

// A subscriber asking for a point cloud in one-character pieces and reading nothing once queued
// 3.65 GB: a message's fragments went to the socket whatever their number. Now the pieces are
// at least 1024 characters and a message goes whole only while the queue is within its bound.
TEST_F(RosbridgeSensorTest, FragmentsForAClientThatNeverReadsStayWithinItsByteBound) {
  const RosbridgeOptions o = SmallClientBuffer();
  Start(160, 120, 50, o);
  RawSocket sleeper(port_);
  ASSERT_TRUE(sleeper.Ok());
  sleeper.SendText(
      json{{"op", "subscribe"}, {"topic", "/cam/points"}, {"fragment_size", 1}}.dump());
  TestClient watcher(port_);
  ASSERT_TRUE(watcher.WaitOpen());
  watcher.Send(json{{"op", "subscribe"}, {"topic", "/clock"}});
  EXPECT_TRUE(WaitFor([&] { return bridge_->GetStats().messages_dropped > 0; }));
  EXPECT_TRUE(ClockMoves(watcher, 1.0));
  const RosbridgeStats s = bridge_->GetStats();
  // a cloud of 160x120 points is at most 307 kB of base64 (410 kB with its fragments' framing)
  EXPECT_GT(s.peak_buffered_bytes, 0);
  EXPECT_LE(s.peak_buffered_bytes, static_cast<long long>(o.max_client_buffered + (1u << 20)));
}

// One client subscribed to every topic, images in small pieces, point clouds whole, reading
// nothing: its queue stays within its bound plus a message, and another client's clock flows.
TEST_F(RosbridgeSensorTest, ClientSubscribedToEverythingThatNeverReadsStaysWithinItsBound) {
  const RosbridgeOptions o = SmallClientBuffer();
  Start(160, 120, 50, o);
  RawSocket sleeper(port_);
  ASSERT_TRUE(sleeper.Ok());
  for (const char* t : {"/clock", "/joint_states", "/tf", "/imu", "/cam/camera_info"})
    sleeper.SendText(json{{"op", "subscribe"}, {"topic", t}}.dump());
  sleeper.SendText(
      json{{"op", "subscribe"}, {"topic", "/cam/image_raw"}, {"fragment_size", 1}}.dump());
  sleeper.SendText(json{{"op", "subscribe"}, {"topic", "/cam/points"}}.dump());
  TestClient watcher(port_);
  ASSERT_TRUE(watcher.WaitOpen());
  watcher.Send(json{{"op", "subscribe"}, {"topic", "/clock"}});
  ASSERT_TRUE(WaitFor([&] { return watcher.LastClock() >= 0; }));
  EXPECT_TRUE(WaitFor([&] { return bridge_->GetStats().messages_dropped > 0; }));
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(ClockMoves(watcher, 0.5)) << k;
  const RosbridgeStats s = bridge_->GetStats();
  EXPECT_GT(s.peak_buffered_bytes, 0);
  EXPECT_LE(s.peak_buffered_bytes, static_cast<long long>(o.max_client_buffered + (1u << 20)));
}

TEST_F(RosbridgeSensorTest, CborSubscriptionsCarryBytesNotBase64) {
  Start(64, 48, 0);
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "subscribe"}, {"topic", "/cam/image_raw"}, {"compression", "cbor"}});
  c.Send(json{{"op", "subscribe"},
              {"topic", "/joint_states"},
              {"compression", "cbor"},
              {"throttle_rate", 100}});
  json image = c.WaitMessage([](const json& m) {
    return m.value("cbor", false) && m.value("topic", "") == "/cam/image_raw";
  });
  ASSERT_FALSE(image.is_null());
  ASSERT_TRUE(image["msg"]["data"].is_binary()) << "uint8[] is a CBOR byte string";
  EXPECT_EQ(image["msg"]["data"].get_binary().size(), 64u * 48u * 3u);
  EXPECT_EQ(image["msg"]["width"], 64);
  EXPECT_EQ(image["msg"]["encoding"], "rgb8");
  json js = c.WaitMessage([](const json& m) {
    return m.value("cbor", false) && m.value("topic", "") == "/joint_states";
  });
  ASSERT_FALSE(js.is_null());
  EXPECT_EQ(js["op"], "publish");
  EXPECT_EQ(js["msg"]["position"].size(), static_cast<size_t>(robot_.Dof()));
  // an unknown compression is refused, naming it
  c.Send(json{{"op", "subscribe"}, {"topic", "/imu"}, {"compression", "zip"}, {"id", "z"}});
  json e = c.WaitMessage([](const json& m) { return m.value("id", "") == "z"; });
  ASSERT_TRUE(IsError(e)) << e.dump();
  EXPECT_NE(e["msg"].get<std::string>().find("'zip'"), std::string::npos) << e["msg"];
}

TEST_F(RosbridgeSensorTest, ImuAtRestReadsGravity) {
  Start(32, 24, 10);
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  // let the hand settle under its position controller for 0.5 s of simulated time
  ASSERT_TRUE(WaitFor([&] { return sim_->GetClockSteps() >= 250; }));
  c.Send(json{{"op", "subscribe"}, {"topic", "/imu"}, {"throttle_rate", 50}});
  ASSERT_TRUE(WaitFor([&] {
    int n = 0;
    for (const json& m : c.Messages()) n += m.value("topic", "") == "/imu";
    return n >= 5;
  }));
  json last;
  for (const json& m : c.Messages())
    if (m.value("topic", "") == "/imu") last = m["msg"];
  const json& a = last["linear_acceleration"];
  const double g = std::sqrt(a["x"].get<double>() * a["x"].get<double>() +
                             a["y"].get<double>() * a["y"].get<double>() +
                             a["z"].get<double>() * a["z"].get<double>());
  EXPECT_NEAR(g, 9.81, 0.3);
  const json& q = last["orientation"];
  EXPECT_NEAR(
      q["x"].get<double>() * q["x"].get<double>() + q["y"].get<double>() * q["y"].get<double>() +
          q["z"].get<double>() * q["z"].get<double>() + q["w"].get<double>() * q["w"].get<double>(),
      1.0, 1e-6);
  EXPECT_EQ(last["orientation_covariance"].size(), 9u);
}

TEST_F(RosbridgeSensorTest, PublishingToSensorTopicsIsRefusedAndNothingComesUnasked) {
  Start(32, 24, 10);
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.Send(
      json{{"op", "publish"}, {"topic", "/cam/image_raw"}, {"msg", json::object()}, {"id", "p"}});
  json err = c.WaitMessage([](const json& m) { return m.value("id", "") == "p"; });
  EXPECT_TRUE(IsError(err));
  std::this_thread::sleep_for(300ms);
  for (const json& m : c.Messages()) EXPECT_NE(m.value("op", ""), "publish");
}

/// The /tf transform of `child` in the first /tf message that `c` kept (null if none).
json TfTransform(TestClient& c, const std::string& child) {
  json found;
  c.WaitMessage([&](const json& m) {
    if (m.value("topic", "") != "/tf") return false;
    for (const json& t : m["msg"]["transforms"])
      if (t["child_frame_id"] == child) found = t;
    return true;
  });
  return found;
}

TEST_F(RosbridgeSensorTest, TfHoldsTheCameraOpticalFrameAndEveryLink) {
  Start(32, 24, 10);
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.KeepTf();
  c.Send(json{{"op", "subscribe"}, {"topic", "/tf"}});
  json t = TfTransform(c, "cam_optical_frame");
  ASSERT_FALSE(t.is_null());
  EXPECT_EQ(t["header"]["frame_id"], "world");
  const json& p = t["transform"]["translation"];
  EXPECT_NEAR(p["x"].get<double>(), 1.2, 1e-9);
  EXPECT_NEAR(p["y"].get<double>(), -0.8, 1e-9);
  EXPECT_NEAR(p["z"].get<double>(), 1.0, 1e-9);
  for (const Link& l : robot_.GetLinks()) EXPECT_FALSE(TfTransform(c, l.GetName()).is_null());
}

TEST_F(RosbridgeSensorTest, TfCameraOpticalFrameLooksAlongTheViewWithYDown) {
  Start(32, 24, 10);
  TestClient c(port_);
  ASSERT_TRUE(c.WaitOpen());
  c.KeepTf();
  c.Send(json{{"op", "subscribe"}, {"topic", "/tf"}});
  json t = TfTransform(c, "cam_optical_frame");
  ASSERT_FALSE(t.is_null());
  const json& q = t["transform"]["rotation"];
  const Eigen::Quaterniond rot(q["w"].get<double>(), q["x"].get<double>(), q["y"].get<double>(),
                               q["z"].get<double>());
  const Eigen::Vector3d eye(1.2, -0.8, 1.0), target(0, 0, 0.4);
  const Eigen::Vector3d z = rot * Eigen::Vector3d::UnitZ(), y = rot * Eigen::Vector3d::UnitY();
  EXPECT_LT((z - (target - eye).normalized()).norm(), 1e-6) << z.transpose();
  const Eigen::Vector3d up = CameraLookAt(eye, target).q * Eigen::Vector3d::UnitZ();
  EXPECT_LT((y + up).norm(), 1e-6) << y.transpose();
}

}  // namespace
}  // namespace partsim
