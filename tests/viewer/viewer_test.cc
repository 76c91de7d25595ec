// The browser viewer's server against real clients on loopback: HTTP requests over a plain
// socket, websocketpp's WebSocket client. The scene is a generated PartNet-Mobility cabinet on a
// ground with a box falling onto it, viewed in synchronous mode (Render on the test's thread or
// on one thread it starts) and in served mode (a SimServer).
#include "partsim/viewer/viewer.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include "partsim/assets/generator.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/core/log.h"
#include "partsim/physics/observer.h"
#include "partsim/physics/scene.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/image_read.h"
#include "partsim/render/scene_render.h"
#include "partsim/server/sim_server.h"
#include "server/wait_for.h"
#include "server/ws_test_client.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using WsClient = testing::WsTestClient::Client;
using testing::WaitFor;

struct HttpReply {
  int status = 0;
  std::string body;
};

/// GET `path` from 127.0.0.1:port with extra header lines ("Name: value\r\n").
HttpReply HttpGet(int port, const std::string& path, const std::string& headers = "") {
  HttpReply r;
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  timeval tv{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
    close(fd);
    return r;
  }
  const std::string req = "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n" + headers + "\r\n";
  send(fd, req.data(), req.size(), 0);
  std::string all;
  char buf[65536];
  while (true) {
    const ssize_t n = recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) break;
    all.append(buf, static_cast<size_t>(n));
    // the whole body once Content-Length bytes have come
    const size_t head = all.find("\r\n\r\n");
    const size_t len = all.find("Content-Length: ");
    if (head != std::string::npos && len != std::string::npos && len < head &&
        all.size() >= head + 4 + std::stoul(all.substr(len + 16)))
      break;
  }
  close(fd);
  if (all.size() > 12) r.status = std::stoi(all.substr(9, 3));
  const size_t head = all.find("\r\n\r\n");
  if (head != std::string::npos) r.body = all.substr(head + 4);
  return r;
}

std::string Base64Decode(const std::string& in) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::string out;
  int bits = 0, acc = 0;
  for (char c : in) {
    const int v = value(c);
    if (v < 0) continue;
    acc = (acc << 6) | v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((acc >> bits) & 255));
    }
  }
  return out;
}

/// A WebSocket client on its own thread that keeps every message it receives.
class TestClient {
 public:
  explicit TestClient(int port, const std::string& origin = "")
      : ws_(
            port, origin,
            [this](const WsClient::message_ptr& m) {
              log_.Add(json::parse(m->get_payload(), nullptr, false));
            },
            "/") {}
  bool WaitOpen() { return ws_.WaitOpen(); }
  void Send(const std::string& text) { ws_.Send(text); }
  void Send(const json& j) { Send(j.dump()); }
  void Auth(const std::string& token) {
    Send(json{{"op", "auth"}, {"mac", token}});
    ASSERT_FALSE(
        WaitMessage([](const json& m) { return m.value("msg", "") == "authenticated"; }).is_null());
  }
  std::vector<json> Messages() { return log_.All(); }
  /// Waits for a message satisfying `pred` (up to 30 s, WaitFor); returns it, or null.
  template <class F>
  json WaitMessage(F pred) {
    return log_.Wait(pred);
  }
  /// The answer to call `id`.
  json WaitReply(const std::string& id) {
    return WaitMessage([&](const json& m) { return m.value("id", "") == id; });
  }
  void Clear() { log_.Clear(); }
  bool Closed() const { return ws_.Closed(); }
  int CloseCode() const { return ws_.CloseCode(); }

 private:
  testing::MessageLog log_;
  testing::WsTestClient ws_;  // last: its thread stops before the members above go
};

json Call(const std::string& service, const json& args, const std::string& id) {
  return {{"op", "call_service"}, {"service", service}, {"args", args}, {"id", id}};
}

/// Renders on this thread (synchronous mode runs the page's calls there) until `c` has the
/// answer to call `id`, for up to 30 s; returns it (null if none came).
json RenderUntilReply(Viewer& v, TestClient& c, const std::string& id) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline) {
    v.Render();
    for (const json& m : c.Messages())
      if (m.value("id", "") == id) return m;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return json();
}

/// Waits until the simulation thread has run a command posted now: the step under way (if any)
/// is over, and a paused server takes no step of its own after it.
void WaitBetweenSteps(SimServer& sim) {
  auto ran = std::make_shared<std::atomic<bool>>(false);
  sim.Post([ran] { *ran = true; });
  ASSERT_TRUE(WaitFor([&] { return ran->load(); })) << "a command did not run within 30 s";
}

class ViewerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SetLogLevel(LogLevel::kError);
    dir_ = fs::temp_directory_path() /
           ("partsim_viewer_test_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    WriteObject(GenerateObject("StorageFurniture", 0, 7), (dir_ / "cabinet").string());
    scene_ = std::make_unique<Scene>();
    scene_->AddGround(0.0);
    PartNetMobilityLoader loader(scene_.get());
    loader.urdf.fix_root_link = true;
    cabinet_ = loader.Load((dir_ / "cabinet").string());
    PlaceOnGround(cabinet_);  // its parts clear the ground
    auto box = scene_->CreateActorBuilder();
    box.AddBoxCollision(Pose(), Eigen::Vector3d(0.05, 0.05, 0.05));
    box.AddBoxVisual(Pose(), Eigen::Vector3d(0.05, 0.05, 0.05));
    box.SetInitialPose(Pose(Eigen::Vector3d(2, 0, 1)));
    box.SetName("falling_box");
    box_ = box.Build();
  }
  void TearDown() override {
    viewer_.reset();
    std::error_code ec;
    fs::remove_all(dir_, ec);
    SetLogLevel(LogLevel::kWarning);
  }
  Viewer& Start(const ViewerOptions& o = {}) {
    viewer_ = std::make_unique<Viewer>(scene_.get(), o);
    viewer_->Start();
    return *viewer_;
  }
  std::string Api(const std::string& path) { return path + "?token=" + viewer_->GetToken(); }
  json SceneJson() {
    HttpReply r = HttpGet(viewer_->GetPort(), Api("/api/scene.json"));
    EXPECT_EQ(r.status, 200) << r.body;
    return json::parse(r.body, nullptr, false);
  }
  /// The first joint of the cabinet with a dof.
  Joint MovableJoint() {
    for (const Joint& j : cabinet_.GetActiveJoints())
      if (std::isfinite(j.GetLimits()[0]) && std::isfinite(j.GetLimits()[1])) return j;
    ADD_FAILURE() << "the cabinet has no limited joint";
    return {};
  }

  fs::path dir_;
  std::unique_ptr<Scene> scene_;
  Articulation cabinet_;
  Actor box_;
  std::unique_ptr<Viewer> viewer_;
};

TEST_F(ViewerTest, SceneJsonDescribesEveryBodyJointAndLabel) {
  Start();
  const json j = SceneJson();
  const std::vector<VisualBody> bodies = GetVisualBodies(*scene_);
  ASSERT_EQ(j["bodies"].size(), bodies.size());
  EXPECT_EQ(j["poses"].size(), 7 * bodies.size());
  size_t labelled = 0;
  for (size_t i = 0; i < bodies.size(); ++i) {
    EXPECT_EQ(j["bodies"][i]["name"], bodies[i].name);
    EXPECT_EQ(j["bodies"][i]["label"], bodies[i].semantic_label);
    EXPECT_EQ(j["bodies"][i]["visuals"].size(), bodies[i].visuals.size());
    labelled += !bodies[i].semantic_label.empty();
  }
  EXPECT_GT(labelled, 1u);  // the cabinet's parts carry PartNet labels
  ASSERT_EQ(j["articulations"].size(), 1u);
  const json& art = j["articulations"][0];
  EXPECT_EQ(art["dof"], cabinet_.Dof());
  ASSERT_EQ(art["joints"].size(), cabinet_.GetJoints().size());
  for (size_t k = 0; k < art["joints"].size(); ++k) {
    const Joint joint = cabinet_.GetJoints()[k];
    const json& jj = art["joints"][k];
    EXPECT_EQ(jj["name"], joint.GetName());
    EXPECT_EQ(jj["dof_index"], joint.GetDofIndex());
    if (joint.GetDofIndex() >= 0 && std::isfinite(joint.GetLimits()[1])) {
      EXPECT_DOUBLE_EQ(jj["lower"].get<double>(), joint.GetLimits()[0]);
      EXPECT_DOUBLE_EQ(jj["upper"].get<double>(), joint.GetLimits()[1]);
    }
    // the child body is the joint's child link
    EXPECT_EQ(j["bodies"][jj["child"].get<int>()]["name"], joint.GetChildLink().GetName());
  }
  // the falling box's pose is where it starts
  const json& poses = j["poses"];
  EXPECT_NEAR(poses[7 * 1 + 2].get<double>(), 1.0, 1e-9);
  EXPECT_TRUE(j["initial_camera"].is_null());
}

TEST_F(ViewerTest, MeshBinaryDecodesToTheVisualsVertexCount) {
  Start();
  const json j = SceneJson();
  const std::vector<VisualBody> bodies = GetVisualBodies(*scene_);
  int checked = 0;
  for (size_t i = 0; i < bodies.size(); ++i)
    for (size_t v = 0; v < bodies[i].visuals.size(); ++v) {
      const VisualShape& shape = bodies[i].visuals[v];
      if (shape.type != ShapeType::kConvexMesh || checked >= 5) continue;
      const int k = j["bodies"][i]["visuals"][v]["mesh"];
      HttpReply r = HttpGet(viewer_->GetPort(), Api("/api/mesh/" + std::to_string(k) + ".bin"));
      ASSERT_EQ(r.status, 200);
      ASSERT_GE(r.body.size(), 20u);
      ASSERT_EQ(r.body.substr(0, 4), "PSMH");
      uint32_t header[4];
      std::memcpy(header, r.body.data() + 4, 16);
      EXPECT_EQ(header[0], 1u);
      EXPECT_EQ(header[1], shape.mesh->vertices.size());
      EXPECT_EQ(header[2], 3 * shape.mesh->faces.size());
      const size_t n = header[1];
      const size_t floats = 3 * n + ((header[3] & 1) ? 3 * n : 0) + ((header[3] & 2) ? 2 * n : 0);
      EXPECT_EQ(r.body.size(), 20 + 4 * (floats + header[2]));
      // the first vertex as sent
      float x;
      std::memcpy(&x, r.body.data() + 20, 4);
      EXPECT_EQ(x, shape.mesh->vertices[0].x());
      ++checked;
    }
  EXPECT_GT(checked, 0);
  EXPECT_EQ(HttpGet(viewer_->GetPort(), Api("/api/mesh/99999.bin")).status, 404);
}

TEST_F(ViewerTest, ApiNeedsTheToken) {
  ViewerOptions o;
  o.auth_token = "secret-token";
  Viewer& v = Start(o);
  EXPECT_EQ(v.GetToken(), "secret-token");
  EXPECT_NE(v.GetUrl().find("?token=secret-token"), std::string::npos);
  EXPECT_EQ(HttpGet(v.GetPort(), "/api/scene.json").status, 403);
  EXPECT_EQ(HttpGet(v.GetPort(), "/api/scene.json?token=wrong").status, 403);
  EXPECT_EQ(HttpGet(v.GetPort(), "/api/mesh/0.bin").status, 403);
  EXPECT_EQ(HttpGet(v.GetPort(), "/api/scene.json?token=secret-token").status, 200);
  EXPECT_EQ(HttpGet(v.GetPort(), "/api/scene.json", "X-Partsim-Token: secret-token\r\n").status,
            200);
  // a random token when none is given
  Viewer other(scene_.get());
  EXPECT_EQ(other.GetToken().size(), 32u);
  EXPECT_NE(other.GetToken(), Viewer(scene_.get()).GetToken());
}

TEST_F(ViewerTest, BundleServesItsFilesAndRefusesPathsOutOfIt) {
  const fs::path web = dir_ / "web";
  fs::create_directories(web / "assets");
  std::ofstream(web / "index.html") << "<html>viewer page</html>";
  std::ofstream(web / "assets" / "app.js") << "console.log(1)";
  std::ofstream(web / ".hidden") << "no";
  std::ofstream(dir_ / "secret.txt") << "outside the bundle";
  ViewerOptions o;
  o.web_root = web.string();
  Viewer& v = Start(o);
  HttpReply index = HttpGet(v.GetPort(), "/");
  EXPECT_EQ(index.status, 200);
  EXPECT_NE(index.body.find("viewer page"), std::string::npos);
  EXPECT_EQ(HttpGet(v.GetPort(), "/assets/app.js").status, 200);
  EXPECT_EQ(HttpGet(v.GetPort(), "/missing.js").status, 404);
  for (const char* bad : {"/../secret.txt", "/assets/../../secret.txt", "/%2e%2e/secret.txt",
                          "/.hidden", "//secret.txt", "/assets/..%2fsecret.txt"}) {
    HttpReply r = HttpGet(v.GetPort(), bad);
    EXPECT_EQ(r.status, 400) << bad;
    EXPECT_EQ(r.body.find("outside the bundle"), std::string::npos) << bad;
  }
}

TEST_F(ViewerTest, WithoutABundleTheIndexSaysHowToBuildIt) {
  ViewerOptions o;
  o.web_root = (dir_ / "no_such_folder").string();
  Viewer& v = Start(o);
  HttpReply r = HttpGet(v.GetPort(), "/");
  EXPECT_EQ(r.status, 200);
  EXPECT_NE(r.body.find("scripts/build_web.sh"), std::string::npos);
}

TEST_F(ViewerTest, PagesOfOtherOriginsAreRefused) {
  Viewer& v = Start();
  EXPECT_EQ(HttpGet(v.GetPort(), Api("/api/scene.json"), "Origin: http://evil.example\r\n").status,
            403);
  EXPECT_EQ(
      HttpGet(v.GetPort(), Api("/api/scene.json"), "Origin: http://localhost:5173\r\n").status,
      200);
  TestClient evil(v.GetPort(), "http://evil.example");
  EXPECT_FALSE(evil.WaitOpen());
  TestClient local(v.GetPort(), "http://127.0.0.1:8000");
  EXPECT_TRUE(local.WaitOpen());
}

TEST_F(ViewerTest, WebSocketNeedsTheTokenFirst) {
  Viewer& v = Start();
  TestClient c(v.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "subscribe"}, {"topic", "/partsim/poses"}, {"id", "s"}});
  json e = c.WaitReply("s");
  EXPECT_EQ(e["level"], "error");
  EXPECT_NE(e["msg"].get<std::string>().find("authenticate first"), std::string::npos);
  TestClient wrong(v.GetPort());
  ASSERT_TRUE(wrong.WaitOpen());
  wrong.Send(json{{"op", "auth"}, {"mac", "not-the-token"}});
  EXPECT_TRUE(WaitFor([&] { return wrong.Closed(); }));
  c.Auth(v.GetToken());
}

TEST_F(ViewerTest, PosesComeAllFirstThenOnlyWhatMoved) {
  ViewerOptions o;
  o.max_rate = 1000;  // a snapshot at every Render: the test counts messages, not time
  Viewer& v = Start(o);
  TestClient c(v.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Auth(v.GetToken());
  c.Send(json{{"op", "subscribe"}, {"topic", "/partsim/poses"}});
  const size_t n = GetVisualBodies(*scene_).size();
  json first =
      c.WaitMessage([](const json& m) { return m.value("topic", "") == "/partsim/poses"; });
  ASSERT_FALSE(first.is_null());
  EXPECT_EQ(first["msg"]["ids"].size(), n);
  EXPECT_EQ(first["msg"]["poses"].size(), 7 * n);
  c.Clear();
  // the box falls; the ground and the cabinet's fixed root stay
  for (int i = 0; i < 50; ++i) {
    scene_->Step();
    v.Render();
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(WaitFor([&] { return c.Messages().size() >= 10; }));
  const int box_body = 1;  // actors come first: the ground, then the box
  for (const json& m : c.Messages()) {
    ASSERT_EQ(m["topic"], "/partsim/poses");
    const auto ids = m["msg"]["ids"].get<std::vector<int>>();
    EXPECT_LT(ids.size(), n);
    EXPECT_EQ(std::count(ids.begin(), ids.end(), 0), 0) << "the ground never moves";
    EXPECT_EQ(std::count(ids.begin(), ids.end(), box_body), 1) << "the falling box always does";
  }
  const json last = c.Messages().back()["msg"];
  const std::vector<double> poses = last["poses"];
  const auto ids = last["ids"].get<std::vector<int>>();
  const size_t at = std::find(ids.begin(), ids.end(), box_body) - ids.begin();
  EXPECT_NEAR(poses[7 * at + 2], box_.GetPose().p.z(), 1e-5);
}

TEST_F(ViewerTest, SetJointTargetDrivesTheJoint) {
  Viewer& v = Start();
  TestClient c(v.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Auth(v.GetToken());
  const Joint joint = MovableJoint();
  const double target = 0.5 * (joint.GetLimits()[0] + joint.GetLimits()[1]);
  c.Send(Call("/partsim/set_joint_target",
              {{"articulation", 0}, {"joint", joint.GetName()}, {"position", target}}, "t"));
  // synchronous mode: the answer comes once Render has applied it
  const json reply = RenderUntilReply(v, c, "t");
  ASSERT_FALSE(reply.is_null());
  EXPECT_TRUE(reply["result"].get<bool>()) << reply;
  EXPECT_TRUE(reply["values"]["success"].get<bool>());
  EXPECT_GT(joint.GetDriveStiffness(), 0);
  EXPECT_DOUBLE_EQ(joint.GetDriveTarget(), target);
  for (int i = 0; i < 1500; ++i) {
    scene_->Step();
    v.Render();
  }
  EXPECT_NEAR(joint.GetQpos(), target, 0.05 * (joint.GetLimits()[1] - joint.GetLimits()[0]));
}

TEST_F(ViewerTest, PauseBlocksRenderUntilResumedOrStepped) {
  Viewer& v = Start();
  TestClient c(v.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Auth(v.GetToken());
  c.Send(Call("/partsim/pause", json::object(), "p"));
  ASSERT_TRUE(c.WaitReply("p")["result"].get<bool>());
  EXPECT_TRUE(v.IsPaused());
  // the scene's thread: SAPIEN's loop, counting the Render calls that returned
  std::atomic<int> returned{0};
  std::atomic<bool> stop{false};
  std::thread loop([&] {
    while (!stop && !v.IsClosed()) {
      if (!v.Render(0.05)) continue;  // still paused after 50 ms
      ++returned;
      scene_->Step();
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(returned, 0) << "Render returned while paused";
  c.Send(Call("/partsim/step", {{"n", 3}}, "s"));
  ASSERT_FALSE(c.WaitReply("s").is_null());
  EXPECT_TRUE(WaitFor([&] { return returned >= 3; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(returned, 3) << "step {n: 3} returns exactly 3 times";
  c.Send(Call("/partsim/resume", json::object(), "r"));
  EXPECT_TRUE(WaitFor([&] { return returned > 50; }));
  EXPECT_FALSE(v.IsPaused());
  c.Send(Call("/partsim/close", json::object(), "c"));
  EXPECT_TRUE(WaitFor([&] { return v.IsClosed(); }));
  stop = true;
  loop.join();
}

TEST_F(ViewerTest, ExtensionsAddApiRoutesServicesAndCommandsOnTheScenesThread) {
  viewer_ = std::make_unique<Viewer>(scene_.get());
  Viewer& v = *viewer_;
  v.AddApiRoute(
      "/api/extra/",
      [](const std::string& path, ViewerHttpRespond respond) {
        if (path == "/api/extra/now") respond({200, "text/plain", "now"});
        // any other path is never answered: the route's timeout answers 503
      },
      0.3);
  std::thread::id scene_thread;
  v.AddService("/test/echo", [&](const std::string& args, ViewerServiceReply reply) {
    v.Post([&, args, reply] {
      scene_thread = std::this_thread::get_id();
      reply(true, args);
    });
  });
  v.AddService("/test/fail",
               [](const std::string&, ViewerServiceReply reply) { reply(false, "it fails"); });
  EXPECT_THROW(v.AddService("/partsim/pause", [](const std::string&, ViewerServiceReply) {}),
               Error);
  EXPECT_THROW(v.AddService("/test/echo", [](const std::string&, ViewerServiceReply) {}), Error);
  EXPECT_THROW(v.AddApiRoute("/api/mesh/", [](const std::string&, ViewerHttpRespond) {}), Error);
  EXPECT_THROW(v.AddApiRoute("/extra/", [](const std::string&, ViewerHttpRespond) {}), Error);
  v.Start();
  EXPECT_THROW(v.AddService("/test/late", [](const std::string&, ViewerServiceReply) {}), Error);

  HttpReply r = HttpGet(v.GetPort(), Api("/api/extra/now"));
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.body, "now");
  EXPECT_EQ(HttpGet(v.GetPort(), "/api/extra/now").status, 403) << "the token is checked";
  const auto t0 = std::chrono::steady_clock::now();
  r = HttpGet(v.GetPort(), Api("/api/extra/never"));
  EXPECT_EQ(r.status, 503);
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.25);
  r = HttpGet(v.GetPort(), Api("/api/nothing"));
  EXPECT_EQ(r.status, 404);
  EXPECT_NE(r.body.find("/api/extra/"), std::string::npos) << r.body;

  TestClient c(v.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Auth(v.GetToken());
  c.Send(Call("/test/echo", {{"a", 1}}, "e"));
  const json reply = RenderUntilReply(v, c, "e");  // the posted command runs in Render
  ASSERT_FALSE(reply.is_null());
  EXPECT_TRUE(reply["result"].get<bool>());
  EXPECT_EQ(reply["values"], json({{"a", 1}}));
  EXPECT_EQ(scene_thread, std::this_thread::get_id());
  c.Send(Call("/test/fail", json::object(), "f"));
  const json failed = c.WaitReply("f");
  EXPECT_FALSE(failed["result"].get<bool>());
  EXPECT_EQ(failed["values"], "/test/fail: it fails");
  c.Send(Call("/test/none", json::object(), "n"));
  EXPECT_NE(c.WaitReply("n")["values"].get<std::string>().find("/test/echo"), std::string::npos);
}

TEST_F(ViewerTest, StepWhileRunningPausesThenSteps) {
  // served mode: the SimServer pauses, then takes the n steps
  SimServer sim(scene_.get(), nullptr);
  viewer_ = std::make_unique<Viewer>(scene_.get());
  viewer_->Attach(&sim);
  viewer_->Start();
  sim.Start();
  ASSERT_TRUE(WaitFor([&] { return sim.GetClockSteps() > 10; }));
  TestClient c(viewer_->GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Auth(viewer_->GetToken());
  c.Send(Call("/partsim/step", {{"n", 7}}, "s"));
  ASSERT_FALSE(c.WaitReply("s").is_null());
  EXPECT_TRUE(sim.IsPaused());
  EXPECT_TRUE(WaitFor([&] { return sim.GetPendingSteps() == 0; }));
  WaitBetweenSteps(sim);  // the last step, taken off the count as it began, is over
  const long long at = sim.GetClockSteps();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(sim.GetClockSteps(), at) << "paused after the steps";
  sim.Stop();
  viewer_.reset();
}

TEST_F(ViewerTest, ThePageSeesTheStateTheSimulationRestsIn) {
  // served mode: snapshots (what /partsim/status and /partsim/poses tell) are taken at most
  // every 1/60 s while running, but the state a pause or the end of a /partsim/step burst leaves
  // is always taken (SimServer's rest callback; a burst of a few steps takes less than 1/60 s,
  // and its last steps were skipped before)
  SimServerOptions so;
  so.fast = false;
  SimServer sim(scene_.get(), nullptr, so);
  viewer_ = std::make_unique<Viewer>(scene_.get());
  viewer_->Attach(&sim);
  viewer_->Start();
  sim.Start();
  ASSERT_TRUE(WaitFor([&] { return sim.GetClockSteps() > 20; }));
  TestClient c(viewer_->GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Auth(viewer_->GetToken());
  c.Send(json{{"op", "subscribe"}, {"topic", "/partsim/status"}});
  auto status_at = [&](long long step) {
    return c.WaitMessage([&](const json& m) {
      return m.value("topic", "") == "/partsim/status" && m["msg"]["paused"] == true &&
             m["msg"]["step"] == step;
    });
  };
  c.Send(Call("/partsim/pause", json::object(), "p"));
  ASSERT_FALSE(c.WaitReply("p").is_null());
  WaitBetweenSteps(sim);  // the thread may finish the step it is in
  const long long paused_at = sim.GetClockSteps();
  EXPECT_FALSE(status_at(paused_at).is_null()) << "the status shows the step it paused at";
  for (int burst = 1; burst <= 5; ++burst) {
    const long long before = sim.GetClockSteps();
    const std::string id = "s" + std::to_string(burst);
    c.Send(Call("/partsim/step", {{"n", 3}}, id));
    ASSERT_FALSE(c.WaitReply(id).is_null());
    ASSERT_TRUE(WaitFor([&] { return sim.GetClockSteps() == before + 3; }));
    EXPECT_FALSE(status_at(before + 3).is_null()) << "burst " << burst;
  }
  // a pause from outside the page (a ROS client, the program) is shown too
  sim.Resume();
  ASSERT_TRUE(WaitFor([&] { return sim.GetClockSteps() > paused_at + 40; }));
  sim.Pause();
  WaitBetweenSteps(sim);
  EXPECT_FALSE(status_at(sim.GetClockSteps()).is_null()) << "paused by the program";
  sim.Stop();
  viewer_.reset();
}

TEST_F(ViewerTest, CameraServiceAnswersAPngThatDecodes) {
  Camera cam = AddCamera(*scene_, "front", 64, 48, 1.0, 0.05, 20.0);
  cam.SetLocalPose(CameraLookAt(Eigen::Vector3d(2, -2, 1.5), Eigen::Vector3d(0, 0, 0.4)));
  Viewer& v = Start();
  EXPECT_EQ(SceneJson()["cameras"][0]["name"], "front");
  TestClient c(v.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Auth(v.GetToken());
  int k = 0;
  for (const char* picture : {"Color", "Depth", "Segmentation"}) {
    const std::string id = "cam" + std::to_string(k++);
    c.Send(Call("/partsim/camera", {{"name", "front"}, {"picture", picture}}, id));
    const json reply = RenderUntilReply(v, c, id);
    ASSERT_FALSE(reply.is_null()) << picture;
    ASSERT_TRUE(reply["result"].get<bool>()) << reply;
    const fs::path png = dir_ / (id + ".png");
    std::ofstream(png, std::ios::binary) << Base64Decode(reply["values"]["png"]);
    int w = 0, h = 0;
    const std::vector<uint8_t> rgb = ReadPng(png.string(), 3, &w, &h);
    EXPECT_EQ(w, 64);
    EXPECT_EQ(h, 48);
    int lit = 0;
    for (uint8_t b : rgb) lit += b > 0;
    EXPECT_GT(lit, 100) << picture << ": the cabinet is in view";
  }
  c.Send(Call("/partsim/camera", {{"name", "nope"}}, "bad"));
  const json bad = RenderUntilReply(v, c, "bad");
  ASSERT_FALSE(bad.is_null());
  EXPECT_FALSE(bad["result"].get<bool>());
  EXPECT_NE(bad["values"].get<std::string>().find("no camera 'nope' (cameras: front)"),
            std::string::npos);
}

TEST_F(ViewerTest, BadMessagesGetErrorsAndTheViewerGoesOn) {
  ViewerOptions o;
  o.max_message_bytes = 4096;
  Viewer& v = Start(o);
  TestClient c(v.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Auth(v.GetToken());
  const Joint joint = MovableJoint();
  struct Case {
    std::string text, words;
  };
  const std::vector<Case> cases = {
      {"{not json", "malformed JSON"},
      {"[1, 2]", "no 'op'"},
      {R"({"op": "explode", "id": "x"})", "unknown op 'explode'"},
      {R"({"op": "publish", "topic": "/x", "msg": {}})", "not supported"},
      {R"({"op": "subscribe", "topic": 5})", "string 'topic'"},
      {R"({"op": "subscribe", "topic": "/tf"})", "no topic '/tf'"},
      {R"({"op": "call_service", "service": "/nope"})", "no service '/nope'"},
      {R"({"op": "call_service", "service": "/partsim/step", "args": {"n": -3}})",
       "n must be an integer"},
      {R"({"op": "call_service", "service": "/partsim/set_joint_target", "args": {"articulation": 0, "joint": ")" +
           joint.GetName() + R"(", "position": "nan"}})",
       "number 'position'"},
      {R"({"op": "call_service", "service": "/partsim/set_joint_target", "args": {"articulation": 0, "joint": ")" +
           joint.GetName() + R"(", "position": 1e999}})",
       "number overflow"},
      {R"({"op": "call_service", "service": "/partsim/set_joint_target", "args": {"articulation": "a", "joint": "j", "position": 0}})",
       "integer 'articulation'"},
      {R"({"op": "call_service", "service": "/partsim/camera", "args": {"name": "front", "picture": "Infrared"}})",
       "picture must be"},
      {R"({"op": "call_service", "service": "/partsim/pause", "args": [1]})",
       "args must be an object"},
      // hostile: nesting past the parser's bound, an id of 1e300, non-ASCII garbage in a name
      {std::string(200, '[') + std::string(200, ']'), "nested deeper than"},
      {R"({"op": "call_service", "service": "/partsim/set_joint_target", "args": {"articulation": 1e300, "joint": "j", "position": 0}})",
       "integer 'articulation'"},
      {"{\"op\": \"subscribe\", \"topic\": \"/\u00e9\u00e8\u4e2d\u6587\"}", "no topic"},
  };
  for (const Case& k : cases) {
    c.Clear();
    c.Send(k.text);
    const json e = c.WaitMessage([](const json& m) {
      return m.value("level", "") == "error" || m.value("result", true) == false;
    });
    ASSERT_FALSE(e.is_null()) << k.text;
    const std::string what = e.contains("msg") ? e["msg"].get<std::string>() : e["values"].dump();
    EXPECT_NE(what.find(k.words), std::string::npos) << k.text << " -> " << what;
  }
  // an unknown joint fails when applied, naming the joints there are
  c.Clear();
  c.Send(Call("/partsim/set_joint_target",
              {{"articulation", 0}, {"joint", "no_such_joint"}, {"position", 0}}, "j"));
  const json reply = RenderUntilReply(v, c, "j");
  ASSERT_FALSE(reply.is_null());
  EXPECT_FALSE(reply["result"].get<bool>());
  EXPECT_NE(reply["values"].get<std::string>().find("no joint 'no_such_joint'"), std::string::npos);
  EXPECT_NE(reply["values"].get<std::string>().find(joint.GetName()), std::string::npos);
  // a message over the bound closes that connection only
  c.Send(std::string(8192, ' ') + "{}");
  EXPECT_TRUE(WaitFor([&] { return c.Closed(); }));
  EXPECT_EQ(c.CloseCode(), 1009);
  TestClient after(v.GetPort());
  ASSERT_TRUE(after.WaitOpen());
  after.Auth(v.GetToken());
  EXPECT_EQ(HttpGet(v.GetPort(), Api("/api/scene.json")).status, 200);
  EXPECT_GT(v.GetStats().errors, 10);
}

TEST_F(ViewerTest, BytesThatAreNotUtf8CloseThatConnectionOnly) {
  Viewer& v = Start();
  testing::RawSocket raw(v.GetPort());
  ASSERT_TRUE(raw.Ok());
  raw.SendText("{\"op\": \"auth\", \"mac\": \"\xff\xfe\xc0\x80\"}");  // invalid UTF-8
  raw.SendText(std::string("\xff\xfe\xfd garbage \x80\x81", 14));
  for (int i = 0; i < 20; ++i) {
    scene_->Step();
    v.Render();
  }
  TestClient after(v.GetPort());
  ASSERT_TRUE(after.WaitOpen());
  after.Auth(v.GetToken());
  EXPECT_EQ(HttpGet(v.GetPort(), Api("/api/scene.json")).status, 200);
}

TEST_F(ViewerTest, ClientThatNeverReadsStallsNeitherRenderNorOthers) {
  // 300 kinematic boxes, all moved at every step: each pose message is about 20 kB
  std::vector<Actor> boxes;
  for (int k = 0; k < 300; ++k) {
    auto b = scene_->CreateActorBuilder();
    b.AddBoxVisual(Pose(), Eigen::Vector3d(0.01, 0.01, 0.01));
    b.SetInitialPose(Pose(Eigen::Vector3d(0.05 * k, 3, 0.5)));
    boxes.push_back(b.BuildKinematic());
  }
  auto move = [&](int step) {
    for (size_t k = 0; k < boxes.size(); ++k)
      boxes[k].SetPose(Pose(Eigen::Vector3d(0.05 * k, 3, 0.5 + 0.001 * (step % 100))));
    scene_->Step();
  };
  ViewerOptions o;
  o.max_rate = 1000;                 // a pose message at nearly every Render()
  o.max_client_buffered = 64 << 10;  // drops begin after 64 kB wait in the sleeper's socket
  Viewer& v = Start(o);
  testing::RawSocket sleeper(v.GetPort());  // subscribes, then reads nothing
  ASSERT_TRUE(sleeper.Ok());
  sleeper.SendText(json{{"op", "auth"}, {"mac", v.GetToken()}}.dump());
  sleeper.SendText(json{{"op", "subscribe"}, {"topic", "/partsim/poses"}}.dump());
  TestClient reader(v.GetPort());
  ASSERT_TRUE(reader.WaitOpen());
  reader.Auth(v.GetToken());
  reader.Send(json{{"op", "subscribe"}, {"topic", "/partsim/poses"}});
  double slowest = 0;
  int step = 0;
  for (; step < 5000 && v.GetStats().messages_dropped == 0; ++step) {
    move(step);
    const auto t0 = std::chrono::steady_clock::now();
    v.Render();
    slowest = std::max(
        slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  EXPECT_GT(v.GetStats().messages_dropped, 0) << "no drop after " << step << " steps";
  EXPECT_LT(slowest, 0.25) << "Render() waited for the network";
  // the reader still gets what moves after the drops began
  reader.Clear();
  for (int i = 0; i < 20; ++i) {
    move(step + i);
    v.Render();
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_FALSE(
      reader.WaitMessage([](const json& m) { return m.value("topic", "") == "/partsim/poses"; })
          .is_null());
}

// Out of file descriptors, websocketpp's accept loop retried at once and spun a core; the
// viewer's waits 100 ms after a failed accept (as the rosbridge server's does), so the process
// stays idle, and it accepts again once descriptors are free.
TEST_F(ViewerTest, OutOfFileDescriptorsTheAcceptLoopWaitsInsteadOfSpinning) {
  Viewer& v = Start();
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &old), 0);
  int open_fds = 0;
  for (const auto& e : fs::directory_iterator("/proc/self/fd")) {
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
    a.sin_port = htons(static_cast<uint16_t>(v.GetPort()));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a));
    socks.push_back(fd);
  }
  const bool failed = testing::WaitFor([&] { return v.GetStats().accept_errors > 0; });
  rusage r0{}, r1{};
  getrusage(RUSAGE_SELF, &r0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  getrusage(RUSAGE_SELF, &r1);
  for (int fd : socks) ::close(fd);
  setrlimit(RLIMIT_NOFILE, &old);
  auto secs = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  const double cpu = secs(r1.ru_utime) - secs(r0.ru_utime) + secs(r1.ru_stime) - secs(r0.ru_stime);
  EXPECT_LT(cpu, 0.25) << "CPU seconds in 0.5 s out of descriptors";  // spinning: about 0.5
  ASSERT_TRUE(failed) << "the descriptors never ran out (" << socks.size() << " sockets)";
  EXPECT_LT(v.GetStats().accept_errors, 20);
  TestClient c(v.GetPort());
  EXPECT_TRUE(c.WaitOpen());
}

// The commands a client has waiting for the scene's thread are bounded (64): 3,000 camera calls
// of one client once held another's joint command for a minute. Beyond the bound a call is
// answered at once with an error naming it, so another client's command waits behind at most
// 64 of the flooder's.
TEST_F(ViewerTest, OneClientsFloodOfCommandsDelaysAnothersByAtMostTheBound) {
  Viewer& v = Start();
  TestClient flooder(v.GetPort()), other(v.GetPort());
  ASSERT_TRUE(flooder.WaitOpen());
  ASSERT_TRUE(other.WaitOpen());
  flooder.Auth(v.GetToken());
  other.Auth(v.GetToken());
  // synchronous mode: nothing runs until Render(), so every call waits; a call of an unknown
  // service, answered on the network thread, tells when the calls before it were handled
  const int flood = 300;
  for (int k = 0; k < flood; ++k)
    flooder.Send(Call("/partsim/camera", {{"name", "no_such_camera"}}, "f" + std::to_string(k)));
  flooder.Send(Call("/partsim/no_such_service", json::object(), "flooded"));
  ASSERT_FALSE(flooder.WaitReply("flooded").is_null());
  auto refused = [&] {
    int n = 0;
    for (const json& m : flooder.Messages())
      if (m.value("op", "") == "service_response" && m.value("result", true) == false &&
          m["values"].dump().find("at most 64") != std::string::npos)
        ++n;
    return n;
  };
  EXPECT_EQ(refused(), flood - 64);
  const Joint joint = MovableJoint();
  const double target = 0.5 * (joint.GetLimits()[0] + joint.GetLimits()[1]);
  other.Send(Call("/partsim/set_joint_target",
                  {{"articulation", 0}, {"joint", joint.GetName()}, {"position", target}}, "t"));
  other.Send(Call("/partsim/no_such_service", json::object(), "sent"));
  ASSERT_FALSE(other.WaitReply("sent").is_null());
  // one Render() runs what waits: the flooder's 64 calls and the other's command
  v.Render();
  const json reply = other.WaitReply("t");
  ASSERT_FALSE(reply.is_null());
  EXPECT_TRUE(reply["result"].get<bool>()) << reply;
  EXPECT_DOUBLE_EQ(joint.GetDriveTarget(), target);
  ASSERT_TRUE(WaitFor([&] {
    int answered = 0;
    for (const json& m : flooder.Messages())
      if (m.contains("values") &&
          m["values"].dump().find("no camera 'no_such_camera'") != std::string::npos)
        ++answered;
    return answered == 64;
  }));
  // answered calls free their places: the flooder may call again
  flooder.Clear();
  flooder.Send(Call("/partsim/camera", {{"name", "no_such_camera"}}, "again"));
  flooder.Send(Call("/partsim/no_such_service", json::object(), "flooded"));
  ASSERT_FALSE(flooder.WaitReply("flooded").is_null());
  EXPECT_EQ(refused(), 0);
}

// Calls of an extension's service (the gallery's /partsim/open loads an object on the scene's
// thread) count among a client's waiting commands until answered.
TEST_F(ViewerTest, CallsOfExtraServicesWaitingForAnswersShareTheBound) {
  std::mutex held_mutex;
  std::vector<ViewerServiceReply> held;
  viewer_ = std::make_unique<Viewer>(scene_.get());
  viewer_->AddService("/test/hold", [&](const std::string&, ViewerServiceReply reply) {
    std::lock_guard<std::mutex> lock(held_mutex);
    held.push_back(reply);
  });
  viewer_->AddService("/test/throw",
                      [](const std::string&, ViewerServiceReply) { throw Error("thrown"); });
  Viewer& v = *viewer_;
  v.Start();
  TestClient c(v.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Auth(v.GetToken());
  // a service that throws gives its place back
  for (int k = 0; k < 100; ++k)
    c.Send(Call("/test/throw", json::object(), "t" + std::to_string(k)));
  for (int k = 0; k < 70; ++k) c.Send(Call("/test/hold", json::object(), "h" + std::to_string(k)));
  c.Send(Call("/partsim/camera", {{"name", "front"}}, "camera"));
  c.Send(Call("/partsim/no_such_service", json::object(), "sent"));
  ASSERT_FALSE(c.WaitReply("sent").is_null());
  auto refused = [&] {
    int n = 0;
    for (const json& m : c.Messages())
      if (m.value("op", "") == "service_response" && m.value("result", true) == false &&
          m["values"].dump().find("at most 64") != std::string::npos)
        ++n;
    return n;
  };
  EXPECT_EQ(refused(), 70 - 64 + 1);  // six holds and the camera call
  {
    std::lock_guard<std::mutex> lock(held_mutex);
    ASSERT_EQ(held.size(), 64u);
    for (ViewerServiceReply& r : held) r(true, "{}");
    held[0](true, "{}");  // a second answer neither sends nor gives back a place
  }
  c.Clear();
  for (int k = 0; k < 64; ++k) c.Send(Call("/test/hold", json::object(), "a" + std::to_string(k)));
  c.Send(Call("/test/hold", json::object(), "over"));
  EXPECT_NE(c.WaitReply("over")["values"].dump().find("at most 64"), std::string::npos);
  EXPECT_EQ(refused(), 1);
}

// Before a client has authenticated, a message longer than 4,096 bytes is refused without
// being parsed (the rosbridge server's bound): an auth op padded to 8 kB does not log in.
TEST_F(ViewerTest, UnauthenticatedMessagesOverTheBoundAreRefusedUnparsed) {
  Viewer& v = Start();
  TestClient c(v.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  c.Send(json{{"op", "auth"}, {"mac", v.GetToken()}, {"pad", std::string(8000, 'x')}});
  const json e = c.WaitMessage([](const json& m) { return m.value("level", "") == "error"; });
  ASSERT_FALSE(e.is_null());
  EXPECT_NE(e["msg"].get<std::string>().find("limited to 4096 bytes"), std::string::npos) << e;
  for (const json& m : c.Messages()) EXPECT_NE(m.value("msg", ""), "authenticated");
  c.Clear();
  c.Send(json{{"op", "subscribe"}, {"topic", "/partsim/status"}, {"id", "s"}});
  EXPECT_NE(c.WaitReply("s").value("msg", "").find("authenticate first"), std::string::npos);
  c.Auth(v.GetToken());  // a plain auth op still logs in
  c.Send(std::string(6000, ' ') + R"({"op": "auth", "mac": "x", "id": "long"})");
  EXPECT_EQ(c.WaitReply("long").value("msg", ""), "authenticated");  // once in, 4 kB is no bound
}

// max_clients counts connections from their handshake: a burst of handshakes all passed the
// check before any connection opened (69 of 32 got in under a burst of 400). 64 handshakes
// written at once, answers read afterwards: at most max_clients get 101.
TEST_F(ViewerTest, MaxClientsHoldsUnderABurstOfHandshakes) {
  ViewerOptions o;
  o.max_clients = 4;
  Viewer& v = Start(o);
  std::vector<int> socks;
  const std::string request =
      "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  for (int i = 0; i < 64; ++i) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(v.GetPort()));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
    timeval tv{10, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    socks.push_back(fd);
  }
  for (int fd : socks)
    ASSERT_EQ(::send(fd, request.data(), request.size(), MSG_NOSIGNAL),
              static_cast<ssize_t>(request.size()));
  int upgraded = 0, refused = 0;
  for (int fd : socks) {
    std::string head;
    char ch;
    while (head.find("\r\n") == std::string::npos && ::recv(fd, &ch, 1, 0) == 1) head += ch;
    if (head.find(" 101 ") != std::string::npos) ++upgraded;
    if (head.find(" 503 ") != std::string::npos) ++refused;
  }
  EXPECT_LE(upgraded, 4);
  EXPECT_GE(upgraded, 1);
  EXPECT_EQ(upgraded + refused, 64);
  for (int fd : socks) ::close(fd);
  // the slots are given back as the connections go
  ASSERT_TRUE(WaitFor([&] { return v.GetStats().clients == 0; }));
  bool in = false;
  for (int attempt = 0; attempt < 20 && !in; ++attempt) {
    TestClient c(v.GetPort());
    in = c.WaitOpen();
    if (!in) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_TRUE(in);
}

// A client that has not authenticated within auth_timeout is closed (code 1008); one that has
// stays.
TEST_F(ViewerTest, ClientsThatDoNotAuthenticateInTimeAreClosed) {
  ViewerOptions o;
  o.auth_timeout = 2.0;
  EXPECT_THROW(Viewer(scene_.get(),
                      [] {
                        ViewerOptions bad;
                        bad.auth_timeout = 0;
                        return bad;
                      }()),
               Error);
  Viewer& v = Start(o);
  TestClient silent(v.GetPort()), member(v.GetPort());
  ASSERT_TRUE(silent.WaitOpen());
  ASSERT_TRUE(member.WaitOpen());
  member.Auth(v.GetToken());
  ASSERT_TRUE(WaitFor([&] { return silent.Closed(); }));
  EXPECT_EQ(silent.CloseCode(), 1008);
  EXPECT_NE(silent.Messages().at(0).value("msg", "").find("within 2 s"), std::string::npos);
  // the authenticated client outlived the timeout
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_FALSE(member.Closed());
  member.Send(json{{"op", "auth"}, {"mac", v.GetToken()}, {"id", "still"}});
  EXPECT_EQ(member.WaitReply("still").value("msg", ""), "authenticated");
}

TEST_F(ViewerTest, ServedModeFollowsTheSimServer) {
  SimServerOptions so;
  so.fast = false;
  SimServer sim(scene_.get(), nullptr, so);
  auto viewer = std::make_unique<Viewer>(scene_.get());
  viewer->Attach(&sim);
  viewer->Start();
  EXPECT_THROW(viewer->Render(), Error);
  sim.Start();
  {
    TestClient c(viewer->GetPort());
    ASSERT_TRUE(c.WaitOpen());
    c.Auth(viewer->GetToken());
    c.Send(json{{"op", "subscribe"}, {"topic", "/partsim/joint_states"}});
    c.Send(json{{"op", "subscribe"}, {"topic", "/partsim/status"}});
    const Joint joint = MovableJoint();
    const double target = joint.GetLimits()[1];
    c.Send(Call("/partsim/set_joint_target",
                {{"articulation", 0}, {"joint", joint.GetName()}, {"position", target}}, "t"));
    ASSERT_TRUE(c.WaitReply("t")["result"].get<bool>());
    // the joint's position as the page reads it
    const int dof = joint.GetDofIndex();
    const double span = joint.GetLimits()[1] - joint.GetLimits()[0];
    EXPECT_FALSE(c.WaitMessage([&](const json& m) {
                    return m.value("topic", "") == "/partsim/joint_states" &&
                           std::abs(m["msg"]["position"][dof].get<double>() - target) < 0.1 * span;
                  }).is_null());
    c.Send(Call("/partsim/pause", json::object(), "p"));
    ASSERT_FALSE(c.WaitReply("p").is_null());
    EXPECT_TRUE(sim.IsPaused());
    EXPECT_TRUE(viewer->IsPaused());
    EXPECT_FALSE(c.WaitMessage([](const json& m) {
                    return m.value("topic", "") == "/partsim/status" && m["msg"]["paused"] == true;
                  }).is_null());
    const long long steps = sim.GetClockSteps();
    c.Send(Call("/partsim/step", {{"n", 7}}, "s"));
    ASSERT_FALSE(c.WaitReply("s").is_null());
    EXPECT_TRUE(WaitFor([&] { return sim.GetClockSteps() == steps + 7; }));
  }
  sim.Stop();
  viewer->Stop();
  EXPECT_TRUE(viewer->IsClosed());
}

}  // namespace
}  // namespace partsim
