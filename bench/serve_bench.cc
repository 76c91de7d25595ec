// Asynchronous-mode benchmark: the Panda at its home pose in front of the built-in cabinet,
// stepped in real time at 500 Hz and served by RosbridgeServer on a free port, with WebSocket
// clients in this process. It measures, in one run:
//   1. /joint_states messages per wall second delivered to each of 1, 10 and 50 clients (each
//      subscribed to /clock, /joint_states and /tf), their mean and minimum over the clients and
//      the ratio to the physics rate (500 Hz);
//   2. command latency in simulation steps (RosbridgeServer::GetStats) for position commands sent
//      at 100 Hz, with no other client and with 50 clients subscribed as in 1;
//   3. 640x480 images per second delivered to one client subscribed to /front_camera/image_raw
//      (rendered every step), as JSON text (base64) and as CBOR (binary frames), and the
//      simulated seconds per wall second meanwhile.
// The set repeats and the median of each figure is printed (a Markdown table); see README.md.
//
// Usage: partsim_serve_bench [--repeat N] [--quick] [--images]
//   --repeat N   repetitions of the whole set (default 3); the medians are taken over them
//   --quick      one repetition with shorter windows (a smoke run)
//   --images     3. alone: 640x480 images per second
#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include "partsim/assets/default_objects.h"
#include "partsim/assets/urdf.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/scene_render.h"
#include "partsim/robot/robots.h"
#include "partsim/server/rosbridge.h"
#include "partsim/server/served_robot.h"
#include "partsim/server/sim_server.h"

namespace {

using json = nlohmann::json;
using WsClient = websocketpp::client<websocketpp::config::asio_client>;
using Clock = std::chrono::steady_clock;

constexpr double kPhysicsRate = 500.0;                // Hz, stepped in real time
constexpr int kImageWidth = 640, kImageHeight = 480;  // pixels of /front_camera
constexpr char kImageTopic[] = "/front_camera/image_raw";

/// CPU time of the whole process, all threads (s).
double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Polls `done` every millisecond for at most `seconds`; returns its last value.
bool WaitUntil(const std::function<bool()>& done, double seconds) {
  const Clock::time_point t0 = Clock::now();
  while (!done()) {
    if (SecondsSince(t0) > seconds) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

/// Reports a failed measurement and ends the program at once (threads are still running).
[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "partsim_serve_bench: %s\n", what.c_str());
  std::fflush(nullptr);
  std::_Exit(1);
}

// ---------------------------------------------------------------------------------------------
// Clients: N WebSocket connections served by one client thread, counting what they receive.

/// Counters of one connection, written by the client thread.
struct Connection {
  WsClient::connection_ptr con;
  std::atomic<bool> open{false}, closed{false};
  std::atomic<long long> joint_states{0};  // /joint_states messages
  std::atomic<long long> clock_ns{-1};     // stamp of the newest /clock message (ns)
  std::atomic<long long> images{0};        // /front_camera/image_raw messages
  std::atomic<long long> image_bytes{0};   // their size on the wire (payload)
  std::atomic<long long> short_images{0};  // image messages too small to hold 640x480 rgb8
};

class Clients {
 public:
  /// Opens `n` connections to ws://127.0.0.1:`port`; exits the program if they do not open.
  Clients(int port, int n) {
    ws_.clear_access_channels(websocketpp::log::alevel::all);
    ws_.clear_error_channels(websocketpp::log::elevel::all);
    ws_.init_asio();
    for (int i = 0; i < n; ++i) {
      auto c = std::make_unique<Connection>();
      Connection* p = c.get();
      websocketpp::lib::error_code ec;
      p->con = ws_.get_connection("ws://127.0.0.1:" + std::to_string(port), ec);
      if (ec) Fail("client: " + ec.message());
      p->con->set_open_handler([p](websocketpp::connection_hdl) { p->open = true; });
      p->con->set_close_handler([p](websocketpp::connection_hdl) { p->closed = true; });
      p->con->set_fail_handler([p](websocketpp::connection_hdl) { p->closed = true; });
      p->con->set_message_handler(
          [p](websocketpp::connection_hdl, WsClient::message_ptr m) { Count(p, m); });
      ws_.connect(p->con);
      connections_.push_back(std::move(c));
    }
    thread_ = std::thread([this] { ws_.run(); });
    const bool opened = WaitUntil(
        [this] {
          for (auto& c : connections_)
            if (!c->open) return false;
          return true;
        },
        20.0);
    if (!opened) Fail("not every client connected within 20 s");
  }
  ~Clients() {
    for (auto& c : connections_) {
      websocketpp::lib::error_code ec;
      if (!c->closed) c->con->close(websocketpp::close::status::normal, "", ec);
    }
    WaitUntil(
        [this] {
          for (auto& c : connections_)
            if (!c->closed) return false;
          return true;
        },
        10.0);
    ws_.stop();
    thread_.join();
  }
  Clients(const Clients&) = delete;
  Clients& operator=(const Clients&) = delete;

  /// Sends `text` on every connection.
  void SendAll(const std::string& text) {
    for (auto& c : connections_) Send(*c, text);
  }
  /// Sends `text` on one connection (errors ignored: a closed connection counts nothing).
  void Send(Connection& c, const std::string& text) {
    c.con->send(text, websocketpp::frame::opcode::text);
  }
  std::vector<std::unique_ptr<Connection>>& Get() { return connections_; }
  /// CPU time of the client thread (s).
  double CpuSeconds() {
    clockid_t id;
    timespec ts{};
    if (pthread_getcpuclockid(thread_.native_handle(), &id) == 0) clock_gettime(id, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
  }

 private:
  /// Counts a message by its topic: the last "topic" key of the JSON text (the server writes
  /// keys in order, so it ends the message); a binary (CBOR) frame ends with its topic too.
  static void Count(Connection* c, const WsClient::message_ptr& msg) {
    const auto& m = *msg;
    const std::string& p = m.get_payload();
    bool image = false;
    if (m.get_opcode() == websocketpp::frame::opcode::binary) {
      image = p.size() > 64 && p.find("image_raw", p.size() - 64) != std::string::npos;
    } else {
      const size_t at = p.rfind("\"topic\":\"");
      if (at == std::string::npos) return;
      if (p.compare(at + 9, 14, "/joint_states\"") == 0) {
        ++c->joint_states;
        return;
      }
      if (p.compare(at + 9, 7, "/clock\"") == 0) {
        // {"msg":{"clock":{"nsecs":N,"secs":S}},...}
        const size_t ns = p.find("\"nsecs\":"), s = p.find("\"secs\":");
        if (ns != std::string::npos && s != std::string::npos)
          c->clock_ns =
              std::atoll(p.c_str() + s + 7) * 1000000000LL + std::atoll(p.c_str() + ns + 8);
        return;
      }
      static const std::string quoted = std::string(kImageTopic) + "\"";
      image = p.compare(at + 9, quoted.size(), quoted) == 0;
    }
    if (!image) return;
    ++c->images;
    c->image_bytes += static_cast<long long>(p.size());
    if (p.size() < static_cast<size_t>(kImageWidth * kImageHeight * 3)) ++c->short_images;
  }

  WsClient ws_;
  std::vector<std::unique_ptr<Connection>> connections_;
  std::thread thread_;
};

std::string Subscribe(const std::string& topic, const json& extra = json::object()) {
  json j = {{"op", "subscribe"}, {"topic", topic}};
  j.update(extra);
  return j.dump();
}

/// Subscribes every client to /clock, /joint_states and /tf, then waits for joint states to
/// reach all of them and for 0.5 s more.
void SubscribeToJointTopics(Clients* clients) {
  for (const char* t : {"/clock", "/joint_states", "/tf"}) clients->SendAll(Subscribe(t));
  const bool flowing = WaitUntil(
      [&] {
        for (auto& c : clients->Get())
          if (c->joint_states == 0) return false;
        return true;
      },
      20.0);
  if (!flowing) Fail("joint states did not reach every client within 20 s");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
}

// ---------------------------------------------------------------------------------------------
// The served scene, as `partsim serve` builds it with the Panda and no scene file.

class ServedScene {
 public:
  /// `camera_rate`: Hz (simulated) of the camera topics, 0 for every step.
  explicit ServedScene(double camera_rate) {
    partsim::SceneConfig config;
    config.timestep = 1.0 / kPhysicsRate;
    scene_ = std::make_unique<partsim::Scene>(config);
    scene_->AddGround(0.0);
    // the cabinet 1 m ahead, root fixed
    partsim::UrdfLoader loader(scene_.get());
    loader.fix_root_link = true;
    partsim::ArticulationDesc cabinet = loader.Parse(partsim::MakeCabinetUrdf(), ".", "cabinet");
    cabinet.root_pose = partsim::Pose(Eigen::Vector3d(1.0, 0, 0));
    scene_->AddArticulation(cabinet);
    // the Panda at its home pose, hand open
    partsim::RobotModel model = partsim::BuildPanda();
    robot_ = scene_->AddArticulation(model.articulation);
    Eigen::VectorXd q = robot_.GetQpos();
    for (size_t i = 0; i < model.arm_joints.size() && i < model.home.size(); ++i)
      q[robot_.FindJointByName(model.arm_joints[i]).GetDofIndex()] = model.home[i];
    for (const std::string& g : model.gripper_joints) {
      const int d = robot_.FindJointByName(g).GetDofIndex();
      if (d >= 0) q[d] = model.gripper_open;
    }
    robot_.SetQpos(q);
    // lights and the front camera
    SetAmbientLight(*scene_, Eigen::Vector3f(0.35f, 0.35f, 0.35f));
    AddDirectionalLight(*scene_, Eigen::Vector3d(-1, -0.5, -1), Eigen::Vector3f(0.8f, 0.8f, 0.8f));
    partsim::Camera camera =
        AddCamera(*scene_, "front_camera", kImageWidth, kImageHeight, 1.0, 0.05, 20.0);
    camera.SetLocalPose(
        partsim::CameraLookAt(Eigen::Vector3d(1.3, -2.2, 1.4), Eigen::Vector3d(0.5, 0, 0.4)));

    loop_ = std::make_unique<partsim::ControlLoop>(scene_.get());
    sim_ = std::make_unique<partsim::SimServer>(scene_.get(), loop_.get());
    partsim::ServedRobotOptions so;
    so.camera_rate = camera_rate;
    so.imu_link = model.ee_link;
    so.ee_link = model.ee_link;
    so.tcp_in_ee = model.tcp_in_ee;
    served_ = std::make_unique<partsim::ServedRobot>(sim_.get(), scene_.get(), loop_.get(), robot_,
                                                     robot_.GetName(), so);
    // the commanded joints' positions now: what the position controller holds
    for (const std::string& name : served_->GetJointNames())
      hold_.push_back(q[robot_.FindJointByName(name).GetDofIndex()]);
    partsim::RosbridgeOptions ro;
    ro.port = 0;
    bridge_ = std::make_unique<partsim::RosbridgeServer>(served_.get(), ro);
    bridge_->Start();
    sim_->Start();
  }
  ~ServedScene() { Stop(); }
  ServedScene(const ServedScene&) = delete;
  ServedScene& operator=(const ServedScene&) = delete;

  /// Stops the simulation and the server (idempotent).
  void Stop() {
    sim_->Stop();
    served_->Close();
    bridge_->Stop();
  }
  int Port() const { return bridge_->GetPort(); }
  partsim::SimServer& Sim() { return *sim_; }
  partsim::RosbridgeServer& Bridge() { return *bridge_; }
  /// A position command holding the current pose (std_msgs/Float64MultiArray).
  std::string HoldCommand() const {
    return json{
        {"op", "publish"},
        {"topic", "/" + served_->GetName() + "/joint_position_controller/command"},
        {"msg", {{"layout", {{"dim", json::array()}, {"data_offset", 0}}}, {"data", hold_}}}}
        .dump();
  }
  /// The device that renders (call once stopped, after pictures were taken).
  std::string Renderer() { return GetRenderBackend(*scene_).Device(); }

 private:
  std::unique_ptr<partsim::Scene> scene_;
  partsim::Articulation robot_;
  std::vector<double> hold_;
  std::unique_ptr<partsim::ControlLoop> loop_;
  std::unique_ptr<partsim::SimServer> sim_;
  std::unique_ptr<partsim::ServedRobot> served_;
  std::unique_ptr<partsim::RosbridgeServer> bridge_;
};

// ---------------------------------------------------------------------------------------------
// Measurements. Each adds named figures of one repetition to `f`.

using Figures = std::map<std::string, double>;

/// 1. Joint-state rate to `n` clients subscribed to /clock, /joint_states and /tf, over `window`
/// wall seconds; the physics steps and the server's drops over the same window.
void MeasureJointStates(ServedScene* served, int n, double window, Figures* f) {
  Clients clients(served->Port(), n);
  SubscribeToJointTopics(&clients);
  std::vector<long long> before;
  for (auto& c : clients.Get()) before.push_back(c->joint_states);
  const long long steps0 = served->Sim().GetClockSteps();
  const long long dropped0 = served->Bridge().GetStats().messages_dropped;
  const double cpu0 = ProcessCpuSeconds(), client_cpu0 = clients.CpuSeconds();
  const Clock::time_point t0 = Clock::now();
  std::this_thread::sleep_for(std::chrono::duration<double>(window));
  const double secs = SecondsSince(t0);
  const long long now_steps = served->Sim().GetClockSteps();
  const double cpu = ProcessCpuSeconds() - cpu0, client_cpu = clients.CpuSeconds() - client_cpu0;
  const long long steps = now_steps - steps0;
  const long long dropped = served->Bridge().GetStats().messages_dropped - dropped0;
  // how far behind the simulation clock the newest /clock each client holds is
  double age = 0.0;
  for (auto& c : clients.Get())
    age += now_steps / kPhysicsRate - 1e-9 * static_cast<double>(c->clock_ns.load());
  double sum = 0.0, min = 1e300;
  for (size_t i = 0; i < before.size(); ++i) {
    const double rate = (clients.Get()[i]->joint_states - before[i]) / secs;
    sum += rate;
    min = std::min(min, rate);
  }
  const std::string key = "js" + std::to_string(n);
  (*f)[key + " mean"] = sum / n;
  (*f)[key + " min"] = min;
  (*f)[key + " steps"] = steps / secs;
  (*f)[key + " dropped"] = dropped / secs;
  (*f)[key + " age"] = 1e3 * age / n;
  (*f)[key + " cpu"] = cpu / secs;
  (*f)[key + " client cpu"] = client_cpu / secs;
}

/// 2. Latency of `commands` position commands sent evenly over `spread` wall seconds by one
/// client, while `subscribers` other clients take /clock, /joint_states and /tf. A fresh server,
/// so that the statistics count these commands only.
void MeasureLatency(int subscribers, int commands, double spread, Figures* f) {
  ServedScene served(10.0);
  std::unique_ptr<Clients> others;
  if (subscribers > 0) {
    others = std::make_unique<Clients>(served.Port(), subscribers);
    SubscribeToJointTopics(others.get());
  }
  Clients sender(served.Port(), 1);
  const std::string command = served.HoldCommand();
  const Clock::time_point t0 = Clock::now();
  for (int i = 0; i < commands; ++i) {
    std::this_thread::sleep_until(t0 + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(i * spread / commands)));
    sender.Send(*sender.Get()[0], command);
  }
  if (!WaitUntil([&] { return served.Bridge().GetStats().commands >= commands; }, 10.0))
    Fail("only " + std::to_string(served.Bridge().GetStats().commands) + " of " +
         std::to_string(commands) + " commands were applied within 10 s");
  const partsim::RosbridgeStats s = served.Bridge().GetStats();
  if (s.errors > 0) Fail("the server answered a command with an error");
  const std::string key = "lat" + std::to_string(subscribers);
  (*f)[key + " mean"] = s.mean_latency_steps;
  (*f)[key + " max"] = static_cast<double>(s.max_latency_steps);
}

/// 3. Images per second delivered to one client subscribed to the camera (`cbor`: binary
/// frames), over `window` wall seconds, and simulated seconds per wall second meanwhile.
void MeasureImages(ServedScene* served, bool cbor, double window, Figures* f) {
  Clients client(served->Port(), 1);
  Connection& c = *client.Get()[0];
  client.Send(c, Subscribe(kImageTopic, cbor ? json{{"compression", "cbor"}} : json::object()));
  // the first picture also creates the renderer's context and compiles its shaders
  if (!WaitUntil([&] { return c.images > 0; }, 60.0)) Fail("no image within 60 s");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const long long images0 = c.images, bytes0 = c.image_bytes;
  const long long steps0 = served->Sim().GetClockSteps();
  const Clock::time_point t0 = Clock::now();
  std::this_thread::sleep_for(std::chrono::duration<double>(window));
  const double secs = SecondsSince(t0);
  const long long steps = served->Sim().GetClockSteps() - steps0;
  if (c.short_images > 0) Fail("an image message was too small to hold 640x480 rgb8");
  const std::string key = cbor ? "img cbor" : "img json";
  (*f)[key + " rate"] = (c.images - images0) / secs;
  (*f)[key + " MBps"] = (c.image_bytes - bytes0) / secs / 1e6;
  (*f)[key + " rtf"] = steps / kPhysicsRate / secs;
}

// ---------------------------------------------------------------------------------------------
// Machine note and report.

std::string ReadFirst(const std::string& path, const std::string& prefix) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(prefix, 0) == 0) return line;
  return "";
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one;
  in >> one;
  return one;
}

/// Processors this process may run on (what `nproc` prints).
int Nproc() {
  cpu_set_t set;
  CPU_ZERO(&set);
  return sched_getaffinity(0, sizeof(set), &set) == 0 ? CPU_COUNT(&set) : 0;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int ParseCount(const char* flag, const char* value) {
  char* end = nullptr;
  const long n = value ? std::strtol(value, &end, 10) : 0;
  if (!value || *end != '\0' || n < 1 || n > 1000) {
    std::fprintf(stderr, "%s needs an integer in [1, 1000], got '%s'\n", flag, value ? value : "");
    std::exit(2);
  }
  return static_cast<int>(n);
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3;
  bool quick = false, images_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--repeat") {
      repeat = ParseCount("--repeat", i + 1 < argc ? argv[++i] : nullptr);
    } else if (arg == "--quick") {
      quick = true;
    } else if (arg == "--images") {
      images_only = true;
    } else {
      std::fprintf(stderr, "unknown argument '%s'\nusage: %s [--repeat N] [--quick] [--images]\n",
                   arg.c_str(), argv[0]);
      return 2;
    }
  }
  if (quick) repeat = 1;
  const double js_window = quick ? 1.0 : 3.0;  // s
  const int commands = quick ? 50 : 200;
  const double command_spread = quick ? 0.5 : 2.0;  // s
  const double image_window = quick ? 2.0 : 5.0;    // s
  const std::vector<int> client_counts = {1, 10, 50};

  std::string cpu = ReadFirst("/proc/cpuinfo", "model name");
  if (cpu.find(": ") != std::string::npos) cpu = cpu.substr(cpu.find(": ") + 2);
  const std::string load_start = LoadAverage();
  std::printf(
      "serve bench: Panda at home before the cabinet, %g Hz real time, rosbridge on 127.0.0.1, "
      "clients in this process; %d repetition(s): joint states over %g s windows, %d commands "
      "over %g s, 640x480 images over %g s\n",
      kPhysicsRate, repeat, js_window, commands, command_spread, image_window);
  std::fflush(stdout);

  std::vector<Figures> runs;
  std::string renderer = "?";
  const Clock::time_point start = Clock::now();
  for (int r = 0; r < repeat; ++r) {
    Figures f;
    if (!images_only) {
      {
        ServedScene served(10.0);
        for (int n : client_counts) MeasureJointStates(&served, n, js_window, &f);
      }
      MeasureLatency(0, commands, command_spread, &f);
      MeasureLatency(50, commands, command_spread, &f);
    }
    {
      // the two encodings take turns going first
      ServedScene served(0.0);
      for (int k = 0; k < 2; ++k) MeasureImages(&served, (k + r) % 2 == 1, image_window, &f);
      served.Stop();
      renderer = served.Renderer();
    }
    if (images_only)
      std::printf("rep %d: images/s json %.1f, cbor %.1f\n", r, f["img json rate"],
                  f["img cbor rate"]);
    else
      std::printf(
          "rep %d: joint states/client [Hz] 1: %.0f, 10: %.0f (min %.0f), 50: %.0f (min %.0f); "
          "latency [steps] idle %.2f (max %.0f), 50 clients %.2f (max %.0f); images/s json %.1f, "
          "cbor %.1f\n",
          r, f["js1 mean"], f["js10 mean"], f["js10 min"], f["js50 mean"], f["js50 min"],
          f["lat0 mean"], f["lat0 max"], f["lat50 mean"], f["lat50 max"], f["img json rate"],
          f["img cbor rate"]);
    std::fflush(stdout);
    runs.push_back(f);
  }

  // medians over the repetitions, as a Markdown table
  char machine[512];
  std::snprintf(machine, sizeof(machine),
                "machine: nproc %d, %s, rasterizer on %s, load average %s -> %s, %.0f s in all",
                Nproc(), cpu.c_str(), renderer.c_str(), load_start.c_str(), LoadAverage().c_str(),
                SecondsSince(start));
  std::printf("\n%s\n\n", machine);
  std::printf("| figure | median | per repetition |\n|---|---:|---|\n");
  auto print = [&](const std::string& label, const std::string& key, const char* fmt,
                   double scale = 1.0) {
    std::vector<double> v;
    for (Figures& f : runs) v.push_back(f[key] * scale);
    char cell[64];
    std::string each;
    for (size_t i = 0; i < v.size(); ++i) {
      std::snprintf(cell, sizeof(cell), fmt, v[i]);
      each += (i ? ", " : "") + std::string(cell);
    }
    std::snprintf(cell, sizeof(cell), fmt, Median(v));
    std::printf("| %s | %s | %s |\n", label.c_str(), cell, each.c_str());
  };
  for (int n : images_only ? std::vector<int>{} : client_counts) {
    const std::string k = "js" + std::to_string(n);
    const std::string who = std::to_string(n) + (n == 1 ? " client" : " clients");
    print("/joint_states per client, " + who + ", mean [Hz]", k + " mean", "%.0f");
    print("/joint_states per client, " + who + ", min [Hz]", k + " min", "%.0f");
    print("  mean / physics rate (500 Hz), " + who, k + " mean", "%.3f", 1.0 / kPhysicsRate);
    print("  physics steps per wall second, " + who, k + " steps", "%.0f");
    print("  messages dropped by the server per second (all clients and topics), " + who,
          k + " dropped", "%.0f");
    print("  age of the newest /clock a client holds at the window's end, mean [ms], " + who,
          k + " age", "%.0f");
    print("  process CPU [cores], " + who, k + " cpu", "%.2f");
    print("  of which the clients' thread [cores], " + who, k + " client cpu", "%.2f");
  }
  if (!images_only) {
    print("command latency, idle, mean [steps]", "lat0 mean", "%.2f");
    print("command latency, idle, max [steps]", "lat0 max", "%.0f");
    print("command latency, 50 clients subscribed, mean [steps]", "lat50 mean", "%.2f");
    print("command latency, 50 clients subscribed, max [steps]", "lat50 max", "%.0f");
  }
  for (const char* enc : {"json", "cbor"}) {
    const std::string k = std::string("img ") + enc;
    const std::string name = std::string(enc) == "json" ? "JSON (base64)" : "CBOR";
    print("640x480 images per second, " + name, k + " rate", "%.1f");
    print("  received [MB/s], " + name, k + " MBps", "%.1f");
    print("  simulated seconds per wall second, " + name, k + " rtf", "%.3f");
  }
  return 0;
}
