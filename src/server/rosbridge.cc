#include "partsim/server/rosbridge.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <thread>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "core/json_parse.h"
#include "partsim/core/error.h"
#include "partsim/render/camera.h"
#include "partsim/render/image_io.h"

namespace partsim {

namespace {

using json = nlohmann::json;
using WsServer = websocketpp::server<websocketpp::config::asio>;
using Hdl = websocketpp::connection_hdl;
using WallClock = std::chrono::steady_clock;

// Most pieces of fragmented messages held for one client at a time (each costs a map node
// beside its bytes): a 16 MB message arrives in pieces of 256 bytes or more.
constexpr size_t kMaxFragmentsHeld = 65536;

// Calls to client-advertised services: unanswered ones per caller, and how long one may wait.
constexpr size_t kMaxPendingCalls = 100;
constexpr std::chrono::seconds kCallTimeout{60};

// Open subscribe requests (distinct ids) of one client on one topic.
constexpr size_t kMaxRequestsPerTopic = 64;

// Whether a page of `origin` ("scheme://host[:port]") may connect: one of `allowed`, or with
// none given, a page of this machine.
std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char ch) { return std::tolower(ch); });
  return s;
}

bool OriginAllowed(const std::string& origin, const std::vector<std::string>& allowed) {
  if (origin.empty()) return true;  // not a browser: no page to protect against
  const std::string o = Lower(origin);
  for (const std::string& a : allowed)
    if (a == "*" || Lower(a) == o) return true;
  if (!allowed.empty()) return false;
  for (const char* scheme : {"http://", "https://"}) {
    if (o.rfind(scheme, 0) != 0) continue;
    const std::string rest = o.substr(std::strlen(scheme));
    for (const char* host : {"localhost", "127.0.0.1", "[::1]"}) {
      const size_t n = std::strlen(host);
      if (rest.compare(0, n, host) == 0 && (rest.size() == n || rest[n] == ':')) return true;
    }
  }
  return false;
}

// Compares without stopping at the first difference (the time taken says nothing of where).
bool SameToken(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() != b.size();
  for (size_t i = 0; i < a.size(); ++i) diff |= a[i] ^ b[i % (b.empty() ? 1 : b.size())];
  return diff == 0 && !b.empty();
}

// Text of a JSON value; bytes that are not UTF-8 (a client's string quoted back in an error)
// become U+FFFD instead of throwing.
std::string Dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

// Parses a client's message; throws json::exception when it is malformed or nested deeper than
// internal::kMaxJsonDepth levels.
json ParseClientJson(const std::string& text) { return internal::ParseJsonBounded(text); }

// topics the simulation publishes, and the commands it takes
const char* kClockType = "rosgraph_msgs/Clock";
const char* kJointStateType = "sensor_msgs/JointState";
const char* kTfType = "tf2_msgs/TFMessage";
const char* kFloat64ArrayType = "std_msgs/Float64MultiArray";
const char* kTrajectoryType = "trajectory_msgs/JointTrajectory";
const char* kImageType = "sensor_msgs/Image";
const char* kCameraInfoType = "sensor_msgs/CameraInfo";
const char* kPointCloud2Type = "sensor_msgs/PointCloud2";
const char* kImuType = "sensor_msgs/Imu";

/// Base64 (RFC 4648, padded): how rosbridge sends uint8[] fields.
std::string Base64(const uint8_t* data, size_t n) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((n + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < n; i += 3) {
    uint32_t v = (uint32_t(data[i]) << 16) | (uint32_t(data[i + 1]) << 8) | data[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < n) {
    uint32_t v = uint32_t(data[i]) << 16;
    if (i + 1 < n) v |= uint32_t(data[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < n ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

json Vector3(const Eigen::Vector3d& v) { return {{"x", v.x()}, {"y", v.y()}, {"z", v.z()}}; }

json Stamp(double t) {
  double secs = std::floor(t);
  return {{"secs", static_cast<long long>(secs)},
          {"nsecs", static_cast<long long>(std::llround((t - secs) * 1e9)) % 1000000000}};
}

/// Reads a ROS duration {secs, nsecs} ({sec, nanosec} in ROS 2, or a number of seconds) of
/// `what`; it must be finite and within [0, kMaxTrajectorySeconds].
double Duration(const json& d, const std::string& what) {
  auto field = [&](const char* k) {
    if (!d.contains(k)) return 0.0;
    if (!d[k].is_number()) throw Error(what + "." + k + " is not a number");
    return d[k].get<double>();
  };
  double s = 0.0;
  if (d.is_number())
    s = d.get<double>();
  else if (!d.is_object())
    throw Error(what + " is not a duration");
  else if (d.contains("sec"))
    s = field("sec") + field("nanosec") * 1e-9;
  else
    s = field("secs") + field("nsecs") * 1e-9;
  if (!std::isfinite(s) || s < 0 || s > kMaxTrajectorySeconds)
    throw Error(what + " must be from 0 to 86400 s, got " + Dump(s));
  return s;
}

/// Numbers of a JSON array; throws naming `what`.
std::vector<double> Numbers(const json& a, const std::string& what) {
  if (!a.is_array()) throw Error(what + " is not an array of numbers");
  std::vector<double> v;
  for (const json& x : a) {
    if (!x.is_number()) throw Error(what + " holds a value that is not a number");
    double d = x.get<double>();
    if (!std::isfinite(d)) throw Error(what + " holds a value that is not finite");
    v.push_back(d);
  }
  return v;
}

}  // namespace

struct RosbridgeServer::Impl {
  /// One subscribe request.
  struct Request {
    double throttle_ms = 0;
    size_t queue_length = 0;   // 0: the server's bound
    size_t fragment_size = 0;  // 0: whole messages
    bool cbor = false;         // binary CBOR frames (uint8[] as byte strings) instead of JSON
    long long order = 0;       // later requests choose the compression
  };
  /// A client's subscription to one topic: one message per publication, however many subscribe
  /// requests (by id) it made; the most permissive settings of the requests apply.
  struct Subscription : Request {
    std::map<std::string, Request> requests;  // by subscribe id
    WallClock::time_point last_sent{};
    void Merge() {
      throttle_ms = 1e300;
      queue_length = fragment_size = 0;
      bool server_bound = false, all_fragment = true;
      long long latest = -1;
      for (const auto& [id, r] : requests) {
        throttle_ms = std::min(throttle_ms, r.throttle_ms);
        if (r.queue_length == 0) server_bound = true;  // the largest queue there is
        queue_length = std::max(queue_length, r.queue_length);
        all_fragment = all_fragment && r.fragment_size > 0;
        fragment_size =
            fragment_size == 0 ? r.fragment_size : std::min(fragment_size, r.fragment_size);
        if (r.order > latest) {
          latest = r.order;
          cbor = r.cbor;
        }
      }
      if (server_bound) queue_length = 0;
      if (!all_fragment) fragment_size = 0;
    }
  };
  /// A message waiting for a client. The text is shared by every client it goes to: the
  /// simulation thread queues a pointer per client; fragmenting happens on the network thread.
  struct Outgoing {
    std::shared_ptr<const std::string> data;
    bool binary = false;
    std::string topic;         // the subscription it was published for; "" for replies
    size_t fragment_size = 0;  // > 0: sent as rosbridge fragments of this many characters
  };
  /// An incoming message arriving in fragments.
  /// Only the pieces received are held: memory follows the bytes a client sent, never the
  /// `total` it announced.
  struct Partial {
    size_t total = 0;
    std::map<size_t, std::string> pieces;  // num -> data
    size_t bytes = 0;
  };
  struct Client {
    Hdl hdl;
    std::string address;  // the peer's address and port, for the log
    std::map<std::string, Subscription> subs;
    std::map<std::string, std::string> advertised;  // topic -> type
    std::set<std::string> services;                 // advertised by this client
    std::map<std::string, Partial> partial;         // fragments by message id (network thread)
    std::mutex out_mutex;
    std::deque<Outgoing> out;
    std::atomic<bool> flush_scheduled{false};
    bool authenticated = false;  // network thread; true from the start when no token is set
  };
  using ClientPtr = std::shared_ptr<Client>;

  ServedRobot* robot;
  SimServer* sim;
  std::string robot_name;
  RosbridgeOptions options;

  // sensors (read on the simulation thread)
  struct CameraTopics {
    std::string image, info, points;
    double next_render = 0, next_info = 0;  // simulated time of the next message
  };
  std::vector<CameraTopics> cameras;  // one per robot->GetCameras()
  double imu_next = 0;

  WsServer ws;
  std::unique_ptr<boost::asio::steady_timer> accept_timer;  // network thread
  std::atomic<long long> accept_errors{0};
  std::thread io_thread;
  int port = 0;
  std::atomic<bool> started{false};

  mutable std::mutex clients_mutex;
  std::map<Hdl, ClientPtr, std::owner_less<Hdl>> clients;
  // calls to client-advertised services: our id -> (caller, caller's id, provider, service)
  struct PendingCall {
    std::weak_ptr<Client> caller;
    json id;
    std::weak_ptr<Client> provider;
    std::string service;
    WallClock::time_point since;
  };
  std::map<std::string, PendingCall> pending_calls;  // clients_mutex
  std::mt19937_64 call_ids{std::random_device{}()};  // clients_mutex
  std::atomic<long long> next_fragment{0};
  std::atomic<long long> next_request{0};

  std::atomic<long long> sent{0}, dropped{0}, errors{0}, refused{0};

  // ---- accepting ----
  /// partsim's accept loop (network thread), in place of websocketpp's, which retries a failed
  /// accept at once: out of file descriptors that spun a core. A failure waits 100 ms.
  void StartAccept() {
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = ws.get_connection();
    if (!con) return;
    ws.async_accept(
        websocketpp::lib::static_pointer_cast<WsServer::transport_con_type>(con),
        [this, con](const websocketpp::lib::error_code& e) { OnAccept(con, e); }, ec);
    if (ec) con->terminate(websocketpp::lib::error_code());
  }
  void OnAccept(const WsServer::connection_ptr& con, const websocketpp::lib::error_code& ec) {
    if (!ec) {
      con->start();
      StartAccept();
      return;
    }
    con->terminate(ec);
    if (ec == websocketpp::error::operation_canceled || !ws.is_listening()) return;
    ++accept_errors;
    accept_timer->expires_after(std::chrono::milliseconds(100));
    accept_timer->async_wait([this](const boost::system::error_code& e) {
      if (!e && ws.is_listening()) StartAccept();
    });
  }

  // ---- outgoing ----
  /// Queues a message for a client from any thread; drops the oldest beyond the bound.
  /// Queues a message for a client. A message published for `topic` keeps at most `bound` (the
  /// subscription's queue_length; 0: max_client_queue) of that topic's messages waiting, the
  /// oldest dropped first; replies and statuses (no topic) are only dropped when the whole queue
  /// exceeds max_client_queue, so that a busy subscription never evicts a service response.
  void Enqueue(const ClientPtr& c, const std::string& msg, size_t bound, bool binary = false,
               const std::string& topic = "") {
    Enqueue(c, std::make_shared<const std::string>(msg), bound, binary, topic);
  }
  void Enqueue(const ClientPtr& c, std::shared_ptr<const std::string> msg, size_t bound,
               bool binary, const std::string& topic, size_t fragment_size = 0) {
    if (bound == 0 || bound > options.max_client_queue) bound = options.max_client_queue;
    {
      std::lock_guard<std::mutex> lock(c->out_mutex);
      c->out.push_back({std::move(msg), binary, topic, fragment_size});
      if (!topic.empty()) {
        size_t same = 0;
        for (const Outgoing& o : c->out) same += o.topic == topic;
        for (auto it = c->out.begin(); same > bound && it != c->out.end();) {
          if (it->topic == topic) {
            it = c->out.erase(it);
            --same;
            ++dropped;
          } else {
            ++it;
          }
        }
      }
      while (c->out.size() > options.max_client_queue) {
        c->out.pop_front();
        ++dropped;
      }
    }
    if (!c->flush_scheduled.exchange(true)) {
      std::weak_ptr<Client> weak = c;
      boost::asio::post(ws.get_io_service(), [this, weak] {
        if (ClientPtr cp = weak.lock()) Flush(cp);
      });
    }
  }

  /// Network thread: hands queued messages to the socket unless its queue is full.
  void Flush(const ClientPtr& c) {
    std::deque<Outgoing> pending;
    {
      std::lock_guard<std::mutex> lock(c->out_mutex);
      pending.swap(c->out);
      c->flush_scheduled = false;
    }
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = ws.get_con_from_hdl(c->hdl, ec);
    if (ec || !con || con->get_state() != websocketpp::session::state::open) return;
    for (auto& m : pending) {
      if (con->get_buffered_amount() > options.max_client_buffered) {
        ++dropped;
        continue;
      }
      if (m.fragment_size > 0) {
        if (!SendFragments(con, *m.data, m.fragment_size)) return;
      } else {
        ec = con->send(*m.data, m.binary ? websocketpp::frame::opcode::binary
                                         : websocketpp::frame::opcode::text);
        if (ec) return;
      }
      ++sent;
    }
  }
  /// rosbridge fragments: pieces of at most fragment_size characters of the JSON text, sent
  /// one after the other (network thread). False when the connection failed.
  bool SendFragments(const WsServer::connection_ptr& con, const std::string& text,
                     size_t fragment_size) {
    const size_t n = (text.size() + fragment_size - 1) / fragment_size;
    const std::string id = "partsim_fragment_" + std::to_string(next_fragment++);
    for (size_t i = 0; i < n; ++i) {
      websocketpp::lib::error_code ec =
          con->send(Dump(json{{"op", "fragment"},
                              {"id", id},
                              {"data", text.substr(i * fragment_size, fragment_size)},
                              {"num", i},
                              {"total", n}}),
                    websocketpp::frame::opcode::text);
      if (ec) return false;
    }
    return true;
  }

  /// Answers the callers of `provider`'s pending calls (of `service`, or all when empty) with a
  /// failed service_response saying `why`, and forgets the calls (clients_mutex held).
  void AbandonCalls(const ClientPtr& provider, const std::string& service, const std::string& why) {
    for (auto it = pending_calls.begin(); it != pending_calls.end();) {
      const PendingCall& call = it->second;
      if (call.provider.lock() == provider && (service.empty() || call.service == service)) {
        FailCall(call, why);
        it = pending_calls.erase(it);
      } else {
        ++it;
      }
    }
  }
  void FailCall(const PendingCall& call, const std::string& why) {
    ClientPtr caller = call.caller.lock();
    if (!caller) return;
    json r = {
        {"op", "service_response"}, {"service", call.service}, {"values", why}, {"result", false}};
    if (!call.id.is_null()) r["id"] = call.id;
    Enqueue(caller, Dump(r), 0);
  }
  /// Drops calls whose caller left and fails calls unanswered for kCallTimeout (clients_mutex
  /// held).
  void ExpireCalls() {
    const WallClock::time_point now = WallClock::now();
    for (auto it = pending_calls.begin(); it != pending_calls.end();) {
      const PendingCall& call = it->second;
      if (call.caller.expired()) {
        it = pending_calls.erase(it);
      } else if (now - call.since > kCallTimeout) {
        FailCall(call, "the provider of " + call.service + " did not answer in " +
                           std::to_string(kCallTimeout.count()) + " s");
        it = pending_calls.erase(it);
      } else {
        ++it;
      }
    }
  }
  /// A client left: its calls are forgotten and the callers of the services it provided told.
  void ClientGone(const ClientPtr& c) {
    for (auto it = pending_calls.begin(); it != pending_calls.end();) {
      if (it->second.caller.lock() == c)
        it = pending_calls.erase(it);
      else
        ++it;
    }
    AbandonCalls(c, "", "the provider disconnected");
  }

  void Status(const ClientPtr& c, const std::string& level, const std::string& msg,
              const json& id = nullptr) {
    json j = {{"op", "status"}, {"level", level}, {"msg", msg}};
    if (!id.is_null()) j["id"] = id;
    if (level == "error") ++errors;
    Enqueue(c, Dump(j), 0);
  }

  // ---- topics ----
  std::string Prefix() const { return "/" + robot_name; }
  std::map<std::string, std::string> SimTopics() const {
    std::map<std::string, std::string> t = {
        {"/clock", kClockType},
        {"/joint_states", kJointStateType},
        {"/tf", kTfType},
        {Prefix() + "/joint_position_controller/command", kFloat64ArrayType},
        {Prefix() + "/joint_velocity_controller/command", kFloat64ArrayType},
        {Prefix() + "/joint_effort_controller/command", kFloat64ArrayType},
        {Prefix() + "/joint_trajectory_controller/command", kTrajectoryType},
        {"/imu", kImuType}};
    for (const CameraTopics& c : cameras) {
      t.emplace(c.image, kImageType);
      t.emplace(c.info, kCameraInfoType);
      t.emplace(c.points, kPointCloud2Type);
    }
    return t;
  }
  /// Whether the simulation publishes `topic` (clients may not).
  bool Published(const std::string& topic) const {
    if (topic == "/clock" || topic == "/joint_states" || topic == "/tf" || topic == "/imu")
      return true;
    for (const CameraTopics& c : cameras)
      if (topic == c.image || topic == c.info || topic == c.points) return true;
    return false;
  }
  /// All topics with types: the simulation's and the clients' (clients_mutex held).
  std::map<std::string, std::string> AllTopics() const {
    std::map<std::string, std::string> t = SimTopics();
    for (auto& [h, c] : clients)
      for (auto& [topic, type] : c->advertised) t.emplace(topic, type);
    return t;
  }

  // ---- simulation thread: messages after each step ----
  json JointStateMsg(double t) const {
    JointStateReading r = robot->ReadJointStates();
    return {{"header", Header(t, "")},
            {"name", r.names},
            {"position", r.position},
            {"velocity", r.velocity},
            {"effort", r.effort}};
  }
  json TfMsg(double t) const {
    json tfs = json::array();
    for (const FrameReading& f : robot->ReadFrames()) {
      const Pose& X = f.pose;
      tfs.push_back(
          {{"header", Header(t, "world")},
           {"child_frame_id", f.child},
           {"transform",
            {{"translation", {{"x", X.p.x()}, {"y", X.p.y()}, {"z", X.p.z()}}},
             {"rotation", {{"x", X.q.x()}, {"y", X.q.y()}, {"z", X.q.z()}, {"w", X.q.w()}}}}}});
    }
    return {{"transforms", tfs}};
  }

  void OnStep(long long steps) {
    const double t = steps * sim->GetTimestep();
    PublishJointTopics(t);
    PublishSensors(t);
  }
  void PublishJointTopics(double t) {
    const WallClock::time_point now = WallClock::now();
    {
      std::lock_guard<std::mutex> lock(clients_mutex);
      if (clients.empty()) return;
    }
    Publish(
        "/clock",
        [&] {
          return json{{"clock", Stamp(t)}};
        },
        now);
    Publish(
        "/joint_states", [&] { return JointStateMsg(t); }, now);
    Publish(
        "/tf", [&] { return TfMsg(t); }, now);
  }

  // ---- simulation thread: sensors ----
  /// Whether some client subscribes to `topic` (clients_mutex held).
  bool Wanted(const std::string& topic) const {
    for (auto& [h, c] : clients)
      if (c->subs.count(topic)) return true;
    return false;
  }
  /// Sends `make()` (built once, and encoded once per form: JSON text or CBOR) to the clients
  /// subscribed to `topic` that are not throttled. uint8[] fields are json::binary values: base64
  /// strings in JSON, byte strings in CBOR.
  void Publish(const std::string& topic, const std::function<json()>& make,
               WallClock::time_point now) {
    json msg;
    std::shared_ptr<const std::string> text, cbor;
    std::lock_guard<std::mutex> lock(clients_mutex);
    for (auto& [h, c] : clients) {
      auto it = c->subs.find(topic);
      if (it == c->subs.end()) continue;
      Subscription& s = it->second;
      if (s.throttle_ms > 0 &&
          std::chrono::duration<double, std::milli>(now - s.last_sent).count() < s.throttle_ms)
        continue;
      if (msg.is_null()) msg = json{{"op", "publish"}, {"topic", topic}, {"msg", make()}};
      s.last_sent = now;
      // encoded once; each client gets a pointer (this is the simulation thread)
      if (s.cbor) {
        if (!cbor) {
          std::vector<uint8_t> bytes = json::to_cbor(msg);
          cbor = std::make_shared<const std::string>(bytes.begin(), bytes.end());
        }
        Enqueue(c, cbor, s.queue_length, true, topic);
        continue;
      }
      if (!text) text = std::make_shared<const std::string>(Dump(TextForm(msg)));
      const size_t fragment = text->size() > s.fragment_size ? s.fragment_size : 0;
      Enqueue(c, text, s.queue_length, false, topic, fragment);
    }
  }
  /// The message for JSON clients: binary fields become base64 strings.
  static json TextForm(json j) {
    if (j.is_binary()) return Base64(j.get_binary().data(), j.get_binary().size());
    if (j.is_object() || j.is_array())
      for (auto& v : j) v = TextForm(std::move(v));
    return j;
  }
  static json Header(double t, const std::string& frame) {
    return {{"seq", 0}, {"stamp", Stamp(t)}, {"frame_id", frame}};
  }
  static json ImageMsg(const Camera& cam, double t, const std::string& frame) {
    const int w = cam.GetWidth(), h = cam.GetHeight();
    std::vector<uint8_t> rgb = CameraRgb8(cam);
    return {{"header", Header(t, frame)},
            {"height", h},
            {"width", w},
            {"encoding", "rgb8"},
            {"is_bigendian", 0},
            {"step", w * 3},
            {"data", json::binary(std::move(rgb))}};
  }
  static json CameraInfoMsg(const Camera& cam, double t, const std::string& frame) {
    std::vector<double> p = CameraProjection(cam);
    json k = {p[0], p[1], p[2], p[4], p[5], p[6], p[8], p[9], p[10]};
    return {
        {"header", Header(t, frame)},
        {"height", cam.GetHeight()},
        {"width", cam.GetWidth()},
        {"distortion_model", "plumb_bob"},
        {"D", {0.0, 0.0, 0.0, 0.0, 0.0}},
        {"K", k},
        {"R", {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}},
        {"P", p},
        {"binning_x", 0},
        {"binning_y", 0},
        {"roi",
         {{"x_offset", 0}, {"y_offset", 0}, {"height", 0}, {"width", 0}, {"do_rectify", false}}}};
  }
  /// The points seen, in the optical frame (x right, y down, z forward), as x, y, z float32.
  static json PointsMsg(const Camera& cam, double t, const std::string& frame) {
    static_assert(sizeof(float) == 4, "float32 points");
    std::vector<float> xyz = CameraOpticalPoints(cam);
    json fields = json::array();
    const char* names[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k)
      fields.push_back({{"name", names[k]}, {"offset", 4 * k}, {"datatype", 7}, {"count", 1}});
    const size_t n = xyz.size() / 3;
    return {{"header", Header(t, frame)},
            {"height", 1},
            {"width", n},
            {"fields", fields},
            {"is_bigendian", false},
            {"point_step", 12},
            {"row_step", 12 * n},
            {"data", json::binary(std::vector<uint8_t>(
                         reinterpret_cast<const uint8_t*>(xyz.data()),
                         reinterpret_cast<const uint8_t*>(xyz.data()) + xyz.size() * 4))},
            {"is_dense", true}};
  }
  json ImuMsg(double t) const {
    ImuReading r = robot->GetImu()->Read();
    const json zeros = std::vector<double>(9, 0.0);
    return {{"header", Header(t, robot->GetImuFrame())},
            {"orientation",
             {{"x", r.orientation[1]},
              {"y", r.orientation[2]},
              {"z", r.orientation[3]},
              {"w", r.orientation[0]}}},
            {"orientation_covariance", zeros},
            {"angular_velocity", Vector3(r.angular_velocity)},
            {"angular_velocity_covariance", zeros},
            {"linear_acceleration", Vector3(r.linear_acceleration)},
            {"linear_acceleration_covariance", zeros}};
  }

  /// After a step: reads the sensors somebody subscribes to, when due, and publishes them.
  void PublishSensors(double t) {
    const double eps = 1e-9;
    const WallClock::time_point now = WallClock::now();
    const ServedRobotOptions& ro = robot->GetOptions();
    std::vector<CameraSensor>& sensors = robot->GetCameras();
    bool want_imu = false;
    std::vector<std::array<bool, 3>> want(cameras.size(), {false, false, false});
    {
      std::lock_guard<std::mutex> lock(clients_mutex);
      if (clients.empty()) return;
      want_imu = robot->GetImu() && t + eps >= imu_next && Wanted("/imu");
      for (size_t i = 0; i < cameras.size(); ++i) {
        const CameraTopics& c = cameras[i];
        if (t + eps >= c.next_render) want[i] = {Wanted(c.image), Wanted(c.points), false};
        if (t + eps >= c.next_info) want[i][2] = Wanted(c.info);
      }
    }
    if (want_imu) {
      imu_next = ro.imu_rate > 0 ? t + 1.0 / ro.imu_rate : 0;
      Publish(
          "/imu", [&] { return ImuMsg(t); }, now);
    }
    const double period = ro.camera_rate > 0 ? 1.0 / ro.camera_rate : 0;
    for (size_t i = 0; i < cameras.size(); ++i) {
      CameraTopics& c = cameras[i];
      const std::string& frame = sensors[i].frame;
      if (want[i][0] || want[i][1]) {
        const Camera& cam = robot->TakePicture(i);
        c.next_render = t + period;
        if (want[i][0])
          Publish(
              c.image, [&] { return ImageMsg(cam, t, frame); }, now);
        if (want[i][1])
          Publish(
              c.points, [&] { return PointsMsg(cam, t, frame); }, now);
      }
      if (want[i][2]) {
        c.next_info = t + period;
        Publish(
            c.info, [&] { return CameraInfoMsg(sensors[i].camera, t, frame); }, now);
      }
    }
  }

  // ---- commands (applied on the simulation thread) ----
  ServedRobot::ErrorSink ErrorsTo(const ClientPtr& client, const json& id) {
    std::weak_ptr<Client> weak = client;
    return [this, weak, id](const std::string& e) {
      if (ClientPtr c = weak.lock()) Status(c, "error", e, id);
    };
  }

  /// Checks and applies a message published to one of the simulation's command topics.
  void HandleCommand(const ClientPtr& c, const std::string& topic, const json& msg,
                     const json& id) {
    if (!msg.is_object()) throw Error("publish to " + topic + ": msg is not an object");
    for (const char* kind : {"position", "velocity", "effort"}) {
      if (topic != Prefix() + "/joint_" + kind + "_controller/command") continue;
      if (!msg.contains("data")) throw Error(topic + ": std_msgs/Float64MultiArray needs 'data'");
      std::vector<double> data = Numbers(msg["data"], topic + " data");
      if (kind[0] == 'p')
        robot->CommandPositions(data, topic, ErrorsTo(c, id));
      else if (kind[0] == 'v')
        robot->CommandVelocities(data, topic, ErrorsTo(c, id));
      else
        robot->CommandEfforts(data, topic, ErrorsTo(c, id));
      return;
    }
    TrajectoryCommand cmd = ParseTrajectory(msg, topic);
    auto errors = ErrorsTo(c, id);
    robot->CommandTrajectory(cmd, topic, [errors](TrajectoryOutcome o, const std::string& m) {
      if (o == TrajectoryOutcome::kInvalidGoal) errors(m);
    });
  }

  /// A trajectory_msgs/JointTrajectory; throws naming `what`.
  static TrajectoryCommand ParseTrajectory(const json& msg, const std::string& what) {
    if (!msg.is_object() || !msg.contains("joint_names") || !msg["joint_names"].is_array() ||
        !msg.contains("points") || !msg["points"].is_array())
      throw Error(what + ": trajectory_msgs/JointTrajectory needs joint_names and points");
    TrajectoryCommand cmd;
    for (const json& name : msg["joint_names"]) {
      if (!name.is_string()) throw Error(what + ": joint_names holds a non-string");
      cmd.joint_names.push_back(name.get<std::string>());
    }
    if (msg["points"].empty()) throw Error(what + ": no points");
    for (size_t k = 0; k < msg["points"].size(); ++k) {
      const json& p = msg["points"][k];
      std::string where = what + " points[" + std::to_string(k) + "]";
      if (!p.is_object() || !p.contains("positions")) throw Error(where + " has no positions");
      cmd.positions.push_back(Numbers(p["positions"], where + ".positions"));
      if (p.contains("velocities") && p["velocities"].is_array() && !p["velocities"].empty())
        cmd.velocities.push_back(Numbers(p["velocities"], where + ".velocities"));
      cmd.times.push_back(p.contains("time_from_start")
                              ? Duration(p["time_from_start"], where + ".time_from_start")
                              : 0.0);
    }
    if (!cmd.velocities.empty() && cmd.velocities.size() != cmd.positions.size())
      cmd.velocities.clear();  // velocities on some points only: interpolate positions alone
    return cmd;
  }

  // ---- services ----
  /// Built-in services; returns false if `service` is not one.
  std::vector<std::string> BuiltinServices() const {
    return {"/rosapi/topics", "/rosapi/topic_type", "/rosapi/services",
            "/partsim/pause", "/partsim/resume",    "/partsim/reset",
            "/partsim/step",  "/partsim/stats",     Prefix() + "/plan"};
  }
  bool CallBuiltinName(const std::string& service) const {
    for (const std::string& b : BuiltinServices())
      if (b == service) return true;
    return false;
  }
  bool CallBuiltin(const ClientPtr& c, const std::string& service, const json& args,
                   const json& id) {
    json values;
    if (service == "/rosapi/topics") {
      json topics = json::array(), types = json::array();
      std::lock_guard<std::mutex> lock(clients_mutex);
      for (auto& [t, ty] : AllTopics()) {
        topics.push_back(t);
        types.push_back(ty);
      }
      values = {{"topics", topics}, {"types", types}};
    } else if (service == "/rosapi/topic_type") {
      if (!args.is_object() || !args.contains("topic") || !args["topic"].is_string())
        throw Error("/rosapi/topic_type needs args {topic: string}");
      std::lock_guard<std::mutex> lock(clients_mutex);
      auto all = AllTopics();
      auto it = all.find(args["topic"].get<std::string>());
      values = {{"type", it == all.end() ? "" : it->second}};
    } else if (service == "/rosapi/services") {
      json names = BuiltinServices();
      std::lock_guard<std::mutex> lock(clients_mutex);
      for (auto& [h, cl] : clients)
        for (const std::string& s : cl->services) names.push_back(s);
      values = {{"services", names}};
    } else if (service == "/partsim/pause") {
      sim->Pause();
      values = json::object();
    } else if (service == "/partsim/resume") {
      sim->Resume();
      values = json::object();
    } else if (service == "/partsim/reset") {
      sim->Reset();
      values = json::object();
    } else if (service == "/partsim/step") {
      long long n = 1;
      if (args.is_object() && args.contains("n")) {
        // the whole range is checked: no integer is truncated into a valid one
        const json& a = args["n"];
        const bool in_range =
            a.is_number_unsigned()
                ? a.get<uint64_t>() <= static_cast<uint64_t>(SimServer::kMaxStepRequest)
                : a.is_number_integer();
        if (!in_range || a.get<long long>() < 1)
          throw Error("/partsim/step: n must be an integer from 1 to " +
                      std::to_string(SimServer::kMaxStepRequest) + ", got " + Dump(a));
        n = a.get<long long>();
      }
      sim->StepN(n);
      values = json::object();
    } else if (service == "/partsim/stats") {
      RosbridgeStats s = Stats();
      values = {{"clients", s.clients},
                {"messages_sent", s.messages_sent},
                {"messages_dropped", s.messages_dropped},
                {"commands", s.commands},
                {"mean_latency_steps", s.mean_latency_steps},
                {"max_latency_steps", s.max_latency_steps},
                {"clock_steps", sim->GetClockSteps()},
                {"timestep", sim->GetTimestep()}};
    } else if (service == Prefix() + "/plan") {
      CallPlan(c, service, args, id);
      return true;
    } else {
      return false;
    }
    json r = {
        {"op", "service_response"}, {"service", service}, {"values", values}, {"result", true}};
    if (!id.is_null()) r["id"] = id;
    Enqueue(c, Dump(r), 0);
    return true;
  }

  /// /<robot>/plan: {joint_goal: [..]} or {pose_goal: geometry_msgs/Pose}, optional execute
  /// (default true), time_limit, clearance, algorithm. Answers once planned (from the worker).
  void CallPlan(const ClientPtr& c, const std::string& service, const json& args, const json& id) {
    if (!args.is_object()) throw Error(service + ": args must be an object");
    PlanRequest req;
    if (args.contains("joint_goal")) {
      req.joint_goal = Numbers(args["joint_goal"], service + " joint_goal");
    } else if (args.contains("pose_goal") && args["pose_goal"].is_object()) {
      const json& pg = args["pose_goal"];
      if (!pg.contains("position") || !pg.contains("orientation"))
        throw Error(service + ": pose_goal needs position and orientation");
      auto num = [&](const json& o, const char* k) {
        if (!o.is_object() || !o.contains(k) || !o[k].is_number())
          throw Error(service + ": pose_goal field '" + k + "' is missing or not a number");
        return o[k].get<double>();
      };
      const json &p = pg["position"], &q = pg["orientation"];
      req.pose_goal = Pose(Eigen::Vector3d(num(p, "x"), num(p, "y"), num(p, "z")),
                           Eigen::Quaterniond(num(q, "w"), num(q, "x"), num(q, "y"), num(q, "z")));
    } else {
      throw Error(service + ": args need joint_goal (one value per joint) or pose_goal");
    }
    if (args.contains("execute")) {
      if (!args["execute"].is_boolean()) throw Error(service + ": execute must be a boolean");
      req.execute = args["execute"].get<bool>();
    }
    for (const char* k : {"time_limit", "clearance"})
      if (args.contains(k)) {
        if (!args[k].is_number()) throw Error(service + ": " + k + " must be a number");
        (k[0] == 't' ? req.options.time_limit : req.options.clearance) = args[k].get<double>();
      }
    if (args.contains("algorithm")) req.options.algorithm = Str(args, "algorithm", service);
    std::weak_ptr<Client> weak = c;
    robot->Plan(req, [this, weak, service, id](const PlanResult& r) {
      ClientPtr cp = weak.lock();
      if (!cp) return;
      json points = json::array();
      const JointTrajectory& t = r.trajectory;
      for (size_t k = 0; k < t.times.size(); ++k) {
        json p = {{"positions", std::vector<double>(t.positions[k].data(),
                                                    t.positions[k].data() + t.positions[k].size())},
                  {"time_from_start", Stamp(t.times[k])}};
        if (!t.velocities.empty())
          p["velocities"] = std::vector<double>(t.velocities[k].data(),
                                                t.velocities[k].data() + t.velocities[k].size());
        points.push_back(p);
      }
      json values = {{"success", r.success},
                     {"message", r.message},
                     {"planning_time", r.planning_time},
                     {"trajectory", {{"joint_names", robot->GetJointNames()}, {"points", points}}}};
      json out = {
          {"op", "service_response"}, {"service", service}, {"values", values}, {"result", true}};
      if (!id.is_null()) out["id"] = id;
      Enqueue(cp, Dump(out), 0);
    });
  }

  RosbridgeStats Stats() const {
    RosbridgeStats s;
    {
      std::lock_guard<std::mutex> lock(clients_mutex);
      s.clients = static_cast<long long>(clients.size());
    }
    s.messages_sent = sent;
    s.messages_dropped = dropped;
    CommandStats cs = robot->GetCommandStats();
    s.commands = cs.commands;
    s.mean_latency_steps = cs.mean_latency_steps;
    s.max_latency_steps = cs.max_latency_steps;
    s.errors = errors;
    s.refused = refused;
    s.accept_errors = accept_errors;
    return s;
  }

  // ---- network thread: one incoming message ----
  void OnMessage(Hdl hdl, WsServer::message_ptr m) {
    ClientPtr c;
    {
      std::lock_guard<std::mutex> lock(clients_mutex);
      auto it = clients.find(hdl);
      if (it == clients.end()) return;
      c = it->second;
    }
    // nothing a client sends may end the network thread
    try {
      HandleText(c, m->get_payload());
    } catch (const std::exception& e) {
      try {
        Status(c, "error", std::string("could not handle the message: ") + e.what());
      } catch (...) {
      }
    } catch (...) {
    }
  }

  /// One whole message (or one fragment of one) from a client.
  void HandleText(const ClientPtr& c, const std::string& payload) {
    json j;
    try {
      j = ParseClientJson(payload);
    } catch (const std::exception& e) {
      Status(c, "error", std::string("malformed JSON: ") + e.what());
      return;
    }
    json id = j.is_object() && j.contains("id") ? j["id"] : json();
    if (!c->authenticated) {
      // with a token set, nothing but the auth op until it has come right
      const bool auth = j.is_object() && j.contains("op") && j["op"] == "auth";
      if (!auth) {
        Status(c, "error",
               "authenticate first: send {\"op\": \"auth\", \"mac\": <the server's token>}", id);
        return;
      }
      const bool ok = j.contains("mac") && j["mac"].is_string() &&
                      SameToken(j["mac"].get<std::string>(), options.auth_token);
      if (!ok) {
        Status(c, "error", "auth: wrong token; closing the connection", id);
        websocketpp::lib::error_code ec;
        ws.close(c->hdl, websocketpp::close::status::policy_violation, "authentication failed", ec);
        return;
      }
      c->authenticated = true;
      Status(c, "info", "authenticated", id);
      return;
    }
    if (j.is_object() && j.value("op", "") == "fragment") {
      try {
        std::string whole;
        if (Reassemble(c, j, &whole)) HandleText(c, whole);
      } catch (const std::exception& e) {
        Status(c, "error", e.what(), id);
      }
      return;
    }
    try {
      if (!j.is_object() || !j.contains("op") || !j["op"].is_string())
        throw Error("message has no 'op' string");
      Handle(c, j["op"].get<std::string>(), j, id);
    } catch (const std::exception& e) {
      Status(c, "error", e.what(), id);
    }
  }

  /// Adds a fragment {id, data, num, total}; true with the whole text once all have come.
  bool Reassemble(const ClientPtr& c, const json& j, std::string* whole) {
    if (!j.contains("id") || !(j["id"].is_string() || j["id"].is_number()))
      throw Error("fragment needs an 'id'");
    if (!j.contains("data") || !j["data"].is_string()) throw Error("fragment needs string 'data'");
    if (!j.contains("num") || !j["num"].is_number_unsigned() || !j.contains("total") ||
        !j["total"].is_number_unsigned() || j["total"].get<size_t>() == 0 ||
        j["num"].get<size_t>() >= j["total"].get<size_t>())
      throw Error("fragment needs integers 0 <= num < total");
    const std::string key = j["id"].is_string() ? j["id"].get<std::string>() : Dump(j["id"]);
    const size_t total = j["total"].get<size_t>(), num = j["num"].get<size_t>();
    if (total > kMaxFragmentsHeld)
      throw Error("fragment: total " + std::to_string(total) + " is more than " +
                  std::to_string(kMaxFragmentsHeld) + " pieces");
    auto it = c->partial.find(key);
    if (it == c->partial.end()) {
      if (c->partial.size() >= 16) throw Error("fragment: too many messages in pieces at once");
      it = c->partial.emplace(key, Partial()).first;
      it->second.total = total;
    }
    Partial& p = it->second;
    if (p.total != total) {
      c->partial.erase(it);
      throw Error("fragment '" + key + "': total changed between pieces");
    }
    const std::string& data = j["data"].get_ref<const std::string&>();
    // the bytes held for this client, all its messages in pieces together, stay within one
    // message's bound
    size_t held = 0, held_pieces = 0;
    for (const auto& [k, other] : c->partial) {
      held += other.bytes;
      held_pieces += other.pieces.size();
    }
    if (held_pieces >= kMaxFragmentsHeld && !p.pieces.count(num)) {
      c->partial.erase(it);
      throw Error("fragment '" + key + "': more than " + std::to_string(kMaxFragmentsHeld) +
                  " pieces held for this client");
    }
    auto old_piece = p.pieces.find(num);
    const size_t replaced = old_piece == p.pieces.end() ? 0 : old_piece->second.size();
    if (held - replaced + data.size() > options.max_message_bytes) {
      c->partial.erase(it);
      throw Error("fragment '" + key + "': the pieces held for this client exceed " +
                  std::to_string(options.max_message_bytes) + " bytes");
    }
    p.bytes = p.bytes - replaced + data.size();
    p.pieces[num] = data;
    if (p.pieces.size() < total) return false;
    whole->clear();
    whole->reserve(p.bytes);
    for (const auto& [k, piece] : p.pieces) *whole += piece;
    c->partial.erase(it);
    return true;
  }

  static std::string Str(const json& j, const char* key, const std::string& op) {
    if (!j.contains(key) || !j[key].is_string())
      throw Error("op '" + op + "' needs a string '" + key + "'");
    return j[key].get<std::string>();
  }
  /// A topic or service name; ROS resolves "rosapi/topics" to "/rosapi/topics" at the root.
  static std::string Name(const json& j, const char* key, const std::string& op) {
    std::string n = Str(j, key, op);
    if (n.empty()) throw Error("op '" + op + "': empty '" + key + "'");
    return n[0] == '/' ? n : "/" + n;
  }

  void Handle(const ClientPtr& c, const std::string& op, const json& j, const json& id) {
    const auto sim_topics = SimTopics();
    if (op == "subscribe") {
      std::string topic = Name(j, "topic", op);
      if (j.contains("type") && j["type"].is_string()) {
        std::lock_guard<std::mutex> lock(clients_mutex);
        auto all = AllTopics();
        auto it = all.find(topic);
        if (it != all.end() && it->second != j["type"].get<std::string>())
          throw Error("subscribe " + topic + ": type is " + it->second + ", not " +
                      j["type"].get<std::string>());
      }
      Request s;
      s.order = next_request++;
      if (j.contains("throttle_rate") && j["throttle_rate"].is_number())
        s.throttle_ms = j["throttle_rate"].get<double>();
      if (j.contains("queue_length") && j["queue_length"].is_number_integer() &&
          j["queue_length"].get<long long>() > 0)
        s.queue_length = static_cast<size_t>(j["queue_length"].get<long long>());
      if (j.contains("fragment_size") && j["fragment_size"].is_number_integer() &&
          j["fragment_size"].get<long long>() > 0)
        s.fragment_size = static_cast<size_t>(j["fragment_size"].get<long long>());
      if (j.contains("compression") && j["compression"].is_string()) {
        const std::string comp = j["compression"].get<std::string>();
        if (comp == "cbor")
          s.cbor = true;
        else if (comp != "none" && comp != "")
          throw Error("subscribe " + topic + ": compression '" + comp +
                      "' is not supported (none, cbor)");
      }
      const std::string sub_id = id.is_null()     ? ""
                                 : id.is_string() ? id.get<std::string>()
                                                  : Dump(id);
      std::lock_guard<std::mutex> lock(clients_mutex);
      if (!c->subs.count(topic) && c->subs.size() >= options.max_subscriptions)
        throw Error("subscribe " + topic + ": this client already subscribes to " +
                    std::to_string(c->subs.size()) + " topics (at most " +
                    std::to_string(options.max_subscriptions) + ")");
      Subscription& sub = c->subs[topic];
      if (!sub.requests.count(sub_id) && sub.requests.size() >= kMaxRequestsPerTopic)
        throw Error("subscribe " + topic + ": " + std::to_string(sub.requests.size()) +
                    " subscribe requests of this client are open on it (at most " +
                    std::to_string(kMaxRequestsPerTopic) + ")");
      sub.requests[sub_id] = s;
      sub.Merge();
    } else if (op == "unsubscribe") {
      // with an id: that subscribe request only; without: the whole topic
      std::string topic = Name(j, "topic", op);
      std::lock_guard<std::mutex> lock(clients_mutex);
      auto it = c->subs.find(topic);
      if (it == c->subs.end()) return;
      if (!id.is_null()) {
        it->second.requests.erase(id.is_string() ? id.get<std::string>() : Dump(id));
        if (!it->second.requests.empty()) {
          it->second.Merge();
          return;
        }
      }
      c->subs.erase(it);
    } else if (op == "advertise") {
      std::string topic = Name(j, "topic", op), type = Str(j, "type", op);
      auto it = sim_topics.find(topic);
      if (it != sim_topics.end() && it->second != type)
        throw Error("advertise " + topic + ": its type is " + it->second + ", not " + type);
      std::lock_guard<std::mutex> lock(clients_mutex);
      for (auto& [h, other] : clients) {
        auto o = other->advertised.find(topic);
        if (o != other->advertised.end() && o->second != type)
          throw Error("advertise " + topic + ": already advertised as " + o->second);
      }
      if (!c->advertised.count(topic) && c->advertised.size() >= options.max_subscriptions)
        throw Error("advertise " + topic + ": this client already advertises " +
                    std::to_string(c->advertised.size()) + " topics (at most " +
                    std::to_string(options.max_subscriptions) + ")");
      c->advertised[topic] = type;
    } else if (op == "unadvertise") {
      std::string topic = Name(j, "topic", op);
      std::lock_guard<std::mutex> lock(clients_mutex);
      c->advertised.erase(topic);
    } else if (op == "publish") {
      std::string topic = Name(j, "topic", op);
      if (!j.contains("msg")) throw Error("publish " + topic + ": no 'msg'");
      if (Published(topic))
        throw Error("publish " + topic + ": the simulation publishes this topic");
      if (sim_topics.count(topic)) {
        HandleCommand(c, topic, j["msg"], id);
        return;
      }
      // a client's own topic: relay to its subscribers
      std::string text = Dump(json{{"op", "publish"}, {"topic", topic}, {"msg", j["msg"]}});
      std::lock_guard<std::mutex> lock(clients_mutex);
      for (auto& [h, other] : clients) {
        auto it = other->subs.find(topic);
        if (it != other->subs.end()) Enqueue(other, text, it->second.queue_length, false, topic);
      }
    } else if (op == "call_service") {
      std::string service = Name(j, "service", op);
      json args = j.contains("args") ? j["args"] : json::object();
      if (CallBuiltin(c, service, args, id)) return;
      // a service some client advertised: forward it with our own id, which no other client
      // can guess
      std::lock_guard<std::mutex> lock(clients_mutex);
      ExpireCalls();
      for (auto& [h, provider] : clients) {
        if (!provider->services.count(service)) continue;
        size_t mine = 0;
        for (const auto& [k, call] : pending_calls) mine += call.caller.lock() == c;
        if (mine >= kMaxPendingCalls)
          throw Error("call_service " + service + ": " + std::to_string(mine) +
                      " calls of this client are still unanswered (at most " +
                      std::to_string(kMaxPendingCalls) + ")");
        char buf[64];
        std::snprintf(buf, sizeof(buf), "partsim_call_%016llx%016llx",
                      static_cast<unsigned long long>(call_ids()),
                      static_cast<unsigned long long>(call_ids()));
        pending_calls[buf] = {c, id, provider, service, WallClock::now()};
        Enqueue(
            provider,
            Dump(json{{"op", "call_service"}, {"service", service}, {"args", args}, {"id", buf}}),
            0);
        return;
      }
      throw Error("call_service: no service '" + service + "'");
    } else if (op == "advertise_service") {
      std::string service = Name(j, "service", op);
      std::lock_guard<std::mutex> lock(clients_mutex);
      if (CallBuiltinName(service))
        throw Error("advertise_service " + service + ": partsim provides this service");
      for (auto& [h, other] : clients)
        if (other != c && other->services.count(service))
          throw Error("advertise_service " + service +
                      ": another client provides this service (it must unadvertise first)");
      if (!c->services.count(service) && c->services.size() >= options.max_services)
        throw Error("advertise_service " + service + ": this client already provides " +
                    std::to_string(c->services.size()) + " services (at most " +
                    std::to_string(options.max_services) + ")");
      c->services.insert(service);
    } else if (op == "unadvertise_service") {
      std::string service = Name(j, "service", op);
      std::lock_guard<std::mutex> lock(clients_mutex);
      c->services.erase(service);
      AbandonCalls(c, service, "the provider unadvertised " + service);
    } else if (op == "service_response") {
      if (!j.contains("id") || !j["id"].is_string())
        throw Error("service_response needs the 'id' of the call it answers");
      std::lock_guard<std::mutex> lock(clients_mutex);
      auto it = pending_calls.find(j["id"].get<std::string>());
      // only the client the call went to may answer it
      if (it == pending_calls.end() || it->second.provider.lock() != c)
        throw Error("service_response: no pending call '" + j["id"].get<std::string>() +
                    "' to this client");
      json r = j;
      if (it->second.id.is_null())
        r.erase("id");
      else
        r["id"] = it->second.id;
      if (ClientPtr caller = it->second.caller.lock()) Enqueue(caller, Dump(r), 0);
      pending_calls.erase(it);
    } else if (op == "auth") {
      // already authenticated, or no token is set
      Status(c, "info", options.auth_token.empty() ? "no token needed" : "authenticated", id);
    } else {
      throw Error("unknown op '" + op + "'");
    }
  }
};

RosbridgeServer::RosbridgeServer(ServedRobot* robot, const RosbridgeOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (!robot) throw Error("RosbridgeServer: robot is null");
  Impl& m = *impl_;
  m.robot = robot;
  m.sim = robot->GetSim();
  m.robot_name = robot->GetName();
  m.options = options;
  for (const CameraSensor& cam : robot->GetCameras()) {
    Impl::CameraTopics c;
    const std::string base = "/" + cam.name;
    c.image = base + "/image_raw";
    c.info = base + "/camera_info";
    c.points = base + "/points";
    m.cameras.push_back(c);
  }
  m.sim->AddStepCallback([this](long long steps) {
    if (impl_->started) impl_->OnStep(steps);
  });

  m.ws.clear_access_channels(websocketpp::log::alevel::all);
  m.ws.clear_error_channels(websocketpp::log::elevel::all);
  m.ws.init_asio();
  m.ws.set_reuse_addr(true);
  m.ws.set_max_message_size(options.max_message_bytes);
  // a connection that has not finished its handshake within 2 s is dropped, so that sockets
  // opened and left silent do not pile up towards the descriptor limit
  m.ws.set_open_handshake_timeout(2000);
  // the handshake: a browser page from an origin not allowed, or one connection too many,
  // is refused before it becomes a client
  m.ws.set_validate_handler([this](Hdl h) {
    Impl& im = *impl_;
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = im.ws.get_con_from_hdl(h, ec);
    if (ec || !con) return false;
    if (!OriginAllowed(con->get_origin(), im.options.allowed_origins)) {
      ++im.refused;
      con->set_status(websocketpp::http::status_code::forbidden);
      return false;
    }
    std::lock_guard<std::mutex> lock(im.clients_mutex);
    if (im.clients.size() >= im.options.max_clients) {
      ++im.refused;
      con->set_status(websocketpp::http::status_code::service_unavailable);
      return false;
    }
    return true;
  });
  // with log_clients, a line per client that comes or goes: its address and the count after
  auto log_client = [this](const Impl::Client& c, const char* what, size_t count) {
    if (!impl_->options.log_clients) return;
    std::fprintf(stderr, "partsim serve: client %s %s (%zu client%s connected)\n",
                 c.address.c_str(), what, count, count == 1 ? "" : "s");
  };
  m.ws.set_open_handler([this, log_client](Hdl h) {
    auto c = std::make_shared<Impl::Client>();
    c->hdl = h;
    c->authenticated = impl_->options.auth_token.empty();
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = impl_->ws.get_con_from_hdl(h, ec);
    c->address = !ec && con ? con->get_remote_endpoint() : "(unknown address)";
    std::lock_guard<std::mutex> lock(impl_->clients_mutex);
    impl_->clients[h] = c;
    log_client(*c, "connected", impl_->clients.size());
  });
  auto gone = [this, log_client](Hdl h) {
    std::lock_guard<std::mutex> lock(impl_->clients_mutex);
    auto it = impl_->clients.find(h);
    if (it == impl_->clients.end()) return;
    Impl::ClientPtr c = it->second;
    impl_->clients.erase(it);
    impl_->ClientGone(c);
    log_client(*c, "disconnected", impl_->clients.size());
  };
  m.ws.set_close_handler(gone);
  m.ws.set_fail_handler(gone);
  m.ws.set_message_handler([this](Hdl h, WsServer::message_ptr msg) { impl_->OnMessage(h, msg); });
}

RosbridgeServer::~RosbridgeServer() { Stop(); }

void RosbridgeServer::Start() {
  Impl& m = *impl_;
  if (m.started) throw Error("RosbridgeServer: already started");
  websocketpp::lib::error_code ec;
  // an address, or a host name resolved to its first address
  boost::system::error_code bec;
  boost::asio::ip::address addr = boost::asio::ip::make_address(m.options.address, bec);
  if (bec) {
    boost::asio::ip::tcp::resolver resolver(m.ws.get_io_service());
    auto found = resolver.resolve(m.options.address, "", bec);
    if (bec || found.empty())
      throw Error("rosbridge: cannot resolve the address '" + m.options.address +
                  "': " + (bec ? bec.message() : "no address"));
    addr = found.begin()->endpoint().address();
  }
  if (!addr.is_loopback())
    std::fprintf(stderr,
                 "partsim: warning: rosbridge listens on %s (%s), reachable from other machines: "
                 "anyone who can connect can move the robot and stop the simulation%s\n",
                 m.options.address.c_str(), addr.to_string().c_str(),
                 m.options.auth_token.empty() ? "; set a token (--token)" : "");
  boost::asio::ip::tcp::endpoint ep(addr, static_cast<unsigned short>(m.options.port));
  m.ws.listen(ep, ec);
  if (ec) {
    // websocketpp reports socket errors as "Underlying Transport Error"; the operating
    // system's reason ("Address already in use") comes from binding a plain socket the same way
    std::string why = ec.message();
    boost::asio::ip::tcp::acceptor probe(m.ws.get_io_service());
    probe.open(ep.protocol(), bec);
    if (!bec) probe.set_option(boost::asio::socket_base::reuse_address(true), bec);
    if (!bec) probe.bind(ep, bec);
    if (!bec) probe.listen(boost::asio::socket_base::max_listen_connections, bec);
    if (bec == boost::asio::error::address_in_use)
      why =
          "address already in use (another program, perhaps another partsim serve, listens "
          "there)";
    else if (bec)
      why = bec.message();
    throw Error("rosbridge: cannot listen on " + m.options.address + ":" +
                std::to_string(m.options.port) + ": " + why);
  }
  m.accept_timer = std::make_unique<boost::asio::steady_timer>(m.ws.get_io_service());
  m.StartAccept();
  m.port = m.ws.get_local_endpoint(bec).port();
  m.io_thread = std::thread([this] { impl_->ws.run(); });
  m.started = true;
}

void RosbridgeServer::Stop() {
  Impl& m = *impl_;
  if (!m.started) return;
  m.started = false;
  websocketpp::lib::error_code ec;
  m.ws.stop_listening(ec);
  if (m.accept_timer) m.accept_timer->cancel();
  m.ws.stop();
  if (m.io_thread.joinable()) m.io_thread.join();
}

int RosbridgeServer::GetPort() const { return impl_->port; }

RosbridgeStats RosbridgeServer::GetStats() const { return impl_->Stats(); }

}  // namespace partsim
