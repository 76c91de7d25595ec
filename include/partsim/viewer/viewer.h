// The viewer in the browser (docs/viewer.md): one port that serves the web page, the scene's
// content over HTTP (/api/scene.json, /api/mesh/K.bin, /api/texture/K.png) and a rosbridge v2
// WebSocket (/partsim/poses, /partsim/joint_states, /partsim/status, /partsim/contacts out;
// /partsim/set_joint_target, pause, resume, reset, step, camera and close in). The port is a
// RosbridgeServer's (partsim/server/rosbridge.h: its accept loop, login, Origin check and op
// table) to which the viewer adds its topics, services and HTTP routes. The network runs on a
// thread of its own; the scene is read and changed only on the thread that owns it: the caller
// of Render() (synchronous mode) or a SimServer's thread (served mode, Attach).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace partsim {

class Articulation;
class Scene;
class SimServer;

struct ViewerOptions {
  /// Interface to listen on: an address or a host name; "0.0.0.0" or "::" for all (Start()
  /// warns: anyone who can connect and knows the token can move the scene).
  std::string address = "127.0.0.1";
  int port = 0;  ///< 0 picks a free port (see GetPort)
  /// Web pages may connect only from these origins (the Origin header, e.g.
  /// "http://myhost:8000"; "*" for any). Empty: pages of this machine (localhost, 127.0.0.1,
  /// [::1], any port). Requests from other origins get HTTP 403.
  std::vector<std::string> allowed_origins;
  /// The token that /api/* requests (?token=T or the header X-Partsim-Token) and the
  /// WebSocket's first op ({"op": "auth", "mac": T}) must carry. "": a random one (GetToken).
  std::string auth_token;
  /// Folder of the web bundle (index.html, viewer.js, ...). "": $PARTSIM_WEB_DIR, else
  /// share/partsim/web beside the installed binary, else the build tree's web/; without one, /
  /// answers a page that says how to build it.
  std::string web_root;
  double max_rate = 60.0;  ///< most pose messages per second (Hz), > 0
  /// WebSocket connections at once, counted from the handshake; more get HTTP 503
  size_t max_clients = 32;
  size_t max_message_bytes = 1u << 20;    ///< larger incoming messages close with code 1009
  size_t max_client_buffered = 8u << 20;  ///< bytes waiting in a client's socket before drops
  /// Seconds a WebSocket client has to authenticate ({"op": "auth"}) before it is closed
  /// (code 1008); > 0.
  double auth_timeout = 5.0;
};

/// Counters for tests and benchmarks.
struct ViewerStats {
  long long clients = 0;           ///< WebSocket clients connected now that have authenticated
  long long messages_sent = 0;     ///< WebSocket messages handed to sockets
  long long messages_dropped = 0;  ///< publications dropped for slow clients
  long long http_requests = 0;     ///< HTTP requests answered (any status)
  long long errors = 0;            ///< error statuses sent to clients
  long long snapshots = 0;         ///< pose snapshots taken on the scene's thread
  long long scene_version = 0;     ///< structure snapshots taken (1 after Start)
  long long accept_errors = 0;     ///< failed accepts (out of file descriptors), each waits 100 ms
};

/// An HTTP answer of an extra API route (Viewer::AddApiRoute).
struct ViewerHttpAnswer {
  int status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body;
};
/// Answers one request of an extra API route: call it once, from any thread, now or later.
using ViewerHttpRespond = std::function<void(ViewerHttpAnswer answer)>;
/// Handles GET `path` (an /api/ path, its token checked) on the network thread; it must return
/// quickly and answers through `respond`.
using ViewerApiRoute = std::function<void(const std::string& path, ViewerHttpRespond respond)>;
/// Answers one call of an extra service, once, from any thread: on success `text` is the
/// answer's "values" as JSON text (e.g. {"success": true, "message": ""}); on failure a message.
using ViewerServiceReply = std::function<void(bool success, const std::string& text)>;
/// Handles a call of an extra service on the network thread: `args_json` is its args (a JSON
/// object's text); it must return quickly and answers through `reply`.
using ViewerService = std::function<void(const std::string& args_json, ViewerServiceReply reply)>;

/// Moves joint `joint` of `articulation` to `position` the way a network client's command does
/// (a served robot's controllers); returns false for an articulation it does not serve, which
/// the viewer then moves with a position controller of its own. Runs on the scene's thread;
/// throws partsim::Error for a position it refuses.
using ViewerJointCommand = std::function<bool(const Articulation& articulation,
                                              const std::string& joint, double position)>;

class Viewer {
 public:
  /// Views `scene` (which must outlive the viewer; null: nothing until SetScene). Nothing is
  /// served before Start().
  explicit Viewer(Scene* scene, const ViewerOptions& options = {});
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  /// Served mode: `sim` steps this viewer's scene on its thread; poses are snapshotted from its
  /// step callback and the page's commands are posted to it (pause, resume, step and reset call
  /// the SimServer's). Call before sim->Start() and before Start(); `sim` must be stopped before
  /// the viewer is destroyed. Throws partsim::Error when already started or `sim` is null.
  void Attach(SimServer* sim);
  /// Snapshots the scene's structure (on the calling thread, which must own the scene: before a
  /// SimServer starts, in served mode) and starts serving on a thread of its own. Throws
  /// partsim::Error when the port cannot be opened or it was started already.
  void Start();
  /// Closes every connection and joins the network thread; the viewer is closed (IsClosed)
  /// for good. Idempotent.
  void Stop();

  /// Synchronous mode, on the scene's thread: applies the commands the page queued (drive
  /// targets, reset, camera pictures), snapshots what moved for the page (at most max_rate
  /// times a second; calls in between only apply commands) and returns. While paused (the
  /// page's pause button) it blocks, applying commands, until resumed, stepped ({n}: this and
  /// the next n - 1 calls return, then it blocks again) or closed, or until `max_wait` seconds
  /// pass: it then returns false (still paused), else true. Throws partsim::Error in served
  /// mode or before Start().
  bool Render(double max_wait = -1);
  /// Synchronous mode: views another scene (SAPIEN's viewer.set_scene); the page reloads.
  /// Call on the thread that owns both scenes, not in served mode.
  void SetScene(Scene* scene);
  /// Where the page's camera starts (SAPIEN's viewer.set_camera_xyz): the eye in the world (m).
  /// Sent in scene.json's "initial_camera", read by a page when it loads.
  void SetInitialCameraPosition(const Eigen::Vector3d& position);
  /// How the page's camera starts (SAPIEN's viewer.set_camera_rpy): roll, pitch, yaw (rad) of
  /// its x forward, y left, z up frame; the view direction is (cos p cos y, cos p sin y, sin p),
  /// so a positive pitch looks up, as in SAPIEN's viewer.
  void SetInitialCameraRpy(const Eigen::Vector3d& rpy);
  /// Where the page's camera starts: its vertical field of view (rad, in (0, pi)), SAPIEN's
  /// viewer.set_fovy; scene.json's initial_camera.fovy (null unless set).
  void SetInitialCameraFovy(double fovy);
  /// The viewed scene (null: none).
  Scene* GetScene() const;

  /// True once the page asked to close (/partsim/close) or Close() was called.
  bool IsClosed() const;
  void Close();
  /// Whether the simulation is paused by the page (served mode: the SimServer's state).
  bool IsPaused() const;
  /// The port listened on (after Start).
  int GetPort() const;
  /// The token clients must give (the option's, or the random one made at construction).
  const std::string& GetToken() const;
  /// http://ADDRESS:PORT/?token=T, the page to open (after Start).
  std::string GetUrl() const;
  /// The web bundle folder found, "" for none.
  std::string GetWebRoot() const;
  ViewerStats GetStats() const;

  // ---- extensions: what a tool built on the viewer adds (partsim view --dataset's gallery) ----

  /// Serves GET requests whose path starts with `prefix` (which starts with "/api/") by
  /// `route`; the token is checked first. A request not answered within `timeout` seconds gets
  /// 503. Before Start(); throws partsim::Error for a prefix outside /api/ or one the viewer
  /// serves itself.
  void AddApiRoute(const std::string& prefix, ViewerApiRoute route, double timeout = 30.0);
  /// Answers the rosbridge service `name` (e.g. "/partsim/open") by `service`. Before Start();
  /// throws partsim::Error for a name the viewer answers itself or one added already.
  void AddService(const std::string& name, ViewerService service);
  /// How the page's joint commands (/partsim/set_joint_target) reach the articulations
  /// `command` serves (partsim serve --viewer: the served robot's controllers, the path of a ROS
  /// client's command). Any other articulation's joint gets a JointPositionController of its own
  /// (the robot layer's, default gains, at the physics rate), updated at each Render() or, in
  /// served mode, from the step callback. Before Start().
  void SetJointCommand(ViewerJointCommand command);
  /// Runs `command` on the scene's thread: synchronous mode, at the next Render() (also while
  /// it blocks paused), which then snapshots the scene; served mode, posted to the SimServer.
  /// What it throws is written to stderr.
  void Post(std::function<void()> command);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// The web bundle folder for a viewer with option `web_root`: web_root if given, else
/// $PARTSIM_WEB_DIR, else PREFIX/share/partsim/web for the prefix the binary holding this code
/// is installed in (found at run time: a cmake --install prefix, /usr for the .deb, the package
/// folder for a wheel), else the build tree's web/, the first that holds an index.html; "" when
/// none does (a given web_root is returned even then).
std::string FindWebRoot(const std::string& web_root);

}  // namespace partsim
