// A WebSocket client for the server tests (rosbridge, viewer): websocketpp's client connected to
// a loopback port, running on a thread of its own.
#pragma once

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
  /// Waits (up to 10 s) for a message satisfying `pred`; returns it, or null.
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

}  // namespace partsim::testing
