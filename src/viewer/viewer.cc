#include "partsim/viewer/viewer.h"

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "core/json_parse.h"
#include "partsim/core/error.h"
#include "partsim/physics/observer.h"
#include "partsim/physics/scene.h"
#include "partsim/render/camera.h"
#include "partsim/render/image_io.h"
#include "partsim/render/image_read.h"
#include "partsim/render/scene_render.h"
#include "partsim/server/sim_server.h"
#include "server/ros_json.h"
#include "server/web_security.h"
#include "viewer/http_util.h"
#include "viewer/png_encode.h"
#include "viewer/scene_content.h"

// The viewer's parts: websocketpp over Boost.Asio on a network thread of its own answers HTTP
// (the bundle, scene.json, meshes, textures) and the rosbridge v2 ops of the page; the scene's
// thread (Render() or a SimServer's step callback) applies the page's commands and snapshots
// what moves. Snapshots reach the network thread as immutable objects, which it compares with
// what each client was last sent and publishes; clients' state lives on the network thread only.

namespace partsim {

namespace {

namespace fs = std::filesystem;
using internal::ContentArticulation;
using internal::Json;
using internal::MotionSnapshot;
using internal::SceneContent;
using WsServer = websocketpp::server<websocketpp::config::asio>;
using Hdl = websocketpp::connection_hdl;
using Clock = std::chrono::steady_clock;

constexpr const char* kPosesTopic = "/partsim/poses";
constexpr const char* kJointStatesTopic = "/partsim/joint_states";
constexpr const char* kStatusTopic = "/partsim/status";
constexpr const char* kContactsTopic = "/partsim/contacts";
// files a texture request may send (bytes)
constexpr std::uintmax_t kMaxTextureBytes = 64u << 20;
// files of the web bundle the viewer sends (bytes)
constexpr std::uintmax_t kMaxBundleFileBytes = 256u << 20;
// commands of one client waiting for the scene's thread (set_joint_target, camera, reset):
// more are refused at once, so that one client's flood delays another's command by this many
constexpr int kMaxWaitingCommandsPerClient = 64;

const char kNoBundlePage[] = R"(<!doctype html>
<html><head><meta charset="utf-8"><title>partsim viewer</title></head>
<body style="font-family: sans-serif; max-width: 40em; margin: 3em auto">
<h1>partsim viewer</h1>
<p>The viewer's web page is not built. In partsim's source folder run</p>
<pre>bash scripts/build_web.sh</pre>
<p>then reload this page (or point <code>PARTSIM_WEB_DIR</code> at a built bundle).
The scene is served meanwhile: <code>/api/scene.json?token=...</code>.</p>
</body></html>
)";

/// A connected WebSocket client (network thread only).
struct ViewerClient {
  Hdl connection;
  bool authenticated = false;
  /// commands queued for the scene's thread and not run yet (counted down there)
  std::shared_ptr<std::atomic<int>> waiting = std::make_shared<std::atomic<int>>(0);
  /// closes the connection unless it authenticates in time (ViewerOptions::auth_timeout)
  std::unique_ptr<boost::asio::steady_timer> auth_timer;
  std::set<std::string> topics;
  long long poses_version = -1;  ///< content version of sent_poses; -1: send every body next
  std::vector<double> sent_poses;
  long long joints_version = -1;
  std::vector<std::vector<double>> sent_qpos;
};
using ClientPtr = std::shared_ptr<ViewerClient>;

bool IsViewerTopic(const std::string& t) {
  return t == kPosesTopic || t == kJointStatesTopic || t == kStatusTopic || t == kContactsTopic;
}

std::string Dump(const Json& j) { return internal::DumpJson(j); }

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

}  // namespace

std::string FindWebRoot(const std::string& web_root) {
  if (!web_root.empty()) return web_root;
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("PARTSIM_WEB_DIR")) candidates.push_back(env);
  // an installed copy beside the binary that holds this code, wherever the prefix is (a .deb
  // in /usr, cmake --install to any PREFIX, a wheel): PREFIX/bin/partsim,
  // PREFIX/lib/<multiarch>/libpartsim.so and PREFIX/lib/python3/dist-packages/partsim/_partsim*.so
  // all find PREFIX/share/partsim/web; in a wheel, site-packages/partsim is the prefix of its
  // bin/partsim and holds _partsim*.so itself
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&FindWebRoot), &info) != 0 &&
      info.dli_fname != nullptr) {
    std::error_code ec;
    const fs::path dir = fs::canonical(fs::path(info.dli_fname), ec).parent_path();
    if (!ec) {
      for (const char* up : {"..", "../..", "../../../..", "."})
        candidates.push_back((dir / up / "share/partsim/web").lexically_normal().string());
    }
  }
#ifdef PARTSIM_BUILD_WEB_DIR
  candidates.push_back(PARTSIM_BUILD_WEB_DIR);
#endif
  for (const std::string& c : candidates) {
    std::error_code ec;
    if (!c.empty() && fs::is_regular_file(fs::path(c) / "index.html", ec)) return c;
  }
  return "";
}

struct Viewer::Impl {
  ViewerOptions options;
  std::string token;
  std::string web_root;
  SimServer* sim = nullptr;
  double period = 1.0 / 60;  ///< s between pose snapshots

  // ---- the scene's thread ----
  Scene* scene = nullptr;
  std::shared_ptr<const SceneContent> content;  ///< the structure last snapshotted
  uint64_t description_version = 0;             ///< GetDescriptionVersion at that snapshot
  long long content_versions = 0;
  std::vector<char> initial_state;  ///< what reset restores (synchronous mode)
  Clock::time_point last_snapshot{};

  // ---- shared (mutex) ----
  mutable std::mutex mutex;
  std::condition_variable cv;
  std::deque<std::function<void()>> commands;  ///< synchronous mode: run by Render()
  bool paused = false;                         ///< synchronous mode
  long long pending_steps = 0;                 ///< synchronous mode
  std::shared_ptr<const SceneContent> shared_content;
  std::shared_ptr<const MotionSnapshot> latest;
  std::optional<Eigen::Vector3d> camera_position, camera_rpy;  ///< the page's initial camera
  std::optional<double> camera_fovy;
  std::atomic<bool> closed{false};
  std::atomic<bool> want_contacts{false};
  std::atomic<bool> started{false};
  std::atomic<bool> publish_scheduled{false};
  std::atomic<bool> snapshot_requested{false};  ///< a forced snapshot is queued already

  // ---- the network thread ----
  WsServer ws;
  std::thread io_thread;
  std::unique_ptr<boost::asio::steady_timer> status_timer;
  std::unique_ptr<boost::asio::steady_timer> accept_timer;  // network thread
  std::atomic<long long> accept_errors{0};
  std::map<Hdl, ClientPtr, std::owner_less<Hdl>> clients;
  /// connections that passed the handshake's checks and have not gone: max_clients counts these
  /// (a burst of handshakes all pass validation before any opens)
  std::set<Hdl, std::owner_less<Hdl>> slots;
  struct RateSample {
    Clock::time_point wall;
    long long step;
    double time;
  };
  std::deque<RateSample> rate_samples;
  double steps_per_second = 0, realtime_factor = 0;
  int port = 0;

  // ---- extensions (set before Start, then read only) ----
  struct ApiRoute {
    std::string prefix;
    ViewerApiRoute route;
    double timeout = 30;
  };
  std::vector<ApiRoute> api_routes;
  std::map<std::string, ViewerService> services;

  std::atomic<long long> client_count{0}, sent{0}, dropped{0}, http_requests{0}, errors{0},
      snapshots{0};

  // ================= the scene's thread =================

  /// Snapshots the structure of the scene (a new scene_version).
  void RebuildContent() {
    description_version = GetDescriptionVersion(*scene);
    content = internal::MakeSceneContent(*scene, ++content_versions);
    if (!sim) initial_state = scene->Pack();
    {
      std::lock_guard<std::mutex> lock(mutex);
      shared_content = content;
      latest = nullptr;
    }
    PostStatus();
  }

  /// Snapshots what moved, at most every `period` s unless `force`, and has it published.
  void Snapshot(bool force) {
    if (!scene) return;
    const Clock::time_point now = Clock::now();
    if (!force && now - last_snapshot < std::chrono::duration<double>(period)) return;
    last_snapshot = now;
    if (!content || GetDescriptionVersion(*scene) != description_version) RebuildContent();
    auto snap = internal::TakeMotionSnapshot(*scene, *content, want_contacts);
    if (sim) snap->step = sim->GetClockSteps();
    {
      std::lock_guard<std::mutex> lock(mutex);
      latest = std::move(snap);
    }
    ++snapshots;
    SchedulePublish();
  }

  /// Runs the commands the page queued (synchronous mode); true when there were some.
  bool RunCommands() {
    std::deque<std::function<void()>> pending;
    {
      std::lock_guard<std::mutex> lock(mutex);
      pending.swap(commands);
    }
    for (auto& c : pending) c();
    if (!pending.empty()) Snapshot(true);
    return !pending.empty();
  }

  // ================= commands from the page =================

  /// Counts a call of `client` that waits for its answer (a command for the scene's thread, a
  /// call of an extension's service); throws partsim::Error when kMaxWaitingCommandsPerClient
  /// wait already. The answer gives the place back (--*client->waiting).
  static void TakeWaitingPlace(const ClientPtr& client) {
    if (++*client->waiting > kMaxWaitingCommandsPerClient) {
      --*client->waiting;
      throw Error("too many commands waiting: at most " +
                  std::to_string(kMaxWaitingCommandsPerClient) +
                  " of a client wait for the scene's thread; wait for their answers, then call "
                  "again");
    }
  }

  /// Runs `fn` on the scene's thread and answers the call `id` of `service` with what it
  /// returns, or with its error. Throws partsim::Error when the client has
  /// kMaxWaitingCommandsPerClient commands waiting already.
  void Enqueue(const ClientPtr& client, const std::string& service, const Json& id,
               std::function<Json(Scene&)> fn) {
    TakeWaitingPlace(client);
    std::weak_ptr<ViewerClient> weak = client;
    auto run = [this, weak, waiting = client->waiting, service, id, fn] {
      --*waiting;
      Json reply;
      try {
        if (!scene) throw Error("the viewer has no scene");
        reply = internal::ServiceResponseToJson(service, fn(*scene), true, id);
      } catch (const std::exception& e) {
        ++errors;
        reply = internal::ServiceResponseToJson(service, service + ": " + e.what(), false, id);
      }
      PostReply(weak, Dump(reply));
    };
    if (sim) {
      sim->Post([this, run] {
        run();
        Snapshot(true);
      });
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      commands.push_back(run);
    }
    cv.notify_all();
  }

  /// A forced snapshot on the scene's thread (a client subscribed; a paused scene takes none).
  /// One waits at most: requests while it waits are served by it.
  void RequestSnapshot() {
    if (snapshot_requested.exchange(true)) return;
    auto take = [this] {
      snapshot_requested = false;
      Snapshot(true);
    };
    if (sim) {
      sim->Post(take);
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      commands.push_back(take);
    }
    cv.notify_all();
  }

  Json SetJointTarget(Scene& s, int a, const std::string& name, double position) {
    if (!content || a < 0 || a >= static_cast<int>(content->articulations.size()))
      throw Error("articulation " + std::to_string(a) + " does not exist (the scene has " +
                  std::to_string(content ? content->articulations.size() : 0) + ")");
    const ContentArticulation& ca = content->articulations[a];
    auto it = ca.joint_by_name.find(name);
    if (it == ca.joint_by_name.end())
      throw Error("articulation '" + ca.name + "' has no joint '" + name +
                  "' (joints with a position: " + JoinNames(ca.dof_joints) + ")");
    Articulation art(&s, ca.scene_id);
    Joint joint(&s, ca.scene_id, it->second);
    if (joint.GetDofIndex() < 0)
      throw Error("joint '" + name + "' of '" + ca.name + "' is fixed: it has no position");
    std::string message;
    if (art.IsKinematic()) {
      // a kinematic articulation has no drives: its links follow qpos
      Eigen::VectorXd q = art.GetQpos();
      q[joint.GetDofIndex()] = position;
      art.SetQpos(q);
      return {{"success", true}, {"message", "kinematic articulation: qpos set"}};
    }
    if (joint.GetDriveStiffness() == 0 && joint.GetDriveDamping() == 0) {
      // a critically damped drive at 20 rad/s on the heaviest link's mass
      double mass = 0;
      for (const Link& l : art.GetLinks()) mass = std::max(mass, l.GetMass());
      mass = std::max(mass, 1e-3);
      const double stiffness = 400 * mass, damping = 40 * mass;
      joint.SetDriveProperty(stiffness, damping);
      char buf[200];
      std::snprintf(buf, sizeof(buf),
                    "joint '%s' had no drive: it got one, stiffness %g, damping %g (from the "
                    "heaviest link, %g kg)",
                    name.c_str(), stiffness, damping, mass);
      message = buf;
    }
    joint.SetDriveTarget(position);
    return {{"success", true}, {"message", message}};
  }

  Json CameraPicture(Scene& s, const std::string& name, const std::string& picture) {
    std::vector<std::string> names;
    for (const Camera& cam : GetCameras(s)) {
      names.push_back(cam.GetName());
      if (cam.GetName() != name) continue;
      Camera c = cam;
      UpdateRender(s);
      const int w = c.GetWidth(), h = c.GetHeight();
      Json out = {{"picture", picture}, {"width", w}, {"height", h}};
      std::string png;
      if (picture == "Color") {
        c.TakePicture(kColor);
        const std::vector<uint8_t> rgba = c.GetColorRGBA8();
        png = internal::EncodePng(w, h, 4, rgba.data());
      } else if (picture == "Depth") {
        // grey: near bright, far dark, over the range seen; black where nothing is seen
        c.TakePicture(kPosition);
        const std::vector<float> depth = c.GetDepth();
        float lo = 0, hi = 0;
        bool any = false;
        for (float d : depth)
          if (d > 0) {
            lo = any ? std::min(lo, d) : d;
            hi = any ? std::max(hi, d) : d;
            any = true;
          }
        std::vector<uint8_t> grey(depth.size(), 0);
        for (size_t i = 0; i < depth.size(); ++i)
          if (depth[i] > 0)
            grey[i] = static_cast<uint8_t>(
                std::lround(55 + 200 * (hi > lo ? (hi - depth[i]) / (hi - lo) : 1.0)));
        png = internal::EncodePng(w, h, 1, grey.data());
        out["depth_range"] = {lo, hi};
      } else {
        c.TakePicture(kSegmentation);
        const std::vector<uint32_t>& seg = c.GetUintPicture("Segmentation");
        std::vector<uint8_t> rgb(3 * static_cast<size_t>(w) * h);
        for (size_t i = 0; i < rgb.size() / 3; ++i) {
          const std::array<uint8_t, 3> col = SegmentationColor(seg[2 * i + 1]);
          std::copy(col.begin(), col.end(), rgb.begin() + 3 * i);
        }
        png = internal::EncodePng(w, h, 3, rgb.data());
      }
      out["png"] = internal::Base64(reinterpret_cast<const uint8_t*>(png.data()), png.size());
      return out;
    }
    throw Error("no camera '" + name + "' (cameras: " + JoinNames(names) + ")");
  }

  // ================= the network thread =================

  /// Sends text to a client; a droppable message (a publication) is dropped when the client's
  /// socket already holds more than max_client_buffered bytes. True when sent.
  bool SendText(const ClientPtr& c, const std::string& text, bool droppable) {
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = ws.get_con_from_hdl(c->connection, ec);
    if (ec || !con || con->get_state() != websocketpp::session::state::open) return false;
    if (droppable && con->get_buffered_amount() > options.max_client_buffered) {
      ++dropped;
      return false;
    }
    ec = con->send(text, websocketpp::frame::opcode::text);
    if (ec) return false;
    ++sent;
    return true;
  }

  /// A reply from any thread (network thread to send).
  void PostReply(const std::weak_ptr<ViewerClient>& weak, std::string text) {
    if (!started) return;
    boost::asio::post(ws.get_io_service(), [this, weak, text = std::move(text)] {
      if (ClientPtr c = weak.lock()) SendText(c, text, false);
    });
  }

  void StatusError(const ClientPtr& c, const std::string& msg, const Json& id) {
    ++errors;
    SendText(c, Dump(internal::StatusToJson("error", msg, id)), false);
  }

  void SchedulePublish() {
    if (!started || publish_scheduled.exchange(true)) return;
    boost::asio::post(ws.get_io_service(), [this] {
      publish_scheduled = false;
      Publish();
    });
  }

  void PostStatus() {
    if (!started) return;
    boost::asio::post(ws.get_io_service(), [this] { PublishStatus(); });
  }

  void Latest(std::shared_ptr<const SceneContent>* c, std::shared_ptr<const MotionSnapshot>* s) {
    std::lock_guard<std::mutex> lock(mutex);
    *c = shared_content;
    *s = latest;
  }

  void Publish() {
    std::shared_ptr<const SceneContent> ct;
    std::shared_ptr<const MotionSnapshot> snap;
    Latest(&ct, &snap);
    if (!ct || !snap || snap->version != ct->version) return;
    for (auto& [h, c] : clients) PublishTo(c, *snap);
  }

  /// What moved since what `c` was sent last.
  void PublishTo(const ClientPtr& c, const MotionSnapshot& snap) {
    if (!c->authenticated) return;
    if (c->topics.count(kPosesTopic)) {
      const size_t n = snap.poses.size() / 7;
      const bool all = c->poses_version != snap.version || c->sent_poses.size() != n * 7;
      std::vector<size_t> ids;
      for (size_t i = 0; i < n; ++i)
        if (all || internal::BodyMoved(c->sent_poses, snap.poses, i)) ids.push_back(i);
      if (!ids.empty() || all) {
        char head[160];
        std::snprintf(head, sizeof(head),
                      "{\"op\":\"publish\",\"topic\":\"/partsim/poses\",\"msg\":{\"step\":%lld,"
                      "\"time\":%.9g,",
                      snap.step, snap.time);
        std::string text = head;
        text += "\"scene_version\":" + std::to_string(snap.version) + ",\"ids\":[";
        std::vector<double> poses;
        poses.reserve(7 * ids.size());
        for (size_t k = 0; k < ids.size(); ++k) {
          text += (k ? "," : "") + std::to_string(ids[k]);
          poses.insert(poses.end(), snap.poses.begin() + 7 * ids[k],
                       snap.poses.begin() + 7 * ids[k] + 7);
        }
        text += "],\"poses\":";
        internal::AppendNumbers(&text, poses.data(), poses.size());
        text += "}}";
        if (SendText(c, text, true)) {
          if (all) {
            c->sent_poses = snap.poses;
            c->poses_version = snap.version;
          } else {
            for (size_t i : ids)
              std::copy(snap.poses.begin() + 7 * i, snap.poses.begin() + 7 * i + 7,
                        c->sent_poses.begin() + 7 * i);
          }
        }
      }
    }
    if (c->topics.count(kJointStatesTopic)) {
      std::shared_ptr<const SceneContent> ct;
      std::shared_ptr<const MotionSnapshot> unused;
      Latest(&ct, &unused);
      const bool all = c->joints_version != snap.version || c->sent_qpos.size() != snap.qpos.size();
      if (all) c->sent_qpos.assign(snap.qpos.size(), {});
      c->joints_version = snap.version;
      for (size_t a = 0; a < snap.qpos.size() && ct && a < ct->articulations.size(); ++a) {
        const std::vector<double>& q = snap.qpos[a];
        std::vector<double>& was = c->sent_qpos[a];
        bool moved = was.size() != q.size();
        for (size_t k = 0; !moved && k < q.size(); ++k) moved = std::abs(was[k] - q[k]) > 1e-5;
        if (!moved) continue;
        std::string text =
            "{\"op\":\"publish\",\"topic\":\"/partsim/joint_states\",\"msg\":{\"articulation\":" +
            std::to_string(a) + ",\"name\":" + Dump(Json(ct->articulations[a].dof_joints)) +
            ",\"position\":";
        internal::AppendNumbers(&text, q.data(), q.size());
        text += ",\"velocity\":";
        internal::AppendNumbers(&text, snap.qvel[a].data(), snap.qvel[a].size());
        text += "}}";
        if (SendText(c, text, true)) was = q;
      }
    }
    if (c->topics.count(kContactsTopic) && snap.has_contacts) {
      std::string text = "{\"op\":\"publish\",\"topic\":\"/partsim/contacts\",\"msg\":{\"time\":" +
                         std::to_string(snap.time) + ",\"points\":";
      internal::AppendNumbers(&text, snap.contact_points.data(), snap.contact_points.size());
      text += ",\"normals\":";
      internal::AppendNumbers(&text, snap.contact_normals.data(), snap.contact_normals.size());
      text += ",\"forces\":";
      internal::AppendNumbers(&text, snap.contact_forces.data(), snap.contact_forces.size());
      text += "}}";
      SendText(c, text, true);
    }
  }

  Json StatusJson() {
    std::shared_ptr<const SceneContent> ct;
    std::shared_ptr<const MotionSnapshot> snap;
    Latest(&ct, &snap);
    bool is_paused;
    {
      std::lock_guard<std::mutex> lock(mutex);
      is_paused = sim ? sim->IsPaused() : paused;
    }
    return {{"paused", is_paused},
            {"time", snap ? snap->time : 0.0},
            {"step", snap ? snap->step : 0},
            {"steps_per_second", steps_per_second},
            {"realtime_factor", realtime_factor},
            {"scene_version", ct ? ct->version : 0},
            {"closed", closed.load()}};
  }

  void PublishStatus() {
    std::string text;
    for (auto& [h, c] : clients) {
      if (!c->authenticated || !c->topics.count(kStatusTopic)) continue;
      if (text.empty()) text = Dump(internal::PublishToJson(kStatusTopic, StatusJson()));
      SendText(c, text, true);
    }
  }

  /// Every 250 ms: the measured rates, and /partsim/status.
  void StatusTick() {
    std::shared_ptr<const SceneContent> ct;
    std::shared_ptr<const MotionSnapshot> snap;
    Latest(&ct, &snap);
    const Clock::time_point now = Clock::now();
    rate_samples.push_back({now, snap ? snap->step : 0, snap ? snap->time : 0.0});
    while (rate_samples.size() > 5) rate_samples.pop_front();
    const RateSample& first = rate_samples.front();
    const double wall = std::chrono::duration<double>(now - first.wall).count();
    if (wall > 0 && snap) {
      steps_per_second = std::max(0.0, (snap->step - first.step) / wall);
      realtime_factor = std::max(0.0, (snap->time - first.time) / wall);
    }
    PublishStatus();
    status_timer->expires_after(std::chrono::milliseconds(250));
    status_timer->async_wait([this](const boost::system::error_code& e) {
      if (!e && started) StatusTick();
    });
  }

  void UpdateWantContacts() {
    bool any = false;
    for (auto& [h, c] : clients) any = any || c->topics.count(kContactsTopic);
    want_contacts = any;
  }

  void OnMessage(const ClientPtr& c, const std::string& payload) {
    // nothing a client sends may end the network thread
    try {
      HandleMessage(c, payload);
    } catch (const std::exception& e) {
      try {
        StatusError(c, std::string("could not handle the message: ") + e.what(), nullptr);
      } catch (...) {
      }
    } catch (...) {
    }
  }

  void HandleMessage(const ClientPtr& c, const std::string& payload) {
    // before it has authenticated, a client may send the auth op alone: anything longer is
    // refused unparsed, so that it costs the viewer no more than its bytes
    if (!c->authenticated && payload.size() > internal::kMaxUnauthenticatedBytes) {
      StatusError(c,
                  "authenticate first: before {\"op\": \"auth\"} succeeds, messages are limited "
                  "to " +
                      std::to_string(internal::kMaxUnauthenticatedBytes) + " bytes (got " +
                      std::to_string(payload.size()) + ")",
                  nullptr);
      return;
    }
    Json j;
    try {
      j = internal::ParseJsonBounded(payload);
    } catch (const std::exception& e) {
      StatusError(c, std::string("malformed JSON: ") + e.what(), nullptr);
      return;
    }
    const Json id = j.is_object() && j.contains("id") ? j["id"] : Json();
    if (!j.is_object() || !j.contains("op") || !j["op"].is_string()) {
      StatusError(c, "message has no 'op' string", id);
      return;
    }
    const std::string op = j["op"].get<std::string>();
    if (!c->authenticated) {
      if (op != "auth") {
        StatusError(c, "authenticate first: send {\"op\": \"auth\", \"mac\": <the viewer's token>}",
                    id);
        return;
      }
      const bool ok = j.contains("mac") && j["mac"].is_string() &&
                      internal::SameToken(j["mac"].get<std::string>(), token);
      if (!ok) {
        StatusError(c, "auth: wrong token; closing the connection", id);
        websocketpp::lib::error_code ec;
        ws.close(c->connection, websocketpp::close::status::policy_violation,
                 "authentication failed", ec);
        return;
      }
      c->authenticated = true;
      if (c->auth_timer) c->auth_timer->cancel();
      SendText(c, Dump(internal::StatusToJson("info", "authenticated", id)), false);
      return;
    }
    try {
      if (op == "auth") {
        SendText(c, Dump(internal::StatusToJson("info", "authenticated", id)), false);
      } else if (op == "subscribe" || op == "unsubscribe") {
        if (!j.contains("topic") || !j["topic"].is_string())
          throw Error("op '" + op + "' needs a string 'topic'");
        std::string topic = j["topic"].get<std::string>();
        if (!topic.empty() && topic[0] != '/') topic = "/" + topic;
        if (op == "unsubscribe") {
          c->topics.erase(topic);
          UpdateWantContacts();
          return;
        }
        if (!IsViewerTopic(topic))
          throw Error("subscribe: no topic '" + topic + "' (the viewer publishes " +
                      std::string(kPosesTopic) + ", " + kJointStatesTopic + ", " + kStatusTopic +
                      ", " + kContactsTopic + ")");
        c->topics.insert(topic);
        if (topic == kPosesTopic) c->poses_version = -1;
        if (topic == kJointStatesTopic) c->joints_version = -1;
        UpdateWantContacts();
        if (topic == kStatusTopic) {
          SendText(c, Dump(internal::PublishToJson(kStatusTopic, StatusJson())), false);
        } else {
          // what there is now at once, then what the scene's thread snapshots next
          std::shared_ptr<const SceneContent> ct;
          std::shared_ptr<const MotionSnapshot> snap;
          Latest(&ct, &snap);
          if (ct && snap && snap->version == ct->version) PublishTo(c, *snap);
          RequestSnapshot();
        }
      } else if (op == "call_service") {
        if (!j.contains("service") || !j["service"].is_string())
          throw Error("op 'call_service' needs a string 'service'");
        std::string service = j["service"].get<std::string>();
        if (!service.empty() && service[0] != '/') service = "/" + service;
        const Json args = j.contains("args") ? j["args"] : Json::object();
        CallService(c, service, args, id);
      } else if (op == "publish" || op == "advertise" || op == "unadvertise" ||
                 op == "advertise_service" || op == "unadvertise_service" ||
                 op == "service_response" || op == "fragment") {
        throw Error("op '" + op +
                    "' is not supported by the viewer (it answers auth, subscribe, unsubscribe "
                    "and call_service)");
      } else {
        throw Error("unknown op '" + op + "'");
      }
    } catch (const std::exception& e) {
      StatusError(c, e.what(), id);
    }
  }

  void Answer(const ClientPtr& c, const std::string& service, const Json& values, const Json& id) {
    SendText(c, Dump(internal::ServiceResponseToJson(service, values, true, id)), false);
  }

  void CallService(const ClientPtr& c, const std::string& service, const Json& args,
                   const Json& id) {
    try {
      if (!args.is_object() && !args.is_null())
        throw Error("args must be an object, got " + Dump(args));
      if (service == "/partsim/set_joint_target") {
        if (!args.contains("articulation") || !args["articulation"].is_number_integer())
          throw Error("args need an integer 'articulation' (an id of scene.json)");
        if (!args.contains("joint") || !args["joint"].is_string())
          throw Error("args need a string 'joint' (a joint name)");
        if (!args.contains("position") || !args["position"].is_number())
          throw Error("args need a number 'position' (m or rad)");
        const double q = args["position"].get<double>();
        if (!std::isfinite(q))
          throw Error("position must be finite, got " + Dump(args["position"]));
        const long long a = args["articulation"].get<long long>();
        const std::string joint = args["joint"].get<std::string>();
        if (a < 0 || a > 1000000000)
          throw Error("articulation " + std::to_string(a) + " does not exist");
        Enqueue(c, service, id, [this, a, joint, q](Scene& s) {
          return SetJointTarget(s, static_cast<int>(a), joint, q);
        });
      } else if (service == "/partsim/pause") {
        if (sim) {
          sim->Pause();
        } else {
          std::lock_guard<std::mutex> lock(mutex);
          paused = true;
          pending_steps = 0;
        }
        cv.notify_all();
        Answer(c, service, Json::object(), id);
        PublishStatus();
      } else if (service == "/partsim/resume") {
        if (sim) {
          sim->Resume();
        } else {
          std::lock_guard<std::mutex> lock(mutex);
          paused = false;
          pending_steps = 0;
        }
        cv.notify_all();
        Answer(c, service, Json::object(), id);
        PublishStatus();
      } else if (service == "/partsim/step") {
        // while running: pause first, then the n steps
        const long long n = internal::StepCountFromJson(args);
        if (sim) {
          if (!sim->IsPaused()) sim->Pause();
          sim->StepN(n);
        } else {
          std::lock_guard<std::mutex> lock(mutex);
          if (!paused) pending_steps = 0;
          paused = true;
          pending_steps = std::min(pending_steps + n, SimServer::kMaxStepRequest);
        }
        cv.notify_all();
        Answer(c, service, Json::object(), id);
        PublishStatus();
      } else if (service == "/partsim/reset") {
        if (sim) {
          sim->Reset();
          RequestSnapshot();
          Answer(c, service, Json::object(), id);
        } else {
          Enqueue(c, service, id, [this](Scene& s) {
            s.Unpack(initial_state);
            return Json::object();
          });
        }
      } else if (service == "/partsim/camera") {
        if (!args.contains("name") || !args["name"].is_string())
          throw Error("args need a string 'name' (a camera of scene.json)");
        const std::string picture = args.value("picture", std::string("Color"));
        if (picture != "Color" && picture != "Depth" && picture != "Segmentation")
          throw Error("picture must be \"Color\", \"Depth\" or \"Segmentation\", got \"" + picture +
                      "\"");
        const std::string name = args["name"].get<std::string>();
        Enqueue(c, service, id,
                [this, name, picture](Scene& s) { return CameraPicture(s, name, picture); });
      } else if (service == "/partsim/close") {
        closed = true;
        cv.notify_all();
        Answer(c, service, Json::object(), id);
        PublishStatus();
      } else if (auto it = services.find(service); it != services.end()) {
        CallExtraService(c, service, it->second, args, id);
      } else {
        std::string extra;
        for (const auto& [name, unused] : services) extra += ", " + name;
        throw Error("no service '" + service +
                    "' (the viewer's: /partsim/set_joint_target, /partsim/pause, /partsim/resume, "
                    "/partsim/step, /partsim/reset, /partsim/camera, /partsim/close" +
                    extra + ")");
      }
    } catch (const nlohmann::json::exception& e) {
      ++errors;
      SendText(c,
               Dump(internal::ServiceResponseToJson(service, service + ": " + e.what(), false, id)),
               false);
    } catch (const std::exception& e) {
      ++errors;
      SendText(c,
               Dump(internal::ServiceResponseToJson(service, service + ": " + e.what(), false, id)),
               false);
    }
  }

  /// A call of an extension's service: its answer comes back from any thread. Until then it
  /// counts among the client's waiting commands (the gallery's /partsim/open loads an object on
  /// the scene's thread).
  void CallExtraService(const ClientPtr& c, const std::string& service,
                        const ViewerService& handler, const Json& args, const Json& id) {
    TakeWaitingPlace(c);
    std::weak_ptr<ViewerClient> weak = c;
    auto once = std::make_shared<std::atomic<bool>>(false);
    ViewerServiceReply reply = [this, weak, waiting = c->waiting, service, id, once](
                                   bool ok, const std::string& text) {
      if (once->exchange(true)) return;
      --*waiting;
      Json answer;
      if (ok) {
        try {
          answer =
              internal::ServiceResponseToJson(service, internal::ParseJsonBounded(text), true, id);
        } catch (const std::exception& e) {
          ok = false;
          answer = internal::ServiceResponseToJson(
              service, service + ": bad answer from the service: " + e.what(), false, id);
        }
      } else {
        answer = internal::ServiceResponseToJson(service, service + ": " + text, false, id);
      }
      if (!ok) ++errors;
      PostReply(weak, Dump(answer));
    };
    try {
      handler(Dump(args.is_null() ? Json::object() : args), reply);
    } catch (...) {
      if (!once->exchange(true)) --*c->waiting;  // answered with the error by the caller
      throw;
    }
  }

  // ---- HTTP ----

  static void FillHttp(const WsServer::connection_ptr& con, int status, const std::string& type,
                       const std::string& body) {
    con->set_status(static_cast<websocketpp::http::status_code::value>(status));
    con->append_header("Content-Type", type);
    con->append_header("Cache-Control", "no-store");
    con->append_header("X-Content-Type-Options", "nosniff");
    con->set_body(body);
  }

  void HandleHttp(const WsServer::connection_ptr& con) {
    ++http_requests;
    int status = 200;
    std::string body, type = "text/plain; charset=utf-8";
    try {
      if (Route(con, &status, &body, &type)) return;  // answered later
    } catch (const std::exception& e) {
      status = 500;
      body = std::string("error: ") + e.what() + "\n";
      type = "text/plain; charset=utf-8";
    }
    FillHttp(con, status, type, body);
  }

  /// Hands a request to an extension's route; its answer (or 503 after the route's timeout)
  /// is sent later, on the network thread.
  void DeferToRoute(const WsServer::connection_ptr& con, const ApiRoute& r,
                    const std::string& path) {
    websocketpp::lib::error_code ec = con->defer_http_response();
    if (ec) throw Error("cannot defer the answer: " + ec.message());
    auto once = std::make_shared<std::atomic<bool>>(false);
    auto timer = std::make_shared<boost::asio::steady_timer>(ws.get_io_service());
    ViewerHttpRespond respond = [this, con, once, timer](ViewerHttpAnswer a) {
      if (once->exchange(true) || !started) return;
      boost::asio::post(ws.get_io_service(), [con, timer, a = std::move(a)] {
        timer->cancel();
        FillHttp(con, a.status, a.content_type, a.body);
        websocketpp::lib::error_code unused;
        con->send_http_response(unused);
      });
    };
    timer->expires_after(std::chrono::milliseconds(static_cast<long long>(r.timeout * 1000)));
    const double timeout = r.timeout;
    timer->async_wait([respond, timeout](const boost::system::error_code& e) {
      if (e) return;
      char why[100];
      std::snprintf(why, sizeof(why), "no answer within %g s; try again\n", timeout);
      respond({503, "text/plain; charset=utf-8", why});
    });
    try {
      r.route(path, respond);
    } catch (const std::exception& e) {
      respond({500, "text/plain; charset=utf-8", std::string("error: ") + e.what() + "\n"});
    }
  }

  /// Fills the answer to a request, or returns true when an extension answers it later.
  bool Route(const WsServer::connection_ptr& con, int* status, std::string* body,
             std::string* type) {
    auto fail = [&](int code, const std::string& why) {
      *status = code;
      *body = why + "\n";
      return false;
    };
    if (con->get_request().get_method() != "GET") return fail(405, "only GET is served");
    // (a plain HTTP request has no WebSocket processor: get_origin() is not for it)
    const std::string origin = con->get_request_header("Origin");
    if (!internal::OriginAllowed(origin, options.allowed_origins))
      return fail(403, "origin '" + origin + "' is not allowed");
    std::string path, query;
    internal::SplitResource(con->get_resource(), &path, &query);
    if (path.rfind("/api/", 0) == 0) {
      std::string given = internal::QueryValue(query, "token");
      if (given.empty()) given = con->get_request_header("X-Partsim-Token");
      if (!internal::SameToken(given, token))
        return fail(403, "missing or wrong token: add ?token=T (the token of the viewer's URL)");
      for (const ApiRoute& r : api_routes)
        if (path.rfind(r.prefix, 0) == 0) {
          DeferToRoute(con, r, path);
          return true;
        }
      Api(path, status, body, type);
      return false;
    }
    if (path == "/") path = "/index.html";
    if (!internal::SafeBundlePath(path))
      return fail(400, "bad path '" + path +
                           "': only files of the web bundle are served (no '..', no '%')");
    // only regular files that stay inside the bundle folder once links are followed: no link
    // out of it, no folder, no device, no FIFO (never opened)
    const std::string file =
        web_root.empty()
            ? ""
            : internal::RegularFileInside((fs::path(web_root) / path.substr(1)).string(), web_root);
    if (file.empty() || !internal::ReadRegularFile(file, kMaxBundleFileBytes, body)) {
      // no bundle (or one without its page): say how to build it
      if (path == "/index.html") {
        *type = "text/html; charset=utf-8";
        *body = kNoBundlePage;
        return false;
      }
      return fail(404, "no file '" + path + "' in the web bundle (" +
                           (web_root.empty() ? "none found" : web_root) + ")");
    }
    *type = internal::ContentTypeOf(path);
    return false;
  }

  void Api(const std::string& path, int* status, std::string* body, std::string* type) {
    std::shared_ptr<const SceneContent> ct;
    std::shared_ptr<const MotionSnapshot> snap;
    Latest(&ct, &snap);
    if (!ct) {
      *status = 503;
      *body = "no scene yet\n";
      return;
    }
    if (path == "/api/scene.json") {
      Json j = ct->json;
      if (snap && snap->version == ct->version) {
        j["poses"] = snap->poses;
        j["time"] = snap->time;
        j["step"] = snap->step;
      } else {
        j["poses"] = Json::array();  // none yet: the first /partsim/poses message has them all
      }
      {
        std::lock_guard<std::mutex> lock(mutex);
        auto vec = [](const std::optional<Eigen::Vector3d>& v) {
          return v ? Json::array({v->x(), v->y(), v->z()}) : Json(nullptr);
        };
        if (camera_position || camera_rpy || camera_fovy)
          j["initial_camera"] = {{"position", vec(camera_position)},
                                 {"rpy", vec(camera_rpy)},
                                 {"fovy", camera_fovy ? Json(*camera_fovy) : Json(nullptr)}};
        else
          j["initial_camera"] = nullptr;
      }
      *body = Dump(j);
      *type = "application/json";
      return;
    }
    const long long mesh = internal::PathIndex(path, "/api/mesh/", ".bin");
    if (mesh >= 0) {
      if (mesh >= static_cast<long long>(ct->meshes.size())) {
        *status = 404;
        *body = "no mesh " + std::to_string(mesh) + " (the scene has " +
                std::to_string(ct->meshes.size()) + ")\n";
        return;
      }
      *body = internal::EncodeMesh(*ct->meshes[mesh]);
      *type = "application/octet-stream";
      return;
    }
    const long long tex = internal::PathIndex(path, "/api/texture/", ".png");
    if (tex >= 0 && tex < static_cast<long long>(ct->textures.size())) {
      // only images leave: the file decoded as PNG or JPEG and sent as a PNG of its pixels
      const std::string& file = ct->textures[tex];
      std::error_code ec;
      const std::uintmax_t size = fs::file_size(file, ec);
      std::vector<uint8_t> rgba;
      int width = 0;
      int height = 0;
      try {
        if (ec || size > kMaxTextureBytes) throw Error("cannot be read");
        rgba = ReadImageRgba8(file, &width, &height);
      } catch (const Error&) {
        *status = 404;
        *body = "texture " + std::to_string(tex) + " cannot be read as a PNG or JPEG image\n";
        return;
      }
      *body = internal::EncodePng(width, height, 4, rgba.data());
      *type = "image/png";
      return;
    }
    std::string extra;
    for (const ApiRoute& r : api_routes) extra += ", " + r.prefix + "...";
    *status = 404;
    *body = "no API path '" + path +
            "' (there are /api/scene.json, /api/mesh/K.bin, /api/texture/K.png" + extra + ")\n";
  }

  // ---- accepting ----
  /// partsim's accept loop (network thread), in place of websocketpp's start_accept, which
  /// retries a failed accept at once: out of file descriptors that spun a core. A failure waits
  /// 100 ms (the rosbridge server's loop, src/server/rosbridge.cc).
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

  // ---- set-up ----

  void InitServer() {
    ws.clear_access_channels(websocketpp::log::alevel::all);
    ws.clear_error_channels(websocketpp::log::elevel::all);
    ws.init_asio();
    ws.set_reuse_addr(true);
    ws.set_max_message_size(options.max_message_bytes);
    ws.set_max_http_body_size(64 * 1024);
    ws.set_open_handshake_timeout(2000);
    ws.set_validate_handler([this](Hdl h) {
      websocketpp::lib::error_code ec;
      WsServer::connection_ptr con = ws.get_con_from_hdl(h, ec);
      if (ec || !con) return false;
      if (!internal::OriginAllowed(con->get_origin(), options.allowed_origins)) {
        con->set_status(websocketpp::http::status_code::forbidden);
        return false;
      }
      // a slot is taken here and given back when the connection fails or closes
      if (slots.size() >= options.max_clients) {
        con->set_status(websocketpp::http::status_code::service_unavailable);
        return false;
      }
      slots.insert(h);
      return true;
    });
    ws.set_open_handler([this](Hdl h) {
      auto c = std::make_shared<ViewerClient>();
      c->connection = h;
      clients[h] = c;
      client_count = static_cast<long long>(clients.size());
      // a client that has not authenticated in time is closed
      c->auth_timer = std::make_unique<boost::asio::steady_timer>(ws.get_io_service());
      c->auth_timer->expires_after(std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(options.auth_timeout)));
      std::weak_ptr<ViewerClient> weak = c;
      c->auth_timer->async_wait([this, weak](const boost::system::error_code& e) {
        ClientPtr client = weak.lock();
        if (e || !client || client->authenticated) return;
        char why[160];
        std::snprintf(why, sizeof(why),
                      "auth: no {\"op\": \"auth\"} with the token within %g s; closing the "
                      "connection",
                      options.auth_timeout);
        StatusError(client, why, nullptr);
        websocketpp::lib::error_code ec;
        ws.close(client->connection, websocketpp::close::status::policy_violation,
                 "not authenticated in time", ec);
      });
    });
    auto gone = [this](Hdl h) {
      slots.erase(h);
      if (auto it = clients.find(h); it != clients.end() && it->second->auth_timer)
        it->second->auth_timer->cancel();
      clients.erase(h);
      client_count = static_cast<long long>(clients.size());
      UpdateWantContacts();
    };
    ws.set_close_handler(gone);
    ws.set_fail_handler(gone);
    ws.set_message_handler([this](Hdl h, WsServer::message_ptr msg) {
      auto it = clients.find(h);
      if (it != clients.end()) OnMessage(it->second, msg->get_payload());
    });
    ws.set_http_handler([this](Hdl h) {
      websocketpp::lib::error_code ec;
      WsServer::connection_ptr con = ws.get_con_from_hdl(h, ec);
      if (!ec && con) HandleHttp(con);
    });
  }

  void Listen() {
    boost::system::error_code bec;
    boost::asio::ip::address addr = boost::asio::ip::make_address(options.address, bec);
    if (bec) {
      boost::asio::ip::tcp::resolver resolver(ws.get_io_service());
      auto found = resolver.resolve(options.address, "", bec);
      if (bec || found.empty())
        throw Error("viewer: cannot resolve the address '" + options.address +
                    "': " + (bec ? bec.message() : "no address"));
      addr = found.begin()->endpoint().address();
    }
    if (!addr.is_loopback())
      std::fprintf(stderr,
                   "partsim: warning: the viewer listens on %s (%s), reachable from other "
                   "machines: anyone with the token can move the scene\n",
                   options.address.c_str(), addr.to_string().c_str());
    boost::asio::ip::tcp::endpoint ep(addr, static_cast<unsigned short>(options.port));
    websocketpp::lib::error_code ec;
    ws.listen(ep, ec);
    if (ec) {
      // the operating system's reason, from binding a plain socket the same way
      std::string why = ec.message();
      boost::asio::ip::tcp::acceptor probe(ws.get_io_service());
      probe.open(ep.protocol(), bec);
      if (!bec) probe.set_option(boost::asio::socket_base::reuse_address(true), bec);
      if (!bec) probe.bind(ep, bec);
      if (bec) why = bec.message();
      throw Error("viewer: cannot listen on " + options.address + ":" +
                  std::to_string(options.port) + ": " + why);
    }
    accept_timer = std::make_unique<boost::asio::steady_timer>(ws.get_io_service());
    StartAccept();
    port = ws.get_local_endpoint(bec).port();
  }
};

Viewer::Viewer(Scene* scene, const ViewerOptions& options) : impl_(std::make_unique<Impl>()) {
  if (!(options.max_rate > 0) || !std::isfinite(options.max_rate))
    throw Error("Viewer: max_rate must be a positive number of Hz, got " +
                std::to_string(options.max_rate));
  if (!(options.auth_timeout > 0) || options.auth_timeout > 1e6)
    throw Error("Viewer: auth_timeout must be a positive number of seconds (at most 1e6), got " +
                std::to_string(options.auth_timeout));
  Impl& m = *impl_;
  m.options = options;
  m.scene = scene;
  m.period = 1.0 / options.max_rate;
  m.token = options.auth_token.empty() ? internal::RandomToken() : options.auth_token;
  m.web_root = FindWebRoot(options.web_root);
  m.InitServer();
}

Viewer::~Viewer() { Stop(); }

void Viewer::Attach(SimServer* sim) {
  Impl& m = *impl_;
  if (!sim) throw Error("Viewer::Attach: sim is null");
  if (m.started || m.sim) throw Error("Viewer::Attach: attach before Start(), once");
  if (!m.scene) throw Error("Viewer::Attach: the viewer has no scene");
  m.sim = sim;
  sim->AddStepCallback([this](long long) {
    if (impl_->started) impl_->Snapshot(false);
  });
  // the state a pause or the end of a step burst leaves is always shown, whoever asked for it
  // (the page, a ROS client, the program), though the last steps came within 1 / max_rate s
  sim->AddRestCallback([this](long long) {
    if (impl_->started) impl_->Snapshot(true);
  });
}

void Viewer::Start() {
  Impl& m = *impl_;
  if (m.started) throw Error("Viewer: already started");
  m.Listen();
  m.started = true;
  if (m.scene) {
    m.RebuildContent();
    m.Snapshot(true);
  }
  m.status_timer = std::make_unique<boost::asio::steady_timer>(m.ws.get_io_service());
  m.StatusTick();
  m.io_thread = std::thread([this] {
    // a handler that throws must not end the viewer
    while (true) {
      try {
        impl_->ws.run();
        return;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "partsim viewer: network thread: %s (it goes on)\n", e.what());
      }
    }
  });
}

void Viewer::Stop() {
  Impl& m = *impl_;
  if (!m.started) return;
  m.started = false;
  m.closed = true;
  websocketpp::lib::error_code ec;
  m.ws.stop_listening(ec);
  if (m.status_timer) m.status_timer->cancel();
  if (m.accept_timer) m.accept_timer->cancel();
  m.ws.stop();
  if (m.io_thread.joinable()) m.io_thread.join();
  m.cv.notify_all();
}

bool Viewer::Render(double max_wait) {
  Impl& m = *impl_;
  if (!m.started) throw Error("Viewer::Render: the viewer is not started");
  if (m.sim)
    throw Error("Viewer::Render: the viewer is attached to a SimServer, whose thread does this");
  m.RunCommands();
  bool is_paused;
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    is_paused = m.paused;
  }
  // a paused scene is snapshotted every time: what a step the page asked for changed
  m.Snapshot(is_paused);
  const Clock::time_point deadline =
      max_wait >= 0 ? Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                         std::chrono::duration<double>(std::min(max_wait, 1e6)))
                    : Clock::time_point::max();
  auto ready = [&m] {
    return !m.commands.empty() || m.closed || !m.paused || m.pending_steps > 0 || !m.started;
  };
  std::unique_lock<std::mutex> lock(m.mutex);
  while (true) {
    if (m.closed || !m.paused || !m.started) return true;
    if (m.pending_steps > 0) {
      // a step the page asked for: this call returns, and as many calls as steps remain
      --m.pending_steps;
      return true;
    }
    if (deadline == Clock::time_point::max())
      m.cv.wait(lock, ready);
    else if (!m.cv.wait_until(lock, deadline, ready))
      return false;
    lock.unlock();
    m.RunCommands();
    lock.lock();
  }
}

void Viewer::SetScene(Scene* scene) {
  Impl& m = *impl_;
  if (m.sim) throw Error("Viewer::SetScene: not in served mode");
  m.scene = scene;
  m.content = nullptr;
  if (m.started && scene) {
    m.RebuildContent();
    m.Snapshot(true);
  }
}

void Viewer::SetInitialCameraPosition(const Eigen::Vector3d& position) {
  if (!position.allFinite())
    throw Error("Viewer: the camera position must be finite, got (" + std::to_string(position.x()) +
                ", " + std::to_string(position.y()) + ", " + std::to_string(position.z()) + ")");
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->camera_position = position;
}

void Viewer::SetInitialCameraRpy(const Eigen::Vector3d& rpy) {
  if (!rpy.allFinite())
    throw Error("Viewer: the camera roll, pitch and yaw must be finite, got (" +
                std::to_string(rpy.x()) + ", " + std::to_string(rpy.y()) + ", " +
                std::to_string(rpy.z()) + ")");
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->camera_rpy = rpy;
}

void Viewer::SetInitialCameraFovy(double fovy) {
  if (!(fovy > 0 && fovy < 3.14159265358979323846))
    throw Error("Viewer: the camera's vertical field of view must be in (0, pi) rad, got " +
                std::to_string(fovy));
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->camera_fovy = fovy;
}

Scene* Viewer::GetScene() const { return impl_->scene; }

bool Viewer::IsClosed() const { return impl_->closed; }

void Viewer::Close() {
  impl_->closed = true;
  impl_->cv.notify_all();
  impl_->PostStatus();
}

bool Viewer::IsPaused() const {
  if (impl_->sim) return impl_->sim->IsPaused();
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->paused;
}

int Viewer::GetPort() const { return impl_->port; }

const std::string& Viewer::GetToken() const { return impl_->token; }

std::string Viewer::GetUrl() const {
  const std::string& a = impl_->options.address;
  const std::string host = a.find(':') != std::string::npos ? "[" + a + "]" : a;
  return "http://" + host + ":" + std::to_string(impl_->port) + "/?token=" + impl_->token;
}

std::string Viewer::GetWebRoot() const { return impl_->web_root; }

ViewerStats Viewer::GetStats() const {
  const Impl& m = *impl_;
  ViewerStats s;
  s.clients = m.client_count;
  s.messages_sent = m.sent;
  s.messages_dropped = m.dropped;
  s.http_requests = m.http_requests;
  s.errors = m.errors;
  s.snapshots = m.snapshots;
  s.accept_errors = m.accept_errors;
  std::lock_guard<std::mutex> lock(m.mutex);
  s.scene_version = m.shared_content ? m.shared_content->version : 0;
  return s;
}

}  // namespace partsim

namespace partsim {

void Viewer::AddApiRoute(const std::string& prefix, ViewerApiRoute route, double timeout) {
  Impl& m = *impl_;
  if (m.started) throw Error("Viewer::AddApiRoute: add routes before Start()");
  if (prefix.rfind("/api/", 0) != 0 || prefix.size() <= 5)
    throw Error("Viewer::AddApiRoute: '" + prefix + "' is not a path under /api/");
  for (const char* own : {"/api/scene.json", "/api/mesh/", "/api/texture/"})
    if (prefix.rfind(own, 0) == 0 || std::string(own).rfind(prefix, 0) == 0)
      throw Error("Viewer::AddApiRoute: '" + prefix + "' overlaps the viewer's own " + own);
  if (!route) throw Error("Viewer::AddApiRoute: the route is empty");
  if (!(timeout > 0) || timeout > 1e6)
    throw Error("Viewer::AddApiRoute: the timeout must be a positive number of seconds");
  m.api_routes.push_back({prefix, std::move(route), timeout});
}

void Viewer::AddService(const std::string& name, ViewerService service) {
  Impl& m = *impl_;
  if (m.started) throw Error("Viewer::AddService: add services before Start()");
  for (const char* own : {"/partsim/set_joint_target", "/partsim/pause", "/partsim/resume",
                          "/partsim/step", "/partsim/reset", "/partsim/camera", "/partsim/close"})
    if (name == own) throw Error("Viewer::AddService: '" + name + "' is the viewer's own");
  if (name.empty() || name[0] != '/')
    throw Error("Viewer::AddService: a service name starts with '/', got '" + name + "'");
  if (!service) throw Error("Viewer::AddService: the service is empty");
  if (!m.services.emplace(name, std::move(service)).second)
    throw Error("Viewer::AddService: '" + name + "' was added already");
}

void Viewer::Post(std::function<void()> command) {
  Impl& m = *impl_;
  auto guarded = [command = std::move(command)] {
    try {
      command();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "partsim viewer: a posted command failed: %s\n", e.what());
    }
  };
  if (m.sim) {
    m.sim->Post([this, guarded] {
      guarded();
      impl_->Snapshot(true);
    });
    return;
  }
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    m.commands.push_back(guarded);
  }
  m.cv.notify_all();
}

}  // namespace partsim
