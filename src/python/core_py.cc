// Bindings of the core subsystem: Pose and the exception types.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "partsim/core/error.h"
#include "partsim/core/log.h"
#include "partsim/core/pose.h"
#include "partsim/render/camera_math.h"

namespace partsim::python {

void BindCore(py::module_& m) {
  // exceptions: translators run newest first, so the base class is registered before the subclass
  static py::exception<Error> error(m, "PartsimError", PyExc_ValueError);
  error.doc() = "Bad input to partsim; the message names the argument, file or element at fault.";
  static py::exception<IndexError> index_error(m, "PartsimIndexError",
                                               py::make_tuple(error, py::handle(PyExc_IndexError)));
  index_error.doc() = "An index or id out of range (a PartsimError and an IndexError).";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const IndexError& e) {
      index_error(e.what());
    } catch (const Error& e) {
      error(e.what());
    }
  });

  py::class_<Pose>(m, "Pose",
                   "A rigid transform X_AB (frame B in frame A): position p (metres) and unit "
                   "quaternion q, read and written as w, x, y, z.")
      .def(py::init(&Pose::FromPQ), py::arg("p") = Eigen::Vector3d::Zero().eval(),
           py::arg("q") = Eigen::Vector4d(1, 0, 0, 0),
           "Pose from position p (3,) in metres and quaternion q (4,) as w, x, y, z.")
      .def_static("from_transformation_matrix", &Pose::FromMatrix, py::arg("m"),
                  "Pose from a 4x4 homogeneous matrix whose upper-left block is a rotation.")
      .def_property(
          "p", [](const Pose& self) -> Eigen::Vector3d { return self.p; },
          [](Pose& self, const Eigen::Vector3d& p) { self.p = p; }, "Position (3,), metres.")
      .def_property(
          "q", &Pose::Wxyz,
          [](Pose& self, const Eigen::Vector4d& wxyz) { self = Pose::FromPQ(self.p, wxyz); },
          "Rotation as a quaternion (4,): w, x, y, z.")
      .def("__mul__", &Pose::operator*, py::arg("other"), "Composition: X_AC = X_AB * X_BC.")
      .def("inv", &Pose::Inverse, "Inverse: X_BA from X_AB.")
      .def("transform", &Pose::Transform, py::arg("x"), "Maps a point (3,) expressed in B to A.")
      .def("to_transformation_matrix", &Pose::ToMatrix, "4x4 homogeneous matrix.")
      .def_static("look_at", &CameraLookAt, py::arg("eye"), py::arg("target"),
                  py::arg("up") = Eigen::Vector3d::UnitZ().eval(),
                  "The pose at `eye` (3,) whose x axis points at `target` (3,) and whose z is "
                  "as close to `up` (3,) as possible, all in metres in one frame: a camera pose "
                  "in partsim's (and SAPIEN's) camera convention, x forward, y left, z up. "
                  "Raises PartsimError when eye and target coincide, up is zero or a value is "
                  "not finite.")
      .def("is_valid", &Pose::IsValid,
           "True when p and q are finite and q has unit norm (within 1e-3).")
      .def("__repr__", &Pose::ToString)
      .def(py::pickle([](const Pose& self) { return py::make_tuple(self.p, self.Wxyz()); },
                      [](const py::tuple& t) {
                        return Pose::FromPQ(t[0].cast<Eigen::Vector3d>(),
                                            t[1].cast<Eigen::Vector4d>());
                      }));

  m.def(
      "set_log_level", [](const std::string& level) { SetLogLevel(ParseLogLevel(level)); },
      py::arg("level"),
      "What partsim writes to standard error: 'warning' (default: loaders' repairs and "
      "numerical trouble), 'error' or 'off' (warnings are still kept in load reports).");
  m.def(
      "get_log_level",
      []() {
        switch (GetLogLevel()) {
          case LogLevel::kWarning:
            return "warning";
          case LogLevel::kError:
            return "error";
          default:
            return "off";
        }
      },
      "The current log level: 'warning', 'error' or 'off'.");
}

}  // namespace partsim::python
