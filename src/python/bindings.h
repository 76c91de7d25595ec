// Shared declarations of the partsim Python module: one Bind* function per subsystem, each in its
// own *_py.cc file, all called from module.cc.
#pragma once

#include <pybind11/pybind11.h>

#include <optional>
#include <vector>

#include "partsim/physics/scene.h"

namespace partsim::python {

namespace py = pybind11;

/// Pose, errors (core).
void BindCore(py::module_& m);
/// Scene description, Scene, builders and handles (physics).
void BindPhysics(py::module_& m);
/// URDF loader and mesh files (assets).
void BindAssets(py::module_& m);
/// Cameras, lights, backends and image / point cloud writers (render); after BindPhysics, whose
/// Scene class it extends.
void BindRender(py::module_& m);
/// Robot models and URDF writing (robot_py.cc).
void BindRobots(py::module_& m);
/// Kinematics, IK, trajectories, controllers and the IMU (control_py.cc).
void BindControl(py::module_& m);
/// Door-opening and drawer-pulling tasks and their heuristic solvers (tasks_py.cc).
void BindTasks(py::module_& m);
/// Motion planning (planning_py.cc).
void BindPlanning(py::module_& m);
/// COCO masks and the perception evaluators, in the submodule `_vision` that
/// python/partsim/vision.py re-exports as partsim.vision (vision_py.cc).
void BindVision(py::module_& m);
/// The browser viewer, partsim.Viewer and Scene.create_viewer (viewer_py.cc); after BindPhysics.
void BindViewer(py::module_& m);

/// Runs `f` without the GIL while this thread holds `scene` (Scene::Use), so that other Python
/// threads can run meanwhile but not touch that scene: their calls on it raise PartsimError, and
/// their steps wait. Waiting for another thread's hold happens without the GIL too.
template <typename F>
auto WithoutGil(const Scene& scene, F&& f) {
  std::optional<Scene::Use> use;
  use.emplace(scene, std::try_to_lock);
  if (!use->owns()) {
    use.reset();
    py::gil_scoped_release release;
    use.emplace(scene);
  }
  py::gil_scoped_release release;
  return f();
}

/// Casts handles to a Python list whose items each keep `owner` alive (py::keep_alive cannot
/// attach to a list, which holds no weak references).
template <typename T>
py::list HandleList(const std::vector<T>& handles, py::handle owner) {
  py::list out;
  for (const T& h : handles) {
    py::object item = py::cast(h);
    py::detail::keep_alive_impl(item, owner);
    out.append(item);
  }
  return out;
}

}  // namespace partsim::python
