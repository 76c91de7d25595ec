// The rosbridge v2 protocol of RosbridgeServer, apart from its WebSocket transport and from what
// is served: the clients' state (subscriptions, advertised topics and services, messages in
// fragments), the ops (auth, subscribe, publish, call_service, ...) by table, partsim's topics and
// services by table (filled by the served robot, rosbridge_robot.cc, and by extensions such as
// the browser viewer), the simulation controls, rosapi, and the calls relayed to
// client-advertised services. Messages are handed to a RosbridgeTransport, which queues and sends
// them.
#pragma once

#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "partsim/server/rosbridge.h"
#include "partsim/server/served_robot.h"
#include "server/ros_json.h"

namespace partsim::internal {

using WallClock = std::chrono::steady_clock;

/// One subscribe request of a client.
struct SubscribeRequest {
  double throttle_ms = 0;
  size_t queue_length = 0;   ///< 0: the server's bound
  size_t fragment_size = 0;  ///< 0: whole messages
  bool cbor = false;         ///< binary CBOR frames (uint8[] as byte strings) instead of JSON
  long long order = 0;       ///< later requests choose the compression
};

/// A client's subscription to one topic: one message per publication, however many subscribe
/// requests (by id) it made; the most permissive settings of the requests apply.
struct Subscription : SubscribeRequest {
  std::map<std::string, SubscribeRequest> requests;  ///< by subscribe id
  WallClock::time_point last_sent{};
  /// Recomputes the settings from the requests.
  void Merge();
};

/// A message waiting for a client. The text is shared by every client it goes to: the
/// simulation thread queues a pointer per client; fragmenting happens on the network thread.
struct Outgoing {
  std::shared_ptr<const std::string> data;
  bool binary = false;
  std::string topic;         ///< the subscription it was published for; "" for replies
  size_t fragment_size = 0;  ///< > 0: sent as rosbridge fragments of this many characters
};

/// An incoming message arriving in fragments. Only the pieces received are held: memory follows
/// the bytes a client sent, never the `total` it announced.
struct Partial {
  size_t total = 0;
  std::map<size_t, std::string> pieces;  ///< num -> data
  size_t bytes = 0;
};

/// Longest topic, type, service and op name, in bytes (ROS names are rarely over 100): longer
/// ones are refused with an error naming the field, before they are stored or echoed.
constexpr size_t kMaxNameBytes = 256;

/// Longest message id, in bytes (as text, for ids that are not strings): ids are stored with
/// subscribe requests and calls, and echoed in replies.
constexpr size_t kMaxIdBytes = 1024;

/// Smallest fragment_size of a subscription, in characters; smaller requests are raised to it.
/// Each fragment costs a frame of about 100 bytes beside its data (and a WebSocket message on
/// the network thread): one-character pieces multiplied a message a hundredfold.
constexpr size_t kMinFragmentSize = 1024;

/// A connected client.
struct RosbridgeClient {
  std::weak_ptr<void> connection;  ///< the transport's handle of the connection
  std::string address;             ///< the peer's address and port, for the log
  // protocol state (clients_mutex, except `partial` and `authenticated`: network thread)
  std::map<std::string, Subscription> subs;
  std::map<std::string, std::string> advertised;  ///< topic -> type
  std::set<std::string> services;                 ///< advertised by this client
  std::map<std::string, Partial> partial;         ///< fragments by message id
  std::atomic<bool> authenticated{false};         ///< true from the start when no token is set
  /// Calls of this client to extension services not answered yet (any thread).
  std::shared_ptr<std::atomic<int>> waiting = std::make_shared<std::atomic<int>>(0);
  // the transport's outgoing queue
  std::mutex out_mutex;
  std::deque<Outgoing> out;
  std::atomic<bool> flush_scheduled{false};
};
using ClientPtr = std::shared_ptr<RosbridgeClient>;

/// What the protocol asks of the transport.
class RosbridgeTransport {
 public:
  virtual ~RosbridgeTransport() = default;
  /// Queues `data` for `client`, from any thread. A message published for `topic` keeps at most
  /// `bound` (0: the server's max_client_queue) of that topic's messages waiting, the oldest
  /// dropped first; replies (no topic) are dropped only beyond max_client_queue in all.
  /// `fragment_size` > 0: sent as rosbridge fragments of that many characters.
  virtual void Send(const ClientPtr& client, std::shared_ptr<const std::string> data, size_t bound,
                    bool binary, const std::string& topic, size_t fragment_size) = 0;
  /// Closes the client's connection as a policy violation, saying `reason`.
  virtual void Close(const ClientPtr& client, const std::string& reason) = 0;
};

class RosbridgeProtocol {
 public:
  /// An op's handler: (client, whole message, its id or null).
  using OpHandler = void (RosbridgeProtocol::*)(const ClientPtr&, const Json&, const Json&);
  /// A built-in service: values to answer with at once, or nullopt when it answers later.
  using ServiceHandler = std::function<std::optional<Json>(
      const ClientPtr& client, const std::string& service, const Json& args, const Json& id)>;
  /// A message a client published to one of partsim's command topics (network thread).
  using CommandHandler = std::function<void(const ClientPtr& client, const std::string& topic,
                                            const Json& msg, const Json& id)>;

  /// Serves the clients of `transport`, which must outlive the protocol; what it serves is
  /// added with AddTopic, AddService and SetSimControls before clients connect.
  RosbridgeProtocol(const RosbridgeOptions& options, RosbridgeTransport* transport);

  // ---- what is served (before clients connect) ----
  /// A topic partsim publishes (`command` empty) or one it subscribes to (clients publish
  /// commands to it, handled by `command`). Throws partsim::Error for a name added already.
  void AddTopic(const std::string& name, const std::string& type, CommandHandler command = {},
                RosbridgeTopicHooks hooks = {});
  /// A service answered by partsim. Throws partsim::Error for a name added already.
  void AddService(const std::string& name, ServiceHandler handler);
  /// An extension's service (RosbridgeServer::AddService): its failures, thrown or replied, are
  /// answered as failed service responses; calls waiting for their answers are bounded per
  /// client (max_waiting_calls).
  void AddExtensionService(const std::string& name, RosbridgeService service);
  /// /partsim/pause, /partsim/resume, /partsim/step and /partsim/reset, each offered when set.
  void SetSimControls(const RosbridgeSimControls& controls);
  /// Called on the network thread when a client leaves (after it is forgotten).
  void AddDisconnectHook(std::function<void(const ClientPtr& client)> hook);

  // ---- clients (network thread) ----
  /// Registers a client that connected; returns the number connected then.
  size_t AddClient(const ClientPtr& client);
  /// Forgets the client of `connection` (its pending calls failed or dropped); returns it, or
  /// null when unknown, and sets `*count` to the number still connected.
  ClientPtr RemoveClient(const std::weak_ptr<void>& connection, size_t* count);
  ClientPtr FindClient(const std::weak_ptr<void>& connection) const;
  size_t ClientCount() const;
  /// Clients connected that have authenticated (all of them when no token is set).
  size_t AuthenticatedCount() const;
  /// One whole message (or one fragment of one) from a client; never throws: whatever goes
  /// wrong is answered with an error status.
  void OnMessage(const ClientPtr& client, const std::string& payload);

  // ---- publishing (any thread) ----
  /// Sends `make()` (built once, and encoded once per form: JSON text or CBOR) to the clients
  /// subscribed to `topic` that are not throttled. uint8[] fields are json::binary values:
  /// base64 strings in JSON, byte strings in CBOR.
  void Publish(const std::string& topic, const std::function<Json()>& make,
               WallClock::time_point now);
  /// Whether some client subscribes to `topic`.
  bool Wanted(const std::string& topic) const;
  /// The clients subscribed to `topic` now.
  std::vector<ClientPtr> Subscribers(const std::string& topic) const;
  bool Subscribes(const ClientPtr& client, const std::string& topic) const;
  /// Sends an error status to `client` (counted in Errors()).
  void SendError(const ClientPtr& client, const std::string& message) {
    Status(client, "error", message);
  }
  /// A reply (status, service response) for `client`, queued in order.
  void Reply(const ClientPtr& c, const Json& j);
  /// Counts an error answered in a way of the caller's own.
  void CountError() { ++errors_; }

  /// Error statuses and failed service responses sent.
  long long Errors() const { return errors_; }

 private:
  /// A call relayed to a client-advertised service.
  struct PendingCall {
    std::weak_ptr<RosbridgeClient> caller;
    Json id;
    std::weak_ptr<RosbridgeClient> provider;
    std::string service;
    WallClock::time_point since;
  };

  void Status(const ClientPtr& c, const std::string& level, const std::string& msg,
              const Json& id = nullptr);
  void HandleText(const ClientPtr& c, const std::string& payload);
  bool Reassemble(const ClientPtr& c, const Json& j, std::string* whole);

  // ops
  void OpSubscribe(const ClientPtr& c, const Json& j, const Json& id);
  void OpUnsubscribe(const ClientPtr& c, const Json& j, const Json& id);
  void OpAdvertise(const ClientPtr& c, const Json& j, const Json& id);
  void OpUnadvertise(const ClientPtr& c, const Json& j, const Json& id);
  void OpPublish(const ClientPtr& c, const Json& j, const Json& id);
  void OpCallService(const ClientPtr& c, const Json& j, const Json& id);
  void OpAdvertiseService(const ClientPtr& c, const Json& j, const Json& id);
  void OpUnadvertiseService(const ClientPtr& c, const Json& j, const Json& id);
  void OpServiceResponse(const ClientPtr& c, const Json& j, const Json& id);
  void OpAuth(const ClientPtr& c, const Json& j, const Json& id);
  void OpNotSupported(const ClientPtr& c, const Json& j, const Json& id);

  // services
  void AddRosapiServices();
  const ServiceHandler* FindService(const std::string& name) const;

  // calls to client-advertised services (clients_mutex_ held)
  void AbandonCalls(const ClientPtr& provider, const std::string& service, const std::string& why);
  void FailCall(const PendingCall& call, const std::string& why);
  void ExpireCalls();

  // topics
  /// partsim's topics by name: type, and the handler of commands for those it subscribes to.
  struct Topic {
    std::string type;
    CommandHandler command;  ///< empty: partsim publishes the topic
    RosbridgeTopicHooks hooks;
  };
  std::string TopicList() const;
  std::map<std::string, std::string> AllTopics() const;  // clients_mutex_ held
  bool WantedLocked(const std::string& topic) const;     // clients_mutex_ held

  RosbridgeOptions options_;
  RosbridgeTransport* transport_;
  std::map<std::string, OpHandler> ops_;
  std::map<std::string, Topic> topics_;                           // set before clients connect
  std::vector<std::pair<std::string, ServiceHandler>> services_;  // in the order rosapi lists
  std::vector<std::function<void(const ClientPtr&)>> disconnect_hooks_;

  mutable std::mutex clients_mutex_;
  std::map<std::weak_ptr<void>, ClientPtr, std::owner_less<std::weak_ptr<void>>> clients_;
  std::map<std::string, PendingCall> pending_calls_;  // our call id -> call (clients_mutex_)
  std::mt19937_64 call_ids_{std::random_device{}()};  // clients_mutex_
  std::atomic<long long> next_request_{0};
  std::atomic<long long> errors_{0};
};

}  // namespace partsim::internal
