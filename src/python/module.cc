// The partsim Python extension `_partsim`; python/partsim/__init__.py re-exports it.
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "partsim/core/version.h"

PYBIND11_MODULE(_partsim, m) {
  m.doc() = "partsim: simulation of robots interacting with articulated objects (on MuJoCo).";
  // core first: the other subsystems use Pose and the exception types in their signatures
  partsim::python::BindCore(m);
  partsim::python::BindPhysics(m);
  partsim::python::BindAssets(m);
  partsim::python::BindRender(m);
  partsim::python::BindRobots(m);
  partsim::python::BindControl(m);
  partsim::python::BindTasks(m);
  partsim::python::BindPlanning(m);
  partsim::python::BindVision(m);
  partsim::python::BindViewer(m);
  m.attr("__version__") = partsim::Version();
}
