#include "partsim/server/rosbridge.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "core/json_parse.h"
#include "partsim/core/error.h"
#include "server/rosbridge_protocol.h"
#include "server/rosbridge_robot.h"
#include "server/web_security.h"

// The transport of RosbridgeServer: websocketpp over Boost.Asio on a thread of its own, the
// accept loop, the handshake checks (origin, connection cap), the login's time limit, each
// client's bounded outgoing queue, the fragmenting of long messages, and plain HTTP requests
// handed to an extension. What the messages mean is the protocol's (rosbridge_protocol.cc); what
// a robot serves is rosbridge_robot.cc's; how ROS messages look in JSON is the codecs'
// (ros_json.cc).

namespace partsim {

namespace {

using internal::ClientPtr;
using internal::Json;
using internal::OriginAllowed;
using internal::Outgoing;
using WsServer = websocketpp::server<websocketpp::config::asio>;
using Hdl = websocketpp::connection_hdl;

}  // namespace

struct RosbridgeServer::Impl : internal::RosbridgeTransport {
  ServedRobot* robot = nullptr;  ///< null: a server of extensions only
  RosbridgeOptions options;
  std::unique_ptr<internal::RosbridgeProtocol> protocol;
  std::unique_ptr<internal::RosbridgeRobot> robot_part;
  RosbridgeHttpHandler http_handler;  ///< set before Start
  struct Periodic {
    double seconds;
    std::function<void()> fn;
    std::unique_ptr<boost::asio::steady_timer> timer;  ///< network thread
  };
  std::vector<std::unique_ptr<Periodic>> periodic;  ///< set before Start

  WsServer ws;
  std::unique_ptr<boost::asio::steady_timer> accept_timer;  // network thread
  std::atomic<long long> accept_errors{0};
  std::thread io_thread;
  int port = 0;
  std::atomic<bool> started{false};
  std::atomic<long long> next_fragment{0};
  std::atomic<long long> sent{0}, dropped{0}, refused{0}, peak_buffered{0};
  /// Connections whose handshake was accepted and that have not gone (network thread): the
  /// slots max_clients counts. Handshakes accepted at once would all see the clients opened
  /// before them, not each other.
  std::set<std::weak_ptr<void>, std::owner_less<std::weak_ptr<void>>> slots;

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
  /// Queues a message for a client (any thread); see RosbridgeTransport::Send for the bounds.
  /// A busy subscription never evicts a service response.
  void Send(const ClientPtr& c, std::shared_ptr<const std::string> msg, size_t bound, bool binary,
            const std::string& topic, size_t fragment_size) override {
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
      std::weak_ptr<internal::RosbridgeClient> weak = c;
      boost::asio::post(ws.get_io_service(), [this, weak] {
        if (ClientPtr cp = weak.lock()) Flush(cp);
      });
    }
  }

  /// Network thread: what waits in the client's queue, then `text` at once (see SendNow).
  bool SendNow(const ClientPtr& c, const std::string& text, bool droppable) {
    Flush(c);
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = ws.get_con_from_hdl(c->connection, ec);
    if (ec || !con || con->get_state() != websocketpp::session::state::open) return false;
    if (droppable && con->get_buffered_amount() > options.max_client_buffered) {
      ++dropped;
      return false;
    }
    if (con->send(text, websocketpp::frame::opcode::text)) return false;
    ++sent;
    return true;
  }

  void Close(const ClientPtr& c, const std::string& reason) override {
    websocketpp::lib::error_code ec;
    ws.close(c->connection, websocketpp::close::status::policy_violation, reason, ec);
  }

  /// Network thread: hands queued messages to the socket unless its queue is full. A message
  /// goes whole (all its fragments) or not at all: a client cannot use part of one. The queue
  /// thus holds at most max_client_buffered plus one message, whose fragments add their framing
  /// (about 100 bytes each, fragments being at least kMinFragmentSize characters) and the
  /// escaping of the quotes in their data.
  void Flush(const ClientPtr& c) {
    std::deque<Outgoing> pending;
    {
      std::lock_guard<std::mutex> lock(c->out_mutex);
      pending.swap(c->out);
      c->flush_scheduled = false;
    }
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = ws.get_con_from_hdl(c->connection, ec);
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
    const long long buffered = static_cast<long long>(con->get_buffered_amount());
    long long peak = peak_buffered;
    while (buffered > peak && !peak_buffered.compare_exchange_weak(peak, buffered)) {
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
          con->send(internal::DumpJson(Json{{"op", "fragment"},
                                            {"id", id},
                                            {"data", text.substr(i * fragment_size, fragment_size)},
                                            {"num", i},
                                            {"total", n}}),
                    websocketpp::frame::opcode::text);
      if (ec) return false;
    }
    return true;
  }

  // ---- timers ----
  void Tick(Periodic* p) {
    p->timer->expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(p->seconds)));
    p->timer->async_wait([this, p](const boost::system::error_code& e) {
      if (e || !started) return;
      p->fn();
      Tick(p);
    });
  }

  // ---- plain HTTP ----
  static void FillHttp(const WsServer::connection_ptr& con, const RosbridgeHttpAnswer& a) {
    con->set_status(static_cast<websocketpp::http::status_code::value>(a.status));
    con->append_header("Content-Type", a.content_type);
    con->append_header("Cache-Control", "no-store");
    con->append_header("X-Content-Type-Options", "nosniff");
    con->set_body(a.body);
  }

  /// Network thread: a request from an origin not allowed gets 403; others go to the
  /// extension's handler, whose answer (or 503 after the time it asked for) is sent later.
  void HandleHttp(const WsServer::connection_ptr& con) {
    // (a plain HTTP request has no WebSocket processor: get_origin() is not for it)
    const std::string origin = con->get_request_header("Origin");
    if (!internal::OriginAllowed(origin, options.allowed_origins)) {
      ++refused;
      FillHttp(con, {403, "text/plain; charset=utf-8", "origin '" + origin + "' is not allowed\n"});
      return;
    }
    if (!http_handler) {
      FillHttp(con, {426, "text/plain; charset=utf-8",
                     "this port answers WebSocket handshakes (rosbridge v2) only\n"});
      return;
    }
    RosbridgeHttpRequest req;
    req.method = con->get_request().get_method();
    internal::SplitResource(con->get_resource(), &req.path, &req.query);
    std::string given = internal::QueryValue(req.query, "token");
    if (given.empty()) given = con->get_request_header("X-Partsim-Token");
    req.token_ok = internal::SameToken(given, options.auth_token);
    websocketpp::lib::error_code ec = con->defer_http_response();
    if (ec) {
      FillHttp(con, {500, "text/plain; charset=utf-8", "cannot defer the answer\n"});
      return;
    }
    auto once = std::make_shared<std::atomic<bool>>(false);
    auto timer = std::make_shared<boost::asio::steady_timer>(ws.get_io_service());
    RosbridgeHttpRespond respond = [this, con, once, timer](RosbridgeHttpAnswer a) {
      if (once->exchange(true) || !started) return;
      boost::asio::post(ws.get_io_service(), [con, timer, a = std::move(a)] {
        timer->cancel();
        FillHttp(con, a);
        websocketpp::lib::error_code unused;
        con->send_http_response(unused);
      });
    };
    double timeout = 30;
    try {
      timeout = http_handler(req, respond);
    } catch (const std::exception& e) {
      respond({500, "text/plain; charset=utf-8", std::string("error: ") + e.what() + "\n"});
    }
    if (!(timeout > 0) || !std::isfinite(timeout)) timeout = 30;
    timer->expires_after(
        std::chrono::milliseconds(static_cast<long long>(std::min(timeout, 1e6) * 1000)));
    timer->async_wait([respond, timeout](const boost::system::error_code& e) {
      if (e) return;
      char why[100];
      std::snprintf(why, sizeof(why), "no answer within %g s; try again\n", timeout);
      respond({503, "text/plain; charset=utf-8", why});
    });
  }

  RosbridgeStats Stats() const {
    RosbridgeStats s;
    s.clients = static_cast<long long>(protocol->ClientCount());
    s.authenticated_clients = static_cast<long long>(protocol->AuthenticatedCount());
    s.messages_sent = sent;
    s.messages_dropped = dropped;
    if (robot) {
      CommandStats cs = robot->GetCommandStats();
      s.commands = cs.commands;
      s.mean_latency_steps = cs.mean_latency_steps;
      s.max_latency_steps = cs.max_latency_steps;
    }
    s.errors = protocol->Errors();
    s.refused = refused;
    s.accept_errors = accept_errors;
    s.peak_buffered_bytes = peak_buffered;
    return s;
  }
};

RosbridgeServer::RosbridgeServer(ServedRobot* robot, const RosbridgeOptions& options)
    : RosbridgeServer(options) {
  if (!robot) throw Error("RosbridgeServer: robot is null");
  Impl& m = *impl_;
  m.robot = robot;
  m.robot_part = std::make_unique<internal::RosbridgeRobot>(robot, m.protocol.get(),
                                                            [this] { return impl_->Stats(); });
  robot->GetSim()->AddStepCallback([this](long long steps) {
    if (impl_->started) impl_->robot_part->OnStep(steps);
  });
}

RosbridgeServer::RosbridgeServer(const RosbridgeOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (!(options.auth_timeout >= 0) || !std::isfinite(options.auth_timeout))
    throw Error(options.label + ": auth_timeout must be finite and >= 0 (0: no limit)");
  Impl& m = *impl_;
  m.options = options;
  m.protocol = std::make_unique<internal::RosbridgeProtocol>(options, &m);
  m.ws.clear_access_channels(websocketpp::log::alevel::all);
  m.ws.clear_error_channels(websocketpp::log::elevel::all);
  m.ws.init_asio();
  m.ws.set_reuse_addr(true);
  m.ws.set_max_message_size(options.max_message_bytes);
  m.ws.set_max_http_body_size(64 * 1024);
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
    // a slot is taken here and given back when the connection goes (close or fail)
    if (im.slots.size() >= im.options.max_clients) {
      ++im.refused;
      con->set_status(websocketpp::http::status_code::service_unavailable);
      return false;
    }
    im.slots.insert(h);
    return true;
  });
  // with log_clients, a line per client that comes or goes: its address and the count after
  auto log_client = [this](const internal::RosbridgeClient& c, const char* what, size_t count) {
    if (!impl_->options.log_clients) return;
    std::fprintf(stderr, "partsim serve: client %s %s (%zu client%s connected)\n",
                 c.address.c_str(), what, count, count == 1 ? "" : "s");
  };
  m.ws.set_open_handler([this, log_client](Hdl h) {
    auto c = std::make_shared<internal::RosbridgeClient>();
    c->connection = h;
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = impl_->ws.get_con_from_hdl(h, ec);
    c->address = !ec && con ? con->get_remote_endpoint() : "(unknown address)";
    log_client(*c, "connected", impl_->protocol->AddClient(c));
    // with a token, a client that stays silent would hold its slot for ever: it has
    // auth_timeout seconds to authenticate; it is told why it is closed
    const double limit = impl_->options.auth_timeout;
    if (impl_->options.auth_token.empty() || limit <= 0) return;
    std::weak_ptr<internal::RosbridgeClient> weak = c;
    impl_->ws.set_timer(
        static_cast<long>(std::min(limit, 1e6) * 1000),
        [this, weak, limit](const websocketpp::lib::error_code& e) {
          ClientPtr cp = weak.lock();
          if (e || !cp || cp->authenticated) return;
          char why[160];
          std::snprintf(why, sizeof(why),
                        "auth: no {\"op\": \"auth\"} with the token within %g s; closing the "
                        "connection",
                        limit);
          impl_->SendNow(cp, internal::DumpJson(internal::StatusToJson("error", why, nullptr)),
                         false);
          impl_->protocol->CountError();
          std::snprintf(why, sizeof(why), "not authenticated within %g s", limit);
          impl_->Close(cp, why);
        });
  });
  auto gone = [this, log_client](Hdl h) {
    impl_->slots.erase(h);
    size_t count = 0;
    if (ClientPtr c = impl_->protocol->RemoveClient(h, &count))
      log_client(*c, "disconnected", count);
  };
  m.ws.set_close_handler(gone);
  m.ws.set_fail_handler(gone);
  m.ws.set_message_handler([this](Hdl h, WsServer::message_ptr msg) {
    if (ClientPtr c = impl_->protocol->FindClient(h))
      impl_->protocol->OnMessage(c, msg->get_payload());
  });
  m.ws.set_http_handler([this](Hdl h) {
    websocketpp::lib::error_code ec;
    WsServer::connection_ptr con = impl_->ws.get_con_from_hdl(h, ec);
    if (!ec && con) impl_->HandleHttp(con);
  });
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
      throw Error(m.options.label + ": cannot resolve the address '" + m.options.address +
                  "': " + (bec ? bec.message() : "no address"));
    addr = found.begin()->endpoint().address();
  }
  if (!addr.is_loopback())
    std::fprintf(stderr,
                 "partsim: warning: %s listens on %s (%s), reachable from other machines: anyone "
                 "who can connect%s can move what it serves and stop the simulation%s\n",
                 m.options.label.c_str(), m.options.address.c_str(), addr.to_string().c_str(),
                 m.options.auth_token.empty() ? "" : " and knows the token",
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
    throw Error(m.options.label + ": cannot listen on " + m.options.address + ":" +
                std::to_string(m.options.port) + ": " + why);
  }
  m.accept_timer = std::make_unique<boost::asio::steady_timer>(m.ws.get_io_service());
  m.StartAccept();
  m.port = m.ws.get_local_endpoint(bec).port();
  for (auto& p : m.periodic) {
    p->timer = std::make_unique<boost::asio::steady_timer>(m.ws.get_io_service());
    m.Tick(p.get());
  }
  m.started = true;
  m.io_thread = std::thread([this] {
    // a handler that throws must not end the network thread
    while (true) {
      try {
        impl_->ws.run();
        return;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "partsim %s: network thread: %s (it goes on)\n",
                     impl_->options.label.c_str(), e.what());
      }
    }
  });
}

void RosbridgeServer::Stop() {
  Impl& m = *impl_;
  if (!m.started) return;
  m.started = false;
  websocketpp::lib::error_code ec;
  m.ws.stop_listening(ec);
  if (m.accept_timer) m.accept_timer->cancel();
  for (auto& p : m.periodic)
    if (p->timer) p->timer->cancel();
  m.ws.stop();
  if (m.io_thread.joinable()) m.io_thread.join();
}

int RosbridgeServer::GetPort() const { return impl_->port; }

RosbridgeStats RosbridgeServer::GetStats() const { return impl_->Stats(); }

// ---- extensions ----

namespace {

void CheckNotStarted(const RosbridgeServer::Impl& m, const char* what);

}  // namespace

void RosbridgeServer::AddTopic(const std::string& name, const std::string& type,
                               RosbridgeTopicHooks hooks) {
  CheckNotStarted(*impl_, "AddTopic");
  impl_->protocol->AddTopic(name, type, {}, std::move(hooks));
}

void RosbridgeServer::AddService(const std::string& name, RosbridgeService service) {
  CheckNotStarted(*impl_, "AddService");
  if (!service) throw Error(impl_->options.label + ": service " + name + " has no handler");
  impl_->protocol->AddExtensionService(name, std::move(service));
}

void RosbridgeServer::SetSimControls(const RosbridgeSimControls& controls) {
  CheckNotStarted(*impl_, "SetSimControls");
  impl_->protocol->SetSimControls(controls);
}

void RosbridgeServer::SetHttpHandler(RosbridgeHttpHandler handler) {
  CheckNotStarted(*impl_, "SetHttpHandler");
  impl_->http_handler = std::move(handler);
}

void RosbridgeServer::OnDisconnect(std::function<void(const RosbridgeClientPtr& client)> hook) {
  CheckNotStarted(*impl_, "OnDisconnect");
  impl_->protocol->AddDisconnectHook(std::move(hook));
}

void RosbridgeServer::Every(double seconds, std::function<void()> fn) {
  CheckNotStarted(*impl_, "Every");
  if (!(seconds > 0) || !std::isfinite(seconds))
    throw Error(impl_->options.label + ": Every needs a finite period > 0 s");
  impl_->periodic.push_back(
      std::make_unique<Impl::Periodic>(Impl::Periodic{seconds, std::move(fn), nullptr}));
}

void RosbridgeServer::Post(std::function<void()> fn) {
  if (!impl_->started) return;
  boost::asio::post(impl_->ws.get_io_service(), std::move(fn));
}

bool RosbridgeServer::SendNow(const RosbridgeClientPtr& client, const std::string& text,
                              bool droppable) {
  return client && impl_->SendNow(client, text, droppable);
}

void RosbridgeServer::Publish(const std::string& topic, const std::string& msg_json) {
  const Json msg = internal::ParseJsonBounded(msg_json);
  impl_->protocol->Publish(
      topic, [&] { return msg; }, internal::WallClock::now());
}

std::vector<RosbridgeClientPtr> RosbridgeServer::Subscribers(const std::string& topic) const {
  return impl_->protocol->Subscribers(topic);
}

bool RosbridgeServer::Subscribes(const RosbridgeClientPtr& client, const std::string& topic) const {
  return client && impl_->protocol->Subscribes(client, topic);
}

void RosbridgeServer::SendError(const RosbridgeClientPtr& client, const std::string& message) {
  if (client) impl_->protocol->SendError(client, message);
}

std::string RandomAuthToken() { return internal::RandomToken(); }

namespace {

void CheckNotStarted(const RosbridgeServer::Impl& m, const char* what) {
  if (m.started) throw Error(m.options.label + ": " + what + " must be called before Start()");
}

}  // namespace

}  // namespace partsim
