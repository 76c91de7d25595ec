#include "partsim/viewer/viewer.h"

#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/physics/scene.h"
#include "viewer/viewer_impl.h"

// The viewer's public face: construction, served and synchronous modes, starting and stopping
// its RosbridgeServer, the initial camera, and what extensions add. Its parts: viewer_topics.cc,
// viewer_services.cc, viewer_routes.cc, scene_content.cc (what is sent of a scene).

namespace partsim {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

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

RosbridgeOptions Viewer::Impl::ServerOptions() const {
  RosbridgeOptions o;
  o.label = "viewer";
  o.address = options.address;
  o.port = options.port;
  o.allowed_origins = options.allowed_origins;
  o.auth_token = token;
  o.auth_timeout = options.auth_timeout;
  o.max_clients = options.max_clients;
  o.max_message_bytes = options.max_message_bytes;
  o.max_client_buffered = options.max_client_buffered;
  // the page subscribes to the viewer's topics and calls its services; it relays nothing
  o.client_topics = false;
  o.max_subscriptions = 16;
  return o;
}

void Viewer::Impl::Serve() {
  AddTopics();
  AddServices();
  server->SetHttpHandler([this](const RosbridgeHttpRequest& request, RosbridgeHttpRespond respond) {
    return HandleHttp(request, std::move(respond));
  });
}

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
  m.token = options.auth_token.empty() ? RandomAuthToken() : options.auth_token;
  m.web_root = FindWebRoot(options.web_root);
  m.server = std::make_unique<RosbridgeServer>(m.ServerOptions());
}

// ================= the scene's thread =================

bool Viewer::Impl::RunCommands() {
  std::deque<std::function<void()>> pending;
  {
    std::lock_guard<std::mutex> lock(mutex);
    pending.swap(commands);
  }
  for (auto& c : pending) c();
  if (!pending.empty()) Snapshot(true);
  return !pending.empty();
}

Viewer::~Viewer() { Stop(); }

void Viewer::Attach(SimServer* sim) {
  Impl& m = *impl_;
  if (!sim) throw Error("Viewer::Attach: sim is null");
  if (m.started || m.sim) throw Error("Viewer::Attach: attach before Start(), once");
  if (!m.scene) throw Error("Viewer::Attach: the viewer has no scene");
  m.sim = sim;
  sim->AddStepCallback([this](long long steps) {
    impl_->UpdateControllers(steps);
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
  m.Serve();
  m.server->Start();
  m.port = m.server->GetPort();
  m.started = true;
  if (m.scene) {
    m.RebuildContent();
    m.Snapshot(true);
  }
}

void Viewer::Stop() {
  Impl& m = *impl_;
  if (!m.started) return;
  m.started = false;
  m.closed = true;
  m.server->Stop();
  m.cv.notify_all();
}

bool Viewer::Render(double max_wait) {
  Impl& m = *impl_;
  if (!m.started) throw Error("Viewer::Render: the viewer is not started");
  if (m.sim)
    throw Error("Viewer::Render: the viewer is attached to a SimServer, whose thread does this");
  m.RunCommands();
  m.UpdateControllers(-1);
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
  const RosbridgeStats net = m.server->GetStats();
  ViewerStats s;
  s.clients = net.authenticated_clients;
  s.messages_sent = net.messages_sent;
  s.messages_dropped = net.messages_dropped;
  s.http_requests = m.http_requests;
  s.errors = net.errors;
  s.snapshots = m.snapshots;
  s.accept_errors = net.accept_errors;
  std::lock_guard<std::mutex> lock(m.mutex);
  s.scene_version = m.shared_content ? m.shared_content->version : 0;
  return s;
}

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

void Viewer::SetJointCommand(ViewerJointCommand command) {
  Impl& m = *impl_;
  if (m.started) throw Error("Viewer::SetJointCommand: set it before Start()");
  m.joint_command = std::move(command);
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
