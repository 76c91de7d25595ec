// A RosbridgeServer without a robot, served only what an extension adds (the browser viewer is
// one): a topic published to its subscribers, a service answered later from another thread, the
// simulation controls given (and only those), a periodic task, and the client-topic ops refused
// when client_topics is off. (The viewer's tests cover the HTTP handler.) Real websocketpp clients
// on loopback.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "partsim/core/error.h"
#include "partsim/server/rosbridge.h"
#include "server/wait_for.h"
#include "server/ws_test_client.h"

namespace partsim {
namespace {

using json = nlohmann::json;
using testing::WaitFor;

using Client = testing::LoggedWsClient;

TEST(RosbridgeExtensionTest, ServesWhatItsExtensionAdds) {
  RosbridgeOptions o;
  o.port = 0;
  o.client_topics = false;
  RosbridgeServer server(o);
  std::atomic<int> subscribed{0}, ticks{0}, paused{0}, stepped{0};
  RosbridgeTopicHooks hooks;
  hooks.on_subscribe = [&](const RosbridgeClientPtr& c) {
    ++subscribed;
    server.SendNow(c, R"({"op": "publish", "topic": "/ext/news", "msg": {"data": "now"}})", false);
  };
  server.AddTopic("/ext/news", "std_msgs/String", hooks);
  EXPECT_THROW(server.AddTopic("/ext/news", "std_msgs/String"), Error) << "served already";
  // answered from another thread, later
  server.AddService("/ext/double", [](const RosbridgeClientPtr&, const std::string& args,
                                      RosbridgeServiceReply reply) {
    const double x = json::parse(args).value("x", 0.0);
    if (x < 0) throw Error("x must be >= 0");
    std::thread([reply, x] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      reply(true, json{{"y", 2 * x}}.dump());
    }).detach();
  });
  RosbridgeSimControls controls;
  controls.pause = [&] { ++paused; };
  controls.step = [&](long long n) { stepped += static_cast<int>(n); };
  server.SetSimControls(controls);
  server.Every(0.05, [&] { ++ticks; });
  server.Start();
  EXPECT_THROW(server.AddService("/ext/late", {}), Error) << "before Start() only";

  Client c(server.GetPort());
  ASSERT_TRUE(c.WaitOpen());
  // the topic: the current state on subscribing, then what the extension publishes
  c.Send({{"op", "subscribe"}, {"topic", "/ext/news"}, {"type", "std_msgs/String"}});
  ASSERT_FALSE(c.Wait([](const json& m) { return m.value("topic", "") == "/ext/news"; }).is_null());
  EXPECT_EQ(subscribed, 1);
  ASSERT_TRUE(WaitFor([&] { return server.Subscribers("/ext/news").size() == 1; }));
  server.Publish("/ext/news", R"({"data": "later"})");
  ASSERT_FALSE(c.Wait([](const json& m) {
                  return m.value("topic", "") == "/ext/news" && m["msg"]["data"] == "later";
                }).is_null());
  // a topic nobody serves, and the ops of client topics, are refused
  c.Send({{"op", "subscribe"}, {"topic", "/tf"}, {"id", "tf"}});
  EXPECT_NE(c.Reply("tf").value("msg", "").find("no topic '/tf'"), std::string::npos);
  c.Send({{"op", "advertise"}, {"topic", "/mine"}, {"type", "std_msgs/String"}, {"id", "adv"}});
  EXPECT_NE(c.Reply("adv").value("msg", "").find("not supported"), std::string::npos);
  // the service: answered later, its failure a failed service response naming it
  c.Send({{"op", "call_service"}, {"service", "/ext/double"}, {"args", {{"x", 2.5}}}, {"id", "d"}});
  const json d = c.Reply("d");
  ASSERT_FALSE(d.is_null());
  EXPECT_TRUE(d["result"].get<bool>());
  EXPECT_DOUBLE_EQ(d["values"]["y"].get<double>(), 5.0);
  c.Send({{"op", "call_service"}, {"service", "/ext/double"}, {"args", {{"x", -1}}}, {"id", "n"}});
  const json n = c.Reply("n");
  EXPECT_FALSE(n["result"].get<bool>());
  EXPECT_EQ(n["values"], "/ext/double: x must be >= 0");
  // an unknown service: a failed response naming those there are
  c.Send({{"op", "call_service"}, {"service", "/nope"}, {"id", "u"}});
  const json u = c.Reply("u");
  EXPECT_FALSE(u["result"].get<bool>());
  EXPECT_NE(u["values"].get<std::string>().find("/ext/double"), std::string::npos) << u;
  // the controls given, and only those
  c.Send({{"op", "call_service"}, {"service", "/partsim/pause"}, {"id", "p"}});
  c.Send({{"op", "call_service"}, {"service", "/partsim/step"}, {"args", {{"n", 3}}}, {"id", "s"}});
  c.Send({{"op", "call_service"}, {"service", "/partsim/resume"}, {"id", "r"}});
  EXPECT_TRUE(c.Reply("p")["result"].get<bool>());
  EXPECT_TRUE(c.Reply("s")["result"].get<bool>());
  EXPECT_FALSE(c.Reply("r").value("result", true)) << "no resume control was given";
  EXPECT_EQ(paused, 1);
  EXPECT_EQ(stepped, 3);
  // the periodic task runs on the network thread while the server runs
  EXPECT_TRUE(WaitFor([&] { return ticks >= 3; }));
  EXPECT_EQ(server.GetStats().authenticated_clients, 1) << "no token: every client is logged in";
  server.Stop();
  const int after = ticks;
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(ticks, after) << "stopped with the server";
}

}  // namespace
}  // namespace partsim
