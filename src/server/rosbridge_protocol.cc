#include "server/rosbridge_protocol.h"

#include <algorithm>
#include <cstdio>

#include "core/json_parse.h"
#include "partsim/core/error.h"
#include "server/web_security.h"

namespace partsim::internal {

namespace {

// Most pieces of fragmented messages held for one client at a time (each costs a map node
// beside its bytes): a 16 MB message arrives in pieces of 256 bytes or more.
constexpr size_t kMaxFragmentsHeld = 65536;

// Messages in pieces held for one client at once.
constexpr size_t kMaxPartialMessages = 16;

// Calls to client-advertised services: unanswered ones per caller, and how long one may wait.
constexpr size_t kMaxPendingCalls = 100;
constexpr std::chrono::seconds kCallTimeout{60};

// Open subscribe requests (distinct ids) of one client on one topic, and on all its topics.
constexpr size_t kMaxRequestsPerTopic = 64;
constexpr size_t kMaxRequestsPerClient = 1024;

/// Throws unless `value` (field `key` of op `op`) is at most kMaxNameBytes long.
void CheckNameLength(const std::string& value, const std::string& key, const std::string& op) {
  if (value.size() > kMaxNameBytes)
    throw Error("op '" + op + "': '" + key + "' is " + std::to_string(value.size()) +
                " bytes long (at most " + std::to_string(kMaxNameBytes) + ")");
}

std::string Str(const Json& j, const char* key, const std::string& op) {
  if (!j.contains(key) || !j[key].is_string())
    throw Error("op '" + op + "' needs a string '" + key + "'");
  std::string s = j[key].get<std::string>();
  CheckNameLength(s, key, op);
  return s;
}

/// A topic or service name; ROS resolves "rosapi/topics" to "/rosapi/topics" at the root.
std::string Name(const Json& j, const char* key, const std::string& op) {
  std::string n = Str(j, key, op);
  if (n.empty()) throw Error("op '" + op + "': empty '" + key + "'");
  return n[0] == '/' ? n : "/" + n;
}

/// The key of a subscribe request or message id: strings as they are, other ids as JSON text.
std::string IdKey(const Json& id) { return id.is_string() ? id.get<std::string>() : DumpJson(id); }

}  // namespace

void Subscription::Merge() {
  throttle_ms = 1e300;
  queue_length = fragment_size = 0;
  bool server_bound = false, all_fragment = true;
  long long latest = -1;
  for (const auto& [id, r] : requests) {
    throttle_ms = std::min(throttle_ms, r.throttle_ms);
    if (r.queue_length == 0) server_bound = true;  // the largest queue there is
    queue_length = std::max(queue_length, r.queue_length);
    all_fragment = all_fragment && r.fragment_size > 0;
    fragment_size = fragment_size == 0 ? r.fragment_size : std::min(fragment_size, r.fragment_size);
    if (r.order > latest) {
      latest = r.order;
      cbor = r.cbor;
    }
  }
  if (server_bound) queue_length = 0;
  if (!all_fragment) fragment_size = 0;
}

RosbridgeProtocol::RosbridgeProtocol(const RosbridgeOptions& options, RosbridgeTransport* transport)
    : options_(options), transport_(transport) {
  ops_ = {{"subscribe", &RosbridgeProtocol::OpSubscribe},
          {"unsubscribe", &RosbridgeProtocol::OpUnsubscribe},
          {"call_service", &RosbridgeProtocol::OpCallService},
          {"auth", &RosbridgeProtocol::OpAuth}};
  const std::map<std::string, OpHandler> relays = {
      {"advertise", &RosbridgeProtocol::OpAdvertise},
      {"unadvertise", &RosbridgeProtocol::OpUnadvertise},
      {"publish", &RosbridgeProtocol::OpPublish},
      {"advertise_service", &RosbridgeProtocol::OpAdvertiseService},
      {"unadvertise_service", &RosbridgeProtocol::OpUnadvertiseService},
      {"service_response", &RosbridgeProtocol::OpServiceResponse}};
  for (const auto& [op, handler] : relays)
    ops_[op] = options_.client_topics ? handler : &RosbridgeProtocol::OpNotSupported;
  AddRosapiServices();
}

// ---- what is served ----

void RosbridgeProtocol::AddTopic(const std::string& name, const std::string& type,
                                 CommandHandler command, RosbridgeTopicHooks hooks) {
  if (name.empty() || name[0] != '/') throw Error("topic '" + name + "' does not start with '/'");
  if (!topics_.emplace(name, Topic{type, std::move(command), std::move(hooks)}).second)
    throw Error("topic " + name + " is served already");
}

void RosbridgeProtocol::AddService(const std::string& name, ServiceHandler handler) {
  if (name.empty() || name[0] != '/') throw Error("service '" + name + "' does not start with '/'");
  for (auto& [n, h] : services_)
    if (n == name) throw Error("service " + name + " is served already");
  services_.emplace_back(name, std::move(handler));
}

void RosbridgeProtocol::AddExtensionService(const std::string& name, RosbridgeService service) {
  AddService(
      name,
      [this, service](const ClientPtr& c, const std::string& name, const Json& args,
                      const Json& id) -> std::optional<Json> {
        // a failure, thrown now or replied later, is a failed service response naming the service
        auto fail = [this, name, id](const ClientPtr& to, const std::string& why) {
          ++errors_;
          Reply(to, ServiceResponseToJson(name, name + ": " + why, false, id));
        };
        if (!args.is_object() && !args.is_null()) {
          fail(c, "args must be an object, got " + DumpJson(args));
          return std::nullopt;
        }
        if (static_cast<size_t>(++*c->waiting) > options_.max_waiting_calls) {
          --*c->waiting;
          fail(c, "too many calls waiting: at most " + std::to_string(options_.max_waiting_calls) +
                      " calls of a client wait for their answers; wait for them, then call again");
          return std::nullopt;
        }
        std::weak_ptr<RosbridgeClient> weak = c;
        auto once = std::make_shared<std::atomic<bool>>(false);
        RosbridgeServiceReply reply = [this, weak, waiting = c->waiting, name, id, once, fail](
                                          bool ok, const std::string& text) {
          if (once->exchange(true)) return;
          --*waiting;
          ClientPtr to = weak.lock();
          if (!to) return;
          if (!ok) return fail(to, text);
          Json values;
          try {
            values = ParseJsonBounded(text);
          } catch (const std::exception& e) {
            return fail(to, std::string("bad answer from the service: ") + e.what());
          }
          Reply(to, ServiceResponseToJson(name, values, true, id));
        };
        try {
          service(c, DumpJson(args.is_null() ? Json::object() : args), reply);
        } catch (const std::exception& e) {
          reply(false, e.what());
        }
        return std::nullopt;
      });
}

void RosbridgeProtocol::SetSimControls(const RosbridgeSimControls& controls) {
  for (const char* name : {"/partsim/pause", "/partsim/resume", "/partsim/step", "/partsim/reset"})
    services_.erase(std::remove_if(services_.begin(), services_.end(),
                                   [&](const auto& s) { return s.first == name; }),
                    services_.end());
  auto simple = [](const char* name, std::function<void()> f) {
    return [name, f](const ClientPtr&, const std::string&, const Json& args,
                     const Json&) -> std::optional<Json> {
      if (!args.is_object() && !args.is_null())
        throw Error(std::string(name) + ": args must be an object, got " + DumpJson(args));
      f();
      return Json::object();
    };
  };
  if (controls.pause) AddService("/partsim/pause", simple("/partsim/pause", controls.pause));
  if (controls.resume) AddService("/partsim/resume", simple("/partsim/resume", controls.resume));
  if (controls.reset) AddService("/partsim/reset", simple("/partsim/reset", controls.reset));
  if (controls.step)
    AddService("/partsim/step",
               [step = controls.step](const ClientPtr&, const std::string&, const Json& args,
                                      const Json&) -> std::optional<Json> {
                 if (!args.is_object() && !args.is_null())
                   throw Error("/partsim/step: args must be an object, got " + DumpJson(args));
                 step(StepCountFromJson(args));
                 return Json::object();
               });
}

void RosbridgeProtocol::AddDisconnectHook(std::function<void(const ClientPtr& client)> hook) {
  disconnect_hooks_.push_back(std::move(hook));
}

// ---- clients ----

size_t RosbridgeProtocol::AddClient(const ClientPtr& client) {
  client->authenticated = options_.auth_token.empty();
  std::lock_guard<std::mutex> lock(clients_mutex_);
  clients_[client->connection] = client;
  return clients_.size();
}

ClientPtr RosbridgeProtocol::RemoveClient(const std::weak_ptr<void>& connection, size_t* count) {
  ClientPtr c;
  {
    std::lock_guard<std::mutex> lock(clients_mutex_);
    *count = clients_.size();
    auto it = clients_.find(connection);
    if (it == clients_.end()) return nullptr;
    c = it->second;
    clients_.erase(it);
    *count = clients_.size();
    // its calls are forgotten, and the callers of the services it provided told
    for (auto call = pending_calls_.begin(); call != pending_calls_.end();) {
      if (call->second.caller.lock() == c)
        call = pending_calls_.erase(call);
      else
        ++call;
    }
    AbandonCalls(c, "", "the provider disconnected");
  }
  // what was served to it is told (a robot's plans for it are dropped, a viewer's state of it
  // forgotten)
  for (const auto& [name, topic] : topics_)
    if (topic.hooks.on_unsubscribe && c->subs.count(name)) topic.hooks.on_unsubscribe(c);
  for (const auto& hook : disconnect_hooks_) hook(c);
  return c;
}

ClientPtr RosbridgeProtocol::FindClient(const std::weak_ptr<void>& connection) const {
  std::lock_guard<std::mutex> lock(clients_mutex_);
  auto it = clients_.find(connection);
  return it == clients_.end() ? nullptr : it->second;
}

size_t RosbridgeProtocol::ClientCount() const {
  std::lock_guard<std::mutex> lock(clients_mutex_);
  return clients_.size();
}

size_t RosbridgeProtocol::AuthenticatedCount() const {
  std::lock_guard<std::mutex> lock(clients_mutex_);
  size_t n = 0;
  for (const auto& [h, c] : clients_) n += c->authenticated;
  return n;
}

void RosbridgeProtocol::Reply(const ClientPtr& c, const Json& j) {
  transport_->Send(c, std::make_shared<const std::string>(DumpJson(j)), 0, false, "", 0);
}

void RosbridgeProtocol::Status(const ClientPtr& c, const std::string& level, const std::string& msg,
                               const Json& id) {
  if (level == "error") ++errors_;
  Reply(c, StatusToJson(level, msg, id));
}

// ---- incoming messages (network thread) ----

void RosbridgeProtocol::OnMessage(const ClientPtr& c, const std::string& payload) {
  // nothing a client sends may end the network thread
  try {
    HandleText(c, payload);
  } catch (const std::exception& e) {
    try {
      Status(c, "error", std::string("could not handle the message: ") + e.what());
    } catch (...) {
    }
  } catch (...) {
  }
}

void RosbridgeProtocol::HandleText(const ClientPtr& c, const std::string& payload) {
  // a client that has not authenticated may send the auth op alone: anything longer is refused
  // unparsed, so that it costs the server no more than its bytes
  if (!c->authenticated && payload.size() > kMaxUnauthenticatedBytes) {
    Status(c, "error",
           "authenticate first: before {\"op\": \"auth\"} succeeds, messages are limited to " +
               std::to_string(kMaxUnauthenticatedBytes) + " bytes (got " +
               std::to_string(payload.size()) + ")");
    return;
  }
  Json j;
  try {
    j = ParseJsonBounded(payload);
  } catch (const std::exception& e) {
    Status(c, "error", std::string("malformed JSON: ") + e.what());
    return;
  }
  Json id = j.is_object() && j.contains("id") ? j["id"] : Json();
  // ids are stored and echoed: a long one is refused, and not echoed
  if (!id.is_null()) {
    const size_t id_bytes =
        id.is_string() ? id.get_ref<const std::string&>().size() : DumpJson(id).size();
    if (id_bytes > kMaxIdBytes) {
      Status(c, "error",
             "'id' is " + std::to_string(id_bytes) + " bytes long (at most " +
                 std::to_string(kMaxIdBytes) + ")");
      return;
    }
  }
  if (!c->authenticated) {
    // with a token set, nothing but the auth op until it has come right
    const bool auth = j.is_object() && j.contains("op") && j["op"] == "auth";
    if (!auth) {
      Status(c, "error",
             "authenticate first: send {\"op\": \"auth\", \"mac\": <the server's token>}", id);
      return;
    }
    const bool ok = j.contains("mac") && j["mac"].is_string() &&
                    SameToken(j["mac"].get<std::string>(), options_.auth_token);
    if (!ok) {
      Status(c, "error", "auth: wrong token; closing the connection", id);
      transport_->Close(c, "authentication failed");
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
    const std::string& op = j["op"].get_ref<const std::string&>();
    if (op.size() > kMaxNameBytes)
      throw Error("'op' is " + std::to_string(op.size()) + " bytes long (at most " +
                  std::to_string(kMaxNameBytes) + ")");
    auto handler = ops_.find(op);
    if (handler == ops_.end()) throw Error("unknown op '" + op + "'");
    (this->*handler->second)(c, j, id);
  } catch (const std::exception& e) {
    Status(c, "error", e.what(), id);
  }
}

bool RosbridgeProtocol::Reassemble(const ClientPtr& c, const Json& j, std::string* whole) {
  if (!j.contains("id") || !(j["id"].is_string() || j["id"].is_number()))
    throw Error("fragment needs an 'id'");
  if (!j.contains("data") || !j["data"].is_string()) throw Error("fragment needs string 'data'");
  if (!j.contains("num") || !j["num"].is_number_unsigned() || !j.contains("total") ||
      !j["total"].is_number_unsigned() || j["total"].get<size_t>() == 0 ||
      j["num"].get<size_t>() >= j["total"].get<size_t>())
    throw Error("fragment needs integers 0 <= num < total");
  const std::string key = IdKey(j["id"]);
  const size_t total = j["total"].get<size_t>(), num = j["num"].get<size_t>();
  if (total > kMaxFragmentsHeld)
    throw Error("fragment: total " + std::to_string(total) + " is more than " +
                std::to_string(kMaxFragmentsHeld) + " pieces");
  auto it = c->partial.find(key);
  if (it == c->partial.end()) {
    if (c->partial.size() >= kMaxPartialMessages)
      throw Error("fragment: too many messages in pieces at once");
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
  if (held - replaced + data.size() > options_.max_message_bytes) {
    c->partial.erase(it);
    throw Error("fragment '" + key + "': the pieces held for this client exceed " +
                std::to_string(options_.max_message_bytes) + " bytes");
  }
  p.bytes = p.bytes - replaced + data.size();
  p.pieces[num] = data;
  if (p.pieces.size() < total) return false;
  // all pieces have come: the message in order of num
  whole->clear();
  whole->reserve(p.bytes);
  for (const auto& [k, piece] : p.pieces) *whole += piece;
  c->partial.erase(it);
  return true;
}

// ---- ops ----

void RosbridgeProtocol::OpSubscribe(const ClientPtr& c, const Json& j, const Json& id) {
  const std::string op = "subscribe", topic = Name(j, "topic", op);
  auto served = topics_.find(topic);
  // without client topics, nothing but partsim's topics will ever be published
  if (!options_.client_topics && (served == topics_.end() || served->second.command))
    throw Error("subscribe: no topic '" + topic + "' (" + options_.label + " publishes " +
                TopicList() + ")");
  if (j.contains("type") && j["type"].is_string()) {
    const std::string type = Str(j, "type", op);
    std::lock_guard<std::mutex> lock(clients_mutex_);
    auto all = AllTopics();
    auto it = all.find(topic);
    if (it != all.end() && it->second != type)
      throw Error("subscribe " + topic + ": type is " + it->second + ", not " + type);
  }
  // the request's settings; out-of-range values are ignored, as rosbridge does
  SubscribeRequest s;
  s.order = next_request_++;
  if (j.contains("throttle_rate") && j["throttle_rate"].is_number())
    s.throttle_ms = j["throttle_rate"].get<double>();
  if (j.contains("queue_length") && j["queue_length"].is_number_integer() &&
      j["queue_length"].get<long long>() > 0)
    s.queue_length = static_cast<size_t>(j["queue_length"].get<long long>());
  if (j.contains("fragment_size") && j["fragment_size"].is_number_integer() &&
      j["fragment_size"].get<long long>() > 0)
    s.fragment_size =
        std::max(kMinFragmentSize, static_cast<size_t>(j["fragment_size"].get<long long>()));
  if (j.contains("compression") && j["compression"].is_string()) {
    const std::string comp = Str(j, "compression", op);
    if (comp == "cbor")
      s.cbor = true;
    else if (comp != "none" && comp != "")
      throw Error("subscribe " + topic + ": compression '" + comp +
                  "' is not supported (none, cbor)");
  }
  const std::string sub_id = id.is_null() ? "" : IdKey(id);
  std::unique_lock<std::mutex> lock(clients_mutex_);
  if (!c->subs.count(topic) && c->subs.size() >= options_.max_subscriptions)
    throw Error("subscribe " + topic + ": this client already subscribes to " +
                std::to_string(c->subs.size()) + " topics (at most " +
                std::to_string(options_.max_subscriptions) + ")");
  auto existing = c->subs.find(topic);
  const bool new_request = existing == c->subs.end() || !existing->second.requests.count(sub_id);
  if (new_request) {
    size_t open = 0;
    for (const auto& [t, other] : c->subs) open += other.requests.size();
    if (open >= kMaxRequestsPerClient)
      throw Error("subscribe " + topic + ": " + std::to_string(open) +
                  " subscribe requests of this client are open (at most " +
                  std::to_string(kMaxRequestsPerClient) + " on all its topics)");
  }
  Subscription& sub = c->subs[topic];
  if (new_request && sub.requests.size() >= kMaxRequestsPerTopic)
    throw Error("subscribe " + topic + ": " + std::to_string(sub.requests.size()) +
                " subscribe requests of this client are open on it (at most " +
                std::to_string(kMaxRequestsPerTopic) + ")");
  const bool first = sub.requests.empty();
  sub.requests[sub_id] = s;
  sub.Merge();
  if (first && served != topics_.end() && served->second.hooks.on_subscribe) {
    lock.unlock();
    served->second.hooks.on_subscribe(c);
  }
}

void RosbridgeProtocol::OpUnsubscribe(const ClientPtr& c, const Json& j, const Json& id) {
  // with an id: that subscribe request only; without: the whole topic
  const std::string topic = Name(j, "topic", "unsubscribe");
  {
    std::lock_guard<std::mutex> lock(clients_mutex_);
    auto it = c->subs.find(topic);
    if (it == c->subs.end()) return;
    if (!id.is_null()) {
      it->second.requests.erase(IdKey(id));
      if (!it->second.requests.empty()) {
        it->second.Merge();
        return;
      }
    }
    c->subs.erase(it);
  }
  auto served = topics_.find(topic);
  if (served != topics_.end() && served->second.hooks.on_unsubscribe)
    served->second.hooks.on_unsubscribe(c);
}

void RosbridgeProtocol::OpAdvertise(const ClientPtr& c, const Json& j, const Json&) {
  const std::string op = "advertise", topic = Name(j, "topic", op), type = Str(j, "type", op);
  auto it = topics_.find(topic);
  if (it != topics_.end() && it->second.type != type)
    throw Error("advertise " + topic + ": its type is " + it->second.type + ", not " + type);
  std::lock_guard<std::mutex> lock(clients_mutex_);
  for (auto& [h, other] : clients_) {
    auto o = other->advertised.find(topic);
    if (o != other->advertised.end() && o->second != type)
      throw Error("advertise " + topic + ": already advertised as " + o->second);
  }
  if (!c->advertised.count(topic) && c->advertised.size() >= options_.max_subscriptions)
    throw Error("advertise " + topic + ": this client already advertises " +
                std::to_string(c->advertised.size()) + " topics (at most " +
                std::to_string(options_.max_subscriptions) + ")");
  c->advertised[topic] = type;
}

void RosbridgeProtocol::OpUnadvertise(const ClientPtr& c, const Json& j, const Json&) {
  const std::string topic = Name(j, "topic", "unadvertise");
  std::lock_guard<std::mutex> lock(clients_mutex_);
  c->advertised.erase(topic);
}

void RosbridgeProtocol::OpPublish(const ClientPtr& c, const Json& j, const Json& id) {
  const std::string topic = Name(j, "topic", "publish");
  if (!j.contains("msg")) throw Error("publish " + topic + ": no 'msg'");
  if (auto served = topics_.find(topic); served != topics_.end()) {
    if (!served->second.command)
      throw Error("publish " + topic + ": the simulation publishes this topic");
    served->second.command(c, topic, j["msg"], id);
    return;
  }
  // a client's own topic: relay to its subscribers
  auto text = std::make_shared<const std::string>(DumpJson(PublishToJson(topic, j["msg"])));
  std::lock_guard<std::mutex> lock(clients_mutex_);
  for (auto& [h, other] : clients_) {
    auto it = other->subs.find(topic);
    if (it != other->subs.end())
      transport_->Send(other, text, it->second.queue_length, false, topic, 0);
  }
}

void RosbridgeProtocol::OpCallService(const ClientPtr& c, const Json& j, const Json& id) {
  const std::string service = Name(j, "service", "call_service");
  const Json args = j.contains("args") ? j["args"] : Json::object();
  if (const ServiceHandler* builtin = FindService(service)) {
    if (std::optional<Json> values = (*builtin)(c, service, args, id))
      Reply(c, ServiceResponseToJson(service, *values, true, id));
    return;
  }
  // a service some client advertised: forward it with our own id, which no other client can
  // guess
  std::lock_guard<std::mutex> lock(clients_mutex_);
  ExpireCalls();
  for (auto& [h, provider] : clients_) {
    if (!provider->services.count(service)) continue;
    size_t mine = 0;
    for (const auto& [k, call] : pending_calls_) mine += call.caller.lock() == c;
    if (mine >= kMaxPendingCalls)
      throw Error("call_service " + service + ": " + std::to_string(mine) +
                  " calls of this client are still unanswered (at most " +
                  std::to_string(kMaxPendingCalls) + ")");
    char buf[64];
    std::snprintf(buf, sizeof(buf), "partsim_call_%016llx%016llx",
                  static_cast<unsigned long long>(call_ids_()),
                  static_cast<unsigned long long>(call_ids_()));
    pending_calls_[buf] = {c, id, provider, service, WallClock::now()};
    Reply(provider,
          Json{{"op", "call_service"}, {"service", service}, {"args", args}, {"id", buf}});
    return;
  }
  // answered as a failed call (what roslib's callService reports to its error callback), then
  // as an error status, as rosbridge does, naming the services there are
  std::string names;
  for (const auto& [name, handler] : services_) names += (names.empty() ? "" : ", ") + name;
  for (auto& [h, provider] : clients_)
    for (const std::string& name : provider->services) names += ", " + name;
  const std::string why =
      "call_service: no service '" + service + "' (" + options_.label + " answers " + names + ")";
  ++errors_;
  Reply(c, ServiceResponseToJson(service, why, false, id));
  Status(c, "error", why, id);
}

void RosbridgeProtocol::OpAdvertiseService(const ClientPtr& c, const Json& j, const Json&) {
  const std::string service = Name(j, "service", "advertise_service");
  std::lock_guard<std::mutex> lock(clients_mutex_);
  if (FindService(service))
    throw Error("advertise_service " + service + ": partsim provides this service");
  for (auto& [h, other] : clients_)
    if (other != c && other->services.count(service))
      throw Error("advertise_service " + service +
                  ": another client provides this service (it must unadvertise first)");
  if (!c->services.count(service) && c->services.size() >= options_.max_services)
    throw Error("advertise_service " + service + ": this client already provides " +
                std::to_string(c->services.size()) + " services (at most " +
                std::to_string(options_.max_services) + ")");
  c->services.insert(service);
}

void RosbridgeProtocol::OpUnadvertiseService(const ClientPtr& c, const Json& j, const Json&) {
  const std::string service = Name(j, "service", "unadvertise_service");
  std::lock_guard<std::mutex> lock(clients_mutex_);
  c->services.erase(service);
  AbandonCalls(c, service, "the provider unadvertised " + service);
}

void RosbridgeProtocol::OpServiceResponse(const ClientPtr& c, const Json& j, const Json&) {
  if (!j.contains("id") || !j["id"].is_string())
    throw Error("service_response needs the 'id' of the call it answers");
  std::lock_guard<std::mutex> lock(clients_mutex_);
  auto it = pending_calls_.find(j["id"].get<std::string>());
  // only the client the call went to may answer it
  if (it == pending_calls_.end() || it->second.provider.lock() != c)
    throw Error("service_response: no pending call '" + j["id"].get<std::string>() +
                "' to this client");
  // the caller gets the answer under its own id
  Json r = j;
  if (it->second.id.is_null())
    r.erase("id");
  else
    r["id"] = it->second.id;
  if (ClientPtr caller = it->second.caller.lock()) Reply(caller, r);
  pending_calls_.erase(it);
}

void RosbridgeProtocol::OpNotSupported(const ClientPtr&, const Json& j, const Json&) {
  throw Error("op '" + j["op"].get<std::string>() + "' is not supported by " + options_.label +
              " (it answers auth, subscribe, unsubscribe and call_service)");
}

void RosbridgeProtocol::OpAuth(const ClientPtr& c, const Json&, const Json& id) {
  // already authenticated, or no token is set
  Status(c, "info", options_.auth_token.empty() ? "no token needed" : "authenticated", id);
}

// ---- services ----

void RosbridgeProtocol::AddRosapiServices() {
  services_ = {
      {"/rosapi/topics",
       [this](const ClientPtr&, const std::string&, const Json&,
              const Json&) -> std::optional<Json> {
         std::lock_guard<std::mutex> lock(clients_mutex_);
         return TopicsToJson(AllTopics());
       }},
      {"/rosapi/topic_type",
       [this](const ClientPtr&, const std::string&, const Json& args,
              const Json&) -> std::optional<Json> {
         if (!args.is_object() || !args.contains("topic") || !args["topic"].is_string())
           throw Error("/rosapi/topic_type needs args {topic: string}");
         std::lock_guard<std::mutex> lock(clients_mutex_);
         const auto all = AllTopics();
         auto it = all.find(args["topic"].get<std::string>());
         return Json{{"type", it == all.end() ? "" : it->second}};
       }},
      {"/rosapi/services",
       [this](const ClientPtr&, const std::string&, const Json&,
              const Json&) -> std::optional<Json> {
         Json names = Json::array();
         for (const auto& [name, handler] : services_) names.push_back(name);
         std::lock_guard<std::mutex> lock(clients_mutex_);
         for (auto& [h, cl] : clients_)
           for (const std::string& s : cl->services) names.push_back(s);
         return Json{{"services", names}};
       }},
  };
}

const RosbridgeProtocol::ServiceHandler* RosbridgeProtocol::FindService(
    const std::string& name) const {
  for (const auto& [n, handler] : services_)
    if (n == name) return &handler;
  return nullptr;
}

// ---- calls to client-advertised services ----

void RosbridgeProtocol::AbandonCalls(const ClientPtr& provider, const std::string& service,
                                     const std::string& why) {
  for (auto it = pending_calls_.begin(); it != pending_calls_.end();) {
    const PendingCall& call = it->second;
    if (call.provider.lock() == provider && (service.empty() || call.service == service)) {
      FailCall(call, why);
      it = pending_calls_.erase(it);
    } else {
      ++it;
    }
  }
}

void RosbridgeProtocol::FailCall(const PendingCall& call, const std::string& why) {
  if (ClientPtr caller = call.caller.lock())
    Reply(caller, ServiceResponseToJson(call.service, why, false, call.id));
}

void RosbridgeProtocol::ExpireCalls() {
  // calls whose caller left are dropped; calls unanswered for kCallTimeout fail
  const WallClock::time_point now = WallClock::now();
  for (auto it = pending_calls_.begin(); it != pending_calls_.end();) {
    const PendingCall& call = it->second;
    if (call.caller.expired()) {
      it = pending_calls_.erase(it);
    } else if (now - call.since > kCallTimeout) {
      FailCall(call, "the provider of " + call.service + " did not answer in " +
                         std::to_string(kCallTimeout.count()) + " s");
      it = pending_calls_.erase(it);
    } else {
      ++it;
    }
  }
}

// ---- topics ----

std::string RosbridgeProtocol::TopicList() const {
  std::string list;
  for (const auto& [name, topic] : topics_)
    if (!topic.command) list += (list.empty() ? "" : ", ") + name;
  return list.empty() ? "no topics" : list;
}

std::map<std::string, std::string> RosbridgeProtocol::AllTopics() const {
  std::map<std::string, std::string> t;
  for (const auto& [name, topic] : topics_) t.emplace(name, topic.type);
  for (auto& [h, c] : clients_)
    for (auto& [topic, type] : c->advertised) t.emplace(topic, type);
  return t;
}

bool RosbridgeProtocol::Wanted(const std::string& topic) const {
  std::lock_guard<std::mutex> lock(clients_mutex_);
  return WantedLocked(topic);
}

std::vector<ClientPtr> RosbridgeProtocol::Subscribers(const std::string& topic) const {
  std::vector<ClientPtr> out;
  std::lock_guard<std::mutex> lock(clients_mutex_);
  for (auto& [h, c] : clients_)
    if (c->subs.count(topic)) out.push_back(c);
  return out;
}

bool RosbridgeProtocol::Subscribes(const ClientPtr& client, const std::string& topic) const {
  std::lock_guard<std::mutex> lock(clients_mutex_);
  return client->subs.count(topic) > 0;
}

bool RosbridgeProtocol::WantedLocked(const std::string& topic) const {
  for (auto& [h, c] : clients_)
    if (c->subs.count(topic)) return true;
  return false;
}

// ---- publishing ----

void RosbridgeProtocol::Publish(const std::string& topic, const std::function<Json()>& make,
                                WallClock::time_point now) {
  Json msg;
  std::shared_ptr<const std::string> text, cbor;
  std::lock_guard<std::mutex> lock(clients_mutex_);
  for (auto& [h, c] : clients_) {
    auto it = c->subs.find(topic);
    if (it == c->subs.end()) continue;
    Subscription& s = it->second;
    if (s.throttle_ms > 0 &&
        std::chrono::duration<double, std::milli>(now - s.last_sent).count() < s.throttle_ms)
      continue;
    if (msg.is_null()) msg = PublishToJson(topic, make());
    s.last_sent = now;
    // encoded once; each client gets a pointer (this is the simulation thread)
    if (s.cbor) {
      if (!cbor) {
        std::vector<uint8_t> bytes = Json::to_cbor(msg);
        cbor = std::make_shared<const std::string>(bytes.begin(), bytes.end());
      }
      transport_->Send(c, cbor, s.queue_length, true, topic, 0);
      continue;
    }
    if (!text) text = std::make_shared<const std::string>(DumpJson(TextForm(msg)));
    const size_t fragment = text->size() > s.fragment_size ? s.fragment_size : 0;
    transport_->Send(c, text, s.queue_length, false, topic, fragment);
  }
}

}  // namespace partsim::internal
