// A WebSocket client for the server tests (rosbridge, viewer): websocketpp's client connected to
// a loopback port, running on a thread of its own.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <utility>
#include <vector>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include "server/wait_for.h"

namespace partsim::testing {

class WsTestClient {
 public:
  using Client = websocketpp::client<websocketpp::config::asio_client>;
  /// Called on the client's thread with each message received.
  using Handler = std::function<void(const Client::message_ptr&)>;

  /// Connects to ws://127.0.0.1:`port``path`; `origin`: the Origin header a browser would send
  /// ("" sends none).
  WsTestClient(int port, const std::string& origin, Handler on_message,
               const std::string& path = "")
      : on_message_(std::move(on_message)) {
    c_.clear_access_channels(websocketpp::log::alevel::all);
    c_.clear_error_channels(websocketpp::log::elevel::all);
    c_.init_asio();
    c_.set_open_handler([this](websocketpp::connection_hdl) { open_ = true; });
    c_.set_close_handler([this](websocketpp::connection_hdl h) {
      close_code_ = c_.get_con_from_hdl(h)->get_remote_close_code();
      closed_ = true;
    });
    c_.set_fail_handler([this](websocketpp::connection_hdl) { closed_ = true; });
    c_.set_message_handler(
        [this](websocketpp::connection_hdl, Client::message_ptr m) { on_message_(m); });
    websocketpp::lib::error_code ec;
    con_ = c_.get_connection("ws://127.0.0.1:" + std::to_string(port) + path, ec);
    if (!origin.empty()) con_->replace_header("Origin", origin);
    c_.connect(con_);
    thread_ = std::thread([this] { c_.run(); });
  }
  ~WsTestClient() {
    websocketpp::lib::error_code ec;
    if (open_ && !closed_) c_.close(con_->get_handle(), websocketpp::close::status::normal, "", ec);
    WaitFor([this] { return closed_.load(); });
    c_.stop();
    thread_.join();
  }
  WsTestClient(const WsTestClient&) = delete;
  WsTestClient& operator=(const WsTestClient&) = delete;

  /// Waits until the connection is open (true) or has failed or closed (false).
  bool WaitOpen() {
    return WaitFor([this] { return open_.load() || closed_.load(); }) && open_;
  }
  void Send(const std::string& bytes,
            websocketpp::frame::opcode::value opcode = websocketpp::frame::opcode::text) {
    websocketpp::lib::error_code ec;
    c_.send(con_->get_handle(), bytes, opcode, ec);
  }
  /// Closes the connection and waits until it is closed.
  void Close() {
    websocketpp::lib::error_code ec;
    c_.close(con_->get_handle(), websocketpp::close::status::normal, "", ec);
    WaitFor([this] { return closed_.load(); });
  }
  bool Closed() const { return closed_; }
  int CloseCode() const { return close_code_; }

 private:
  Handler on_message_;
  Client c_;
  Client::connection_ptr con_;
  std::thread thread_;
  std::atomic<bool> open_{false}, closed_{false};
  std::atomic<int> close_code_{0};
};

/// A raw TCP connection to a loopback port that performs the WebSocket handshake (to `path`) and
/// then writes frames by hand and reads nothing: what a hostile or stuck client does.
class RawSocket {
 public:
  explicit RawSocket(int port, const std::string& path = "/") {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ok_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0;
    int small = 4096;  // a small receive buffer so that the server's writes back up
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &small, sizeof(small));
    Write(Handshake(path));
    // read the handshake response only
    std::string resp;
    char ch;
    while (resp.find("\r\n\r\n") == std::string::npos && ::read(fd_, &ch, 1) == 1) resp += ch;
    ok_ = ok_ && resp.find(" 101 ") != std::string::npos;
  }
  ~RawSocket() { Close(); }
  /// The HTTP request that opens a WebSocket at `path`.
  static std::string Handshake(const std::string& path = "/") {
    return "GET " + path +
           " HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
           "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  }
  bool Ok() const { return ok_; }
  void Write(const std::string& bytes) {
    size_t off = 0;
    while (off < bytes.size()) {
      ssize_t n = ::send(fd_, bytes.data() + off, bytes.size() - off, MSG_NOSIGNAL);
      if (n <= 0) return;
      off += static_cast<size_t>(n);
    }
  }
  /// Header of a masked text frame (mask 0, so the payload goes as it is) of `len` bytes.
  static std::string FrameHeader(size_t len) {
    std::string h;
    h += static_cast<char>(0x81);
    if (len < 126) {
      h += static_cast<char>(0x80 | len);
    } else {
      h += static_cast<char>(0x80 | 126);
      h += static_cast<char>((len >> 8) & 0xff);
      h += static_cast<char>(len & 0xff);
    }
    h += std::string(4, '\0');
    return h;
  }
  void SendText(const std::string& text) { Write(FrameHeader(text.size()) + text); }
  void Close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
  bool ok_ = false;
};

/// The JSON messages a test client kept, shared between its thread and the test's.
class MessageLog {
 public:
  using json = nlohmann::json;
  void Add(json message) {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.push_back(std::move(message));
  }
  std::vector<json> All() {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }
  void Clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.clear();
  }
  /// Waits (up to 30 s, WaitFor) for a message satisfying `pred`; returns it, or null.
  template <class F>
  json Wait(F pred) {
    json found;
    WaitFor([&] {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const json& m : messages_)
        if (pred(m)) {
          found = m;
          return true;
        }
      return false;
    });
    return found;
  }

 private:
  std::mutex mutex_;
  std::vector<json> messages_;
};

/// A WebSocket client of ws://127.0.0.1:`port`/ that keeps every JSON message it receives.
class LoggedWsClient {
 public:
  using json = nlohmann::json;
  explicit LoggedWsClient(int port)
      : ws_(
            port, "",
            [this](const WsTestClient::Client::message_ptr& m) {
              log_.Add(json::parse(m->get_payload(), nullptr, false));
            },
            "/") {}
  bool WaitOpen() { return ws_.WaitOpen(); }
  void Send(const json& j) { ws_.Send(j.dump()); }
  std::vector<json> Messages() { return log_.All(); }
  /// Waits (up to 30 s) for a message satisfying `pred`; returns it, or null.
  template <class F>
  json Wait(F pred) {
    return log_.Wait(pred);
  }
  /// The first message with id `id` (up to 30 s), or null.
  json Reply(const std::string& id) {
    return Wait([&](const json& m) { return m.value("id", "") == id; });
  }

 private:
  MessageLog log_;
  WsTestClient ws_;  // last: its thread stops before the log goes
};

}  // namespace partsim::testing
