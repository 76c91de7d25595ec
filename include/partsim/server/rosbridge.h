// A rosbridge v2 protocol server (JSON over WebSocket) in front of a ServedRobot: /clock,
// /joint_states and /tf (links and camera optical frames) are published from the simulation
// thread; joint position, velocity, effort and trajectory commands, motion planning
// (/<robot>/plan), rosapi services and the simulation controls (pause, resume, reset, step) come
// in. Each client has its own subscriptions and a bounded outgoing queue: a client that reads
// slowly loses messages, the simulation never waits for it. Every camera of the served robot
// publishes /<camera>/image_raw, /<camera>/camera_info and /<camera>/points, and its IMU /imu;
// sensors are read (cameras rendered) on the simulation thread between steps, and only while
// some client subscribes.
//
// The same server, built without a robot, is the transport and protocol of every partsim network
// front-end: the browser viewer adds its topics, services and HTTP routes to one (see the
// extension members below), so one accept loop, one handshake check (Origin, connection cap),
// one login (the auth op and its time limit) and one op table serve them all.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "partsim/server/served_robot.h"

namespace partsim {

struct RosbridgeOptions {
  /// Interface to listen on: an address or a host name ("localhost"); "0.0.0.0" or "::" for
  /// all. Anything but a loopback address is reachable from other machines: Start() warns.
  std::string address = "127.0.0.1";
  int port = 9090;  ///< 0 picks a free port (see GetPort)
  /// Web pages may connect only from these origins (the handshake's Origin header, e.g.
  /// "http://localhost:8000"); clients that send no Origin (roslib in Node.js, rospy, ROS
  /// tools) are not concerned. Empty: the pages of this machine (http or https, host localhost,
  /// 127.0.0.1 or [::1], any port). "*" allows every origin. Refused handshakes get HTTP 403.
  std::vector<std::string> allowed_origins;
  /// When not empty, a client must first send {"op": "auth", "mac": <this token>} (rosbridge's
  /// auth op, with a shared token in place of rosauth's digest); every other op is refused
  /// until then, and a wrong token closes the connection.
  std::string auth_token;
  /// With a token set: seconds a client has to authenticate before its connection is closed
  /// (WebSocket code 1008), so that sockets left silent do not hold the connection slots; 0:
  /// never closed.
  double auth_timeout = 5.0;
  /// Connections at once, counted from the accepted handshake; more get HTTP 503.
  size_t max_clients = 100;
  size_t max_subscriptions = 256;  ///< topics a client may subscribe to, and advertise
  size_t max_services = 64;        ///< services a client may advertise
  /// Incoming messages larger than this close the connection with WebSocket code 1009.
  size_t max_message_bytes = 16u << 20;
  size_t max_client_queue = 200;  ///< messages waiting per client before drops
  /// Bytes in a client's socket queue beyond which its messages are dropped: a message (all
  /// its fragments) is handed to the socket only while the queue holds at most this many.
  size_t max_client_buffered = 4u << 20;
  /// Writes a line on stderr when a client connects or leaves: its address and port, and the
  /// number of clients then connected.
  bool log_clients = false;
  /// Whether clients may advertise and publish topics of their own and provide services (relayed
  /// to other clients). false: only auth, subscribe, unsubscribe and call_service are accepted,
  /// and only partsim's topics may be subscribed to.
  bool client_topics = true;
  /// Calls of one client to extension services (AddService) waiting for their answers; more are
  /// refused at once, so that one client's flood delays another's call by at most this many.
  size_t max_waiting_calls = 64;
  /// What the server is called in its messages ("rosbridge: cannot listen on ...").
  std::string label = "rosbridge";
};

namespace internal {
struct RosbridgeClient;
}  // namespace internal

/// A connected client as the server's extensions see it: compared, kept (weakly, as a
/// std::weak_ptr) and handed back to the server; its fields are the server's.
using RosbridgeClientPtr = std::shared_ptr<internal::RosbridgeClient>;

/// What a topic of an extension is told (on the network thread).
struct RosbridgeTopicHooks {
  /// A client subscribed (it may send the topic's current state at once, SendNow).
  std::function<void(const RosbridgeClientPtr& client)> on_subscribe;
  /// A client unsubscribed or left.
  std::function<void(const RosbridgeClientPtr& client)> on_unsubscribe;
};

/// Answers one call of an extension's service, once, from any thread: on success `values_json`
/// is the answer's "values" as JSON text (e.g. {"success": true}); on failure a message.
using RosbridgeServiceReply = std::function<void(bool success, const std::string& values_json)>;
/// Handles a call on the network thread: `args_json` is its args (a JSON object's text). It must
/// return quickly and answer through `reply`; what it throws is answered as a failure.
using RosbridgeService = std::function<void(
    const RosbridgeClientPtr& client, const std::string& args_json, RosbridgeServiceReply reply)>;

/// The simulation controls a server answers: /partsim/pause, /partsim/resume, /partsim/step
/// ({n}, 1 by default) and /partsim/reset, each offered when its function is set. Called on the
/// network thread; they must return quickly.
struct RosbridgeSimControls {
  std::function<void()> pause, resume, reset;
  std::function<void(long long n)> step;
};

/// A plain HTTP request to the server's port (the handshake of a WebSocket is not one).
struct RosbridgeHttpRequest {
  std::string method;  ///< "GET", ...
  std::string path;    ///< "/api/scene.json"
  std::string query;   ///< "token=T" ("" when none)
  /// Whether the request carries the server's token (?token=T or the header X-Partsim-Token).
  bool token_ok = false;
};
struct RosbridgeHttpAnswer {
  int status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body;
};
/// Answers one request, once, from any thread.
using RosbridgeHttpRespond = std::function<void(RosbridgeHttpAnswer answer)>;
/// Handles a request on the network thread (requests from an origin not allowed were refused
/// with 403 before): answers through `respond`, now or later, and returns the seconds to wait
/// for the answer before the server answers 503.
using RosbridgeHttpHandler =
    std::function<double(const RosbridgeHttpRequest& request, RosbridgeHttpRespond respond)>;

/// A random token of 32 hexadecimal digits (128 bits), for RosbridgeOptions::auth_token.
std::string RandomAuthToken();

/// Counters for the README and the tests.
struct RosbridgeStats {
  long long clients = 0;                ///< connected now
  long long authenticated_clients = 0;  ///< connected now and logged in (all without a token)
  long long messages_sent = 0;          ///< handed to sockets
  long long messages_dropped = 0;       ///< dropped for slow clients
  long long commands = 0;               ///< robot commands applied (from any front-end)
  double mean_latency_steps = 0.0;      ///< steps between a command's arrival and its application
  long long max_latency_steps = 0;
  long long errors = 0;   ///< error statuses and failed service responses sent
  long long refused = 0;  ///< handshakes refused (origin, connection cap)
  /// failed accepts (out of file descriptors), each then waits 100 ms
  long long accept_errors = 0;
  /// Most bytes seen waiting in one client's socket queue (after a message was handed to it):
  /// at most max_client_buffered plus one message with its fragments' framing.
  long long peak_buffered_bytes = 0;
};

class RosbridgeServer {
 public:
  /// Serves `robot`, commanded under /<robot name>/...; adds a step callback to its SimServer
  /// (construct before sim->Start()). The robot must outlive the server, and the SimServer must
  /// be stopped before the server is destroyed.
  explicit RosbridgeServer(ServedRobot* robot, const RosbridgeOptions& options = {});
  /// A server of what its extensions add (topics, services, simulation controls, HTTP), and of
  /// rosapi.
  explicit RosbridgeServer(const RosbridgeOptions& options);
  ~RosbridgeServer();
  RosbridgeServer(const RosbridgeServer&) = delete;
  RosbridgeServer& operator=(const RosbridgeServer&) = delete;

  /// Starts listening and serving on a thread of its own; throws partsim::Error if the port
  /// cannot be opened.
  void Start();
  /// Closes all connections and joins the network thread. Idempotent.
  void Stop();
  /// The port listened on (after Start).
  int GetPort() const;
  RosbridgeStats GetStats() const;

  // ---- extensions: what a front-end built on the server adds (before Start) ----
  /// A topic partsim publishes, of ROS type `type`; its messages are sent by the extension
  /// (SendNow, Publish). Throws partsim::Error for a name served already.
  void AddTopic(const std::string& name, const std::string& type, RosbridgeTopicHooks hooks = {});
  /// A service answered by `service`. Throws partsim::Error for a name served already.
  void AddService(const std::string& name, RosbridgeService service);
  /// The simulation controls (replacing the robot's, when it has them).
  void SetSimControls(const RosbridgeSimControls& controls);
  /// Answers plain HTTP requests (without one, the port answers WebSocket handshakes only).
  void SetHttpHandler(RosbridgeHttpHandler handler);
  /// Called on the network thread when a client leaves.
  void OnDisconnect(std::function<void(const RosbridgeClientPtr& client)> hook);
  /// Runs `fn` on the network thread every `seconds` while the server runs (first after
  /// `seconds`).
  void Every(double seconds, std::function<void()> fn);

  // ---- sending (see each for its thread) ----
  /// Runs `fn` on the network thread (any thread; dropped once stopped).
  void Post(std::function<void()> fn);
  /// Network thread: sends `text` to `client` now, after what waits in its queue. A
  /// `droppable` message (a publication) is dropped when the client's socket holds more than
  /// max_client_buffered bytes. True when handed to the socket.
  bool SendNow(const RosbridgeClientPtr& client, const std::string& text, bool droppable);
  /// Any thread: publishes `msg_json` (the msg object's JSON text) on `topic` to its
  /// subscribers, with their throttle, queue and fragment settings.
  void Publish(const std::string& topic, const std::string& msg_json);
  /// Any thread: the clients subscribed to `topic` now.
  std::vector<RosbridgeClientPtr> Subscribers(const std::string& topic) const;
  /// Any thread: whether `client` subscribes to `topic`.
  bool Subscribes(const RosbridgeClientPtr& client, const std::string& topic) const;
  /// Network thread: sends an error status to `client` (counted in the stats' errors).
  void SendError(const RosbridgeClientPtr& client, const std::string& message);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace partsim
