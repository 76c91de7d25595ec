// A rosbridge v2 protocol server (JSON over WebSocket) in front of a ServedRobot: /clock,
// /joint_states and /tf (links and camera optical frames) are published from the simulation
// thread; joint position, velocity, effort and trajectory commands, motion planning
// (/<robot>/plan), rosapi services and the simulation controls (pause, resume, reset, step) come
// in. Each client has its own subscriptions and a bounded outgoing queue: a client that reads
// slowly loses messages, the simulation never waits for it. Every camera of the served robot
// publishes /<camera>/image_raw, /<camera>/camera_info and /<camera>/points, and its IMU /imu;
// sensors are read (cameras rendered) on the simulation thread between steps, and only while
// some client subscribes.
#pragma once

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
};

/// Counters for the README and the tests.
struct RosbridgeStats {
  long long clients = 0;            ///< connected now
  long long messages_sent = 0;      ///< handed to sockets
  long long messages_dropped = 0;   ///< dropped for slow clients
  long long commands = 0;           ///< robot commands applied (from any front-end)
  double mean_latency_steps = 0.0;  ///< steps between a command's arrival and its application
  long long max_latency_steps = 0;
  long long errors = 0;   ///< status errors sent
  long long refused = 0;  ///< handshakes refused (origin, connection cap)
  long long accept_errors =
      0;  ///< failed accepts (out of file descriptors), each then waits 100 ms
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

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace partsim
