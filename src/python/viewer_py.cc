// Bindings of the viewer subsystem: partsim.Viewer, the browser viewer of a scene, and
// Scene.create_viewer (SAPIEN's name). The viewer's server starts at construction and prints
// its URL on stderr; render() runs without the GIL and, while the page keeps the scene paused,
// checks for Ctrl-C every 100 ms (KeyboardInterrupt closes the viewer).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "partsim/physics/scene.h"
#include "partsim/viewer/viewer.h"

namespace partsim::python {
namespace {

std::unique_ptr<Viewer> MakeViewer(Scene* scene, int port, const std::string& address,
                                   const std::optional<std::string>& token,
                                   const std::vector<std::string>& allowed_origins,
                                   const std::string& web_root, double max_rate) {
  ViewerOptions o;
  o.port = port;
  o.address = address;
  o.auth_token = token.value_or("");
  o.allowed_origins = allowed_origins;
  o.web_root = web_root;
  o.max_rate = max_rate;
  auto viewer = std::make_unique<Viewer>(scene, o);
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

void Render(Viewer& v) {
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

}  // namespace

void BindViewer(py::module_& m) {
  py::class_<Viewer>(m, "Viewer",
                     "The scene in a web browser (docs/viewer.md): a server on one port for the "
                     "page, the scene's meshes and a rosbridge WebSocket. SAPIEN's loop runs "
                     "unchanged: while not viewer.closed: scene.step(); scene.update_render(); "
                     "viewer.render().")
      .def(py::init(&MakeViewer), py::arg("scene") = nullptr, py::arg("port") = 0,
           py::arg("address") = "127.0.0.1", py::arg("token") = py::none(),
           py::arg("allowed_origins") = std::vector<std::string>(), py::arg("web_root") = "",
           py::arg("max_rate") = 60.0, py::keep_alive<1, 2>(),
           "Starts serving `scene` (None: nothing until set_scene) on `address`:`port` (0: a "
           "free port) and prints the URL to open on stderr. `token`: what the page must "
           "carry (None: a random one, in the URL); `allowed_origins`: web pages of other "
           "origins that may connect (default: pages of this machine); `web_root`: the web "
           "bundle folder (default: $PARTSIM_WEB_DIR, the build tree's, the installed one); "
           "`max_rate`: most pose updates per second (Hz).")
      .def("render", &Render,
           "Applies the page's commands (joint targets, reset, camera pictures) and sends it what "
           "moved (at most max_rate times a second). While the page has paused the scene it "
           "blocks until resumed, stepped (step n: this and the next n - 1 calls return) or "
           "closed; Ctrl-C raises KeyboardInterrupt and closes the viewer.")
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
          [](Viewer& v, Scene* scene) {
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
          [](Viewer& v, double x, double y, double z) {
            v.SetInitialCameraPosition(Eigen::Vector3d(x, y, z));
          },
          py::arg("x"), py::arg("y"), py::arg("z"),
          "Where the page's camera starts (m, world), as SAPIEN's viewer.set_camera_xyz; read "
          "by the page when it loads.")
      .def(
          "set_camera_rpy",
          [](Viewer& v, double r, double p, double y) {
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
         const std::optional<std::string>& token) {
        return MakeViewer(&scene, port, address, token, {}, "", 60.0);
      },
      py::name("create_viewer"), py::is_method(py::type::of<Scene>()), py::arg("port") = 0,
      py::arg("address") = "127.0.0.1", py::arg("token") = py::none(), py::keep_alive<0, 1>(),
      "A Viewer of this scene (SAPIEN's name): starts the browser viewer's server on a free "
      "port and prints the URL to open on stderr.");
}

}  // namespace partsim::python
