// RosbridgeServer under faults: malformed JSON, unknown ops, wrong types, a huge message, a
// client that vanishes mid-frame, 50 clients at once, and a client that never reads. Clients are
// websocketpp's own client and raw TCP sockets.
#include "partsim/server/rosbridge.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include "partsim/robot/robots.h"
#include "server/wait_for.h"

namespace partsim {
namespace {

using json = nlohmann::json;
using namespace std::chrono_literals;
using WsClient = websocketpp::client<websocketpp::config::asio_client>;

using testing::WaitFor;

/// A WebSocket client on its own thread that keeps every message it receives.
class TestClient {
 public:
  explicit TestClient(int port) {
    c_.clear_access_channels(websocketpp::log::alevel::all);
    c_.clear_error_channels(websocketpp::log::elevel::all);
    c_.init_asio();
    c_.set_open_handler([this](websocketpp::connection_hdl) { open_ = true; });
    c_.set_close_handler([this](websocketpp::connection_hdl h) {
      close_code_ = c_.get_con_from_hdl(h)->get_remote_close_code();
      closed_ = true;
    });
    c_.set_fail_handler([this](websocketpp::connection_hdl) { closed_ = true; });
    c_.set_message_handler([this](websocketpp::connection_hdl, WsClient::message_ptr m) {
      // published messages are counted (the clock and the last joint state kept); the others
      // are kept whole
      const std::string& text = m->get_payload();
      const size_t at = text.rfind("\"topic\":\"");
      const std::string topic = at == std::string::npos ? "" : text.substr(at + 9);
      std::lock_guard<std::mutex> lock(mutex_);
      if (topic.rfind("/tf\"", 0) == 0) {
        ++tf_count_;
      } else if (topic.rfind("/clock\"", 0) == 0) {
        json j = json::parse(text, nullptr, false);
        last_clock_ = j["msg"]["clock"]["secs"].get<double>() +
                      1e-9 * j["msg"]["clock"]["nsecs"].get<double>();
      } else if (topic.rfind("/joint_states\"", 0) == 0) {
        if (keep_joint_states_) messages_.push_back(json::parse(text, nullptr, false));
      } else {
        messages_.push_back(json::parse(text, nullptr, false));
      }
    });
    websocketpp::lib::error_code ec;
    con_ = c_.get_connection("ws://127.0.0.1:" + std::to_string(port), ec);
    c_.connect(con_);
    thread_ = std::thread([this] { c_.run(); });
  }
  ~TestClient() {
    websocketpp::lib::error_code ec;
    if (open_ && !closed_) c_.close(con_->get_handle(), websocketpp::close::status::normal, "", ec);
    WaitFor([this] { return closed_.load(); });
    c_.stop();
    thread_.join();
  }
  bool WaitOpen() {
    return WaitFor([this] { return open_.load() || closed_.load(); }) && open_;
  }
  void Send(const std::string& text) {
    websocketpp::lib::error_code ec;
    c_.send(con_->get_handle(), text, websocketpp::frame::opcode::text, ec);
  }
  void Send(const json& j) { Send(j.dump()); }
  std::vector<json> Messages() {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }
  /// Waits for a message satisfying `pred`; returns it (null if none came).
  template <class F>
  json WaitMessage(F pred) {
    json found;
    WaitFor([&] {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const json& m : messages_)
        if (pred(m)) {
          found = m;
          return true;
        }
      return false;
    });
    return found;
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
  /// Keep /joint_states messages (set before subscribing).
  void KeepJointStates() { keep_joint_states_ = true; }
  bool Closed() const { return closed_; }
  int CloseCode() const { return close_code_; }

 private:
  WsClient c_;
  WsClient::connection_ptr con_;
  std::thread thread_;
  std::mutex mutex_;
  std::vector<json> messages_;
  double last_clock_ = -1;
  long long tf_count_ = 0;
  std::atomic<bool> keep_joint_states_{false};
  std::atomic<bool> open_{false}, closed_{false};
  std::atomic<int> close_code_{0};
};

bool IsError(const json& m) {
  return m.value("op", "") == "status" && m.value("level", "") == "error";
}

/// A raw TCP connection that performs the WebSocket handshake and writes frames by hand.
class RawSocket {
 public:
  explicit RawSocket(int port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ok_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0;
    int small = 4096;  // a small receive buffer so that the server's writes back up
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &small, sizeof(small));
    std::string req =
        "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
    Write(req);
    // read the handshake response only
    std::string resp;
    char ch;
    while (resp.find("\r\n\r\n") == std::string::npos && ::read(fd_, &ch, 1) == 1) resp += ch;
    ok_ = ok_ && resp.find(" 101 ") != std::string::npos;
  }
  ~RawSocket() { Close(); }
  bool Ok() const { return ok_; }
  void Write(const std::string& bytes) {
    size_t off = 0;
    while (off < bytes.size()) {
      ssize_t n = ::send(fd_, bytes.data() + off, bytes.size() - off, MSG_NOSIGNAL);
      if (n <= 0) return;
      off += static_cast<size_t>(n);
    }
  }
  /// Header of a masked text frame (mask 0, so the payload goes as it is) of `len` bytes.
  static std::string FrameHeader(size_t len) {
    std::string h;
    h += static_cast<char>(0x81);
    if (len < 126) {
      h += static_cast<char>(0x80 | len);
    } else {
      h += static_cast<char>(0x80 | 126);
      h += static_cast<char>((len >> 8) & 0xff);
      h += static_cast<char>(len & 0xff);
    }
    h += std::string(4, '\0');
    return h;
  }
  void SendText(const std::string& text) { Write(FrameHeader(text.size()) + text); }
  void Close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
  bool ok_ = false;
};

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
    RosbridgeOptions o;
    o.port = 0;
    bridge_ = std::make_unique<RosbridgeServer>(sim_.get(), scene_.get(), loop_.get(), robot_,
                                                robot_.GetName(), o);
    bridge_->Start();
    sim_->Start();
    port_ = bridge_->GetPort();
  }
  void TearDown() override {
    sim_->Stop();
    bridge_->Stop();
  }
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
  std::this_thread::sleep_for(50ms);
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
  std::this_thread::sleep_for(50ms);
  const long long n = sim_->GetClockSteps();
  c.Send(json{{"op", "call_service"}, {"service", "/partsim/step"}, {"args", {{"n", 25}}}});
  EXPECT_TRUE(WaitFor([&] { return sim_->GetClockSteps() == n + 25; }));
  std::this_thread::sleep_for(50ms);
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

TEST_F(RosbridgeTest, HugeMessageIsRejectedAndServerStaysUp) {
  auto watcher = ClockWatcher();
  TestClient big(port_);
  ASSERT_TRUE(big.WaitOpen());
  std::string payload = "{\"op\":\"publish\",\"topic\":\"/x\",\"msg\":{\"data\":\"" +
                        std::string(20u << 20, 'a') + "\"}}";
  big.Send(payload);
  EXPECT_TRUE(WaitFor([&] { return big.Closed(); }));
  EXPECT_EQ(big.CloseCode(), 1009);  // "message too big"
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

}  // namespace
}  // namespace partsim
