// Bindings of the viewer subsystem: partsim.Viewer, the browser viewer of a scene, and
// Scene.create_viewer (SAPIEN's name). The viewer's server starts at construction and prints
// its URL on stderr; render() runs without the GIL and, while the page keeps the scene paused,
// checks for Ctrl-C every 100 ms (KeyboardInterrupt closes the viewer). render() is paced to
// real time unless set_realtime(False), as SAPIEN's window paces a loop to the display.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bindings.h"
#include "partsim/physics/scene.h"
#include "partsim/viewer/viewer.h"

namespace partsim::python {
namespace {

using Clock = std::chrono::steady_clock;

/// partsim.Viewer: the viewer and the real-time pacing of its render() calls.
struct PacedViewer : Viewer {
  using Viewer::Viewer;
  /// Whether render() keeps the scene's time from running ahead of the wall clock.
  bool realtime = true;
  /// The scene, its time (s) and the wall-clock instant render() paces from; null scene: none
  /// yet (the next render() starts pacing).
  const Scene* anchor_scene = nullptr;
  double anchor_time = 0.0;
  Clock::time_point anchor_wall;
};

/// A loop that falls behind real time by more than this (s) is paced from where it stands
/// instead of running fast to catch up (a pause, a slow step, a wait for the page).
constexpr double kMaxLag = 0.1;

/// Sleeps `seconds` without the GIL in slices of 100 ms, raising KeyboardInterrupt on Ctrl-C
/// (which closes the viewer); returns early when the viewer is closed.
void Sleep(Viewer& v, double seconds) {
  const Clock::time_point end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(seconds));
  while (!v.IsClosed()) {
    const Clock::time_point now = Clock::now();
    if (now >= end) return;
    {
      py::gil_scoped_release release;
      std::this_thread::sleep_for(
          std::min<Clock::duration>(end - now, std::chrono::milliseconds(100)));
    }
    if (PyErr_CheckSignals() != 0) {
      v.Close();
      throw py::error_already_set();
    }
  }
}

/// Waits until the scene's time since the anchor is no longer ahead of the wall clock's.
void Pace(PacedViewer& v) {
  const Scene* scene = v.GetScene();
  if (!v.realtime || !scene || v.IsClosed()) {
    v.anchor_scene = nullptr;
    return;
  }
  const double time = scene->GetTime();
  const Clock::time_point now = Clock::now();
  // a new scene, or its time went back (a reset): pace from here
  if (scene != v.anchor_scene || time < v.anchor_time) {
    v.anchor_scene = scene;
    v.anchor_time = time;
    v.anchor_wall = now;
    return;
  }
  const double ahead =
      (time - v.anchor_time) - std::chrono::duration<double>(now - v.anchor_wall).count();
  if (ahead > 0) {
    Sleep(v, ahead);
  } else if (ahead < -kMaxLag) {
    v.anchor_time = time;
    v.anchor_wall = now;
  }
}

std::unique_ptr<PacedViewer> MakeViewer(Scene* scene, int port, const std::string& address,
                                        const std::optional<std::string>& token,
                                        const std::vector<std::string>& allowed_origins,
                                        const std::string& web_root, double max_rate,
                                        bool realtime) {
  ViewerOptions o;
  o.port = port;
  o.address = address;
  o.auth_token = token.value_or("");
  o.allowed_origins = allowed_origins;
  o.web_root = web_root;
  o.max_rate = max_rate;
  auto viewer = std::make_unique<PacedViewer>(scene, o);
  viewer->realtime = realtime;
  if (scene) {
    Scene::Use use(*scene);
    viewer->Start();
  } else {
    viewer->Start();
  }
  std::fprintf(
      stderr, "partsim viewer: open %s%s\n", viewer->GetUrl().c_str(),
      viewer->GetWebRoot().empty() ? " (web page not built: bash scripts/build_web.sh)" : "");
  return viewer;
}

void Render(PacedViewer& v) {
  Pace(v);
  // in slices of 100 ms while paused, so that Ctrl-C reaches Python
  while (true) {
    bool done;
    if (Scene* scene = v.GetScene())
      done = WithoutGil(*scene, [&v] { return v.Render(0.1); });
    else {
      py::gil_scoped_release release;
      done = v.Render(0.1);
    }
    if (done) return;
    if (PyErr_CheckSignals() != 0) {
      v.Close();
      throw py::error_already_set();
    }
  }
}

/// Waits until a WebSocket client is connected or `timeout` seconds (None: no limit) pass.
bool WaitForClient(PacedViewer& v, std::optional<double> timeout) {
  const Clock::time_point start = Clock::now();
  while (v.GetStats().clients == 0) {
    const double waited = std::chrono::duration<double>(Clock::now() - start).count();
    if (v.IsClosed() || (timeout && waited >= *timeout)) return false;
    Sleep(v, timeout ? std::min(0.05, *timeout - waited) : 0.05);
  }
  return true;
}

}  // namespace

void BindViewer(py::module_& m) {
  py::class_<PacedViewer>(
      m, "Viewer",
      "The scene in a web browser (docs/viewer.md): a server on one port for the "
      "page, the scene's meshes and a rosbridge WebSocket. SAPIEN's loop runs "
      "unchanged: while not viewer.closed: scene.step(); scene.update_render(); "
      "viewer.render().")
      .def(py::init(&MakeViewer), py::arg("scene") = nullptr, py::arg("port") = 0,
           py::arg("address") = "127.0.0.1", py::arg("token") = py::none(),
           py::arg("allowed_origins") = std::vector<std::string>(), py::arg("web_root") = "",
           py::arg("max_rate") = 60.0, py::arg("realtime") = true, py::keep_alive<1, 2>(),
           "Starts serving `scene` (None: nothing until set_scene) on `address`:`port` (0: a "
           "free port) and prints the URL to open on stderr. `token`: what the page must "
           "carry (None: a random one, in the URL); `allowed_origins`: web pages of other "
           "origins that may connect (default: pages of this machine); `web_root`: the web "
           "bundle folder (default: $PARTSIM_WEB_DIR, the build tree's, the installed one); "
           "`max_rate`: most pose updates per second (Hz); `realtime`: render() paces the loop "
           "to real time (see set_realtime).")
      .def("render", &Render,
           "Applies the page's commands (joint targets, reset, camera pictures) and sends it what "
           "moved (at most max_rate times a second). In real time (the default) it first waits "
           "until the scene's time (scene.get_time()) no longer runs ahead of the wall clock's "
           "since the loop began. While the page has paused the scene it "
           "blocks until resumed, stepped (step n: this and the next n - 1 calls return) or "
           "closed; Ctrl-C raises KeyboardInterrupt and closes the viewer.")
      .def_property_readonly(
          "realtime", [](const PacedViewer& v) { return v.realtime; },
          "Whether render() paces the loop to real time (set_realtime).")
      .def(
          "set_realtime",
          [](PacedViewer& v, bool realtime) {
            v.realtime = realtime;
            v.anchor_scene = nullptr;
          },
          py::arg("realtime"),
          "True (the default): render() waits so that the scene's time does not run ahead of "
          "the wall clock (a loop slower than real time is not sped up to catch up, nor after "
          "a pause); False: the loop runs as fast as it can.")
      .def("wait_for_client", &WaitForClient, py::arg("timeout") = py::none(),
           "Waits until a page (a WebSocket client) is connected: True then, False when "
           "`timeout` seconds (None: no limit) pass first or the viewer is closed. Ctrl-C "
           "raises KeyboardInterrupt and closes the viewer.")
      .def_property_readonly(
          "clients", [](const PacedViewer& v) { return v.GetStats().clients; },
          "The WebSocket clients (pages) connected now.")
      .def_property_readonly("closed", &Viewer::IsClosed,
                             "True once the page's close button was pressed or close() called.")
      .def_property_readonly("paused", &Viewer::IsPaused, "Whether the page paused the scene.")
      .def_property_readonly("url", &Viewer::GetUrl, "http://ADDRESS:PORT/?token=T: the page.")
      .def_property_readonly("port", &Viewer::GetPort, "The port served.")
      .def_property_readonly("token", &Viewer::GetToken, "The token the page carries.")
      .def_property_readonly("web_root", &Viewer::GetWebRoot,
                             "The web bundle folder served, '' when none was found.")
      .def("close", &Viewer::Close, "Marks the viewer closed (viewer.closed becomes True).")
      .def("stop", &Viewer::Stop,
           "Stops the server (closes every connection); the viewer is closed for good.")
      .def(
          "set_scene",
          [](PacedViewer& v, Scene* scene) {
            if (!scene) {
              v.SetScene(nullptr);
              return;
            }
            Scene::Use use(*scene);
            v.SetScene(scene);
          },
          py::arg("scene"), py::keep_alive<1, 2>(),
          "Views another scene (SAPIEN's viewer.set_scene); the page reloads.")
      .def(
          "set_camera_xyz",
          [](PacedViewer& v, double x, double y, double z) {
            v.SetInitialCameraPosition(Eigen::Vector3d(x, y, z));
          },
          py::arg("x"), py::arg("y"), py::arg("z"),
          "Where the page's camera starts (m, world), as SAPIEN's viewer.set_camera_xyz; read "
          "by the page when it loads.")
      .def(
          "set_camera_rpy",
          [](PacedViewer& v, double r, double p, double y) {
            v.SetInitialCameraRpy(Eigen::Vector3d(r, p, y));
          },
          py::arg("r"), py::arg("p"), py::arg("y"),
          "How the page's camera starts: roll, pitch, yaw (rad); it looks along (cos p cos y, "
          "cos p sin y, sin p), as SAPIEN's viewer.set_camera_rpy.")
      .def("set_fovy", &Viewer::SetInitialCameraFovy, py::arg("fovy"),
           "The page's camera's vertical field of view (rad, in (0, pi)), as SAPIEN's "
           "viewer.set_fovy; read by the page when it loads (scene.json's "
           "initial_camera.fovy, null unless set).");

  py::type::of<Scene>().attr("create_viewer") = py::cpp_function(
      [](Scene& scene, int port, const std::string& address,
         const std::optional<std::string>& token, bool realtime) {
        return MakeViewer(&scene, port, address, token, {}, "", 60.0, realtime);
      },
      py::name("create_viewer"), py::is_method(py::type::of<Scene>()), py::arg("port") = 0,
      py::arg("address") = "127.0.0.1", py::arg("token") = py::none(), py::arg("realtime") = true,
      py::keep_alive<0, 1>(),
      "A Viewer of this scene (SAPIEN's name): starts the browser viewer's server on a free "
      "port and prints the URL to open on stderr. `realtime`: its render() paces the loop to "
      "real time (False: as fast as it can).");
}

}  // namespace partsim::python
