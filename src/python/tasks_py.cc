// Python bindings: door-opening and drawer-pulling tasks and their heuristic solvers. The
// Gymnasium-style environments (python/partsim/envs.py) are built on these.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "partsim/tasks/tasks.h"

namespace partsim::python {

void BindTasks(py::module_& m) {
  py::enum_<TaskType>(m, "TaskType", "The two interaction tasks of the SAPIEN paper.")
      .value("PULL_DRAWER", TaskType::kPullDrawer)
      .value("OPEN_DOOR", TaskType::kOpenDoor);
  m.def("parse_task_type", &ParseTaskType, py::arg("name"), "'drawer' or 'door' to a TaskType.");
  m.def("task_target_label", &TaskTargetLabel, py::arg("type"),
        "The semantics.txt label of the task's targets: 'drawer' or 'rotation_door'.");
  m.def("find_task_targets", &FindTaskTargets, py::arg("object"), py::arg("type"),
        "link ids N (of link_N) of a PartNetMobilityObject that the task can target: labelled "
        "task_target_label(type), with a handle and a finite joint range.");

  py::class_<TaskOptions>(m, "TaskOptions", "Settings of a door or drawer task.")
      .def(py::init<>())
      .def_readwrite("type", &TaskOptions::type)
      .def_readwrite("object_index", &TaskOptions::object_index,
                     "Index of the generated StorageFurniture object.")
      .def_readwrite("dataset_seed", &TaskOptions::dataset_seed)
      .def_readwrite("object_folder", &TaskOptions::object_folder,
                     "A PartNet-Mobility folder (real or generated) instead of the generator's "
                     "object; '' uses object_index and dataset_seed.")
      .def_readwrite("target", &TaskOptions::target,
                     "Which drawer (door) of the object; -1: drawn by reset's seed.")
      .def_readwrite("asset_dir", &TaskOptions::asset_dir,
                     "Folder for the generated object ('' = a temporary folder).")
      .def_readwrite("cameras", &TaskOptions::cameras)
      .def_readwrite("camera_width", &TaskOptions::camera_width)
      .def_readwrite("camera_height", &TaskOptions::camera_height)
      .def_readwrite("render_backend", &TaskOptions::render_backend)
      .def_readwrite("timestep", &TaskOptions::timestep)
      .def_readwrite("control_rate", &TaskOptions::control_rate)
      .def_readwrite("max_seconds", &TaskOptions::max_seconds)
      .def_readwrite("success_fraction", &TaskOptions::success_fraction)
      .def_readwrite("init_on_handle", &TaskOptions::init_on_handle);

  m.def("find_task_objects", &FindTaskObjects, py::arg("type"), py::arg("count"),
        py::arg("dataset_seed") = 0,
        "The first `count` StorageFurniture indices with a drawer (door) that has a handle.");

  using Twist = Eigen::Matrix<double, 6, 1>;
  auto ka = py::keep_alive<0, 1>();
  py::class_<ArticulationTask>(
      m, "ArticulationTask",
      "A drawer-pulling or door-opening episode: a generated cabinet facing +x, the flying "
      "gripper and three cameras (left, right, front). Actions: TCP twist (world, 6) and gripper "
      "command in [-1, 1].")
      .def(py::init<const TaskOptions&>(), py::arg("options"),
           py::call_guard<py::gil_scoped_release>())
      .def(
          "reset",
          [](ArticulationTask& t, std::uint64_t seed) {
            WithoutGil(t.GetScene(), [&] { t.Reset(seed); });
          },
          py::arg("seed") = 0, "Starts a new episode.")
      .def_property_readonly(
          "options", [](const ArticulationTask& t) { return t.GetOptions(); },
          "A copy of the task's options (they are fixed when the task is made).")
      .def_property_readonly("scene", &ArticulationTask::GetSharedScene,
                             "The task's scene (shared).")
      .def_property_readonly("robot_model", &ArticulationTask::GetRobotModel)
      .def_property_readonly("robot", &ArticulationTask::GetRobot, ka)
      .def_property_readonly("object", &ArticulationTask::GetObject, ka)
      .def_property_readonly("target_link", &ArticulationTask::GetTargetLink, ka)
      .def_property_readonly("target_joint", &ArticulationTask::GetTargetJoint, ka)
      .def("get_target_candidates", &ArticulationTask::GetTargetCandidates)
      .def("get_handle_visual_ids", &ArticulationTask::GetHandleVisualIds)
      .def("get_target_entity_id", &ArticulationTask::GetTargetEntityId)
      .def("get_progress", &ArticulationTask::GetProgress,
           "Fraction of the target joint's range opened (0 closed, 1 fully open).")
      .def("is_success", &ArticulationTask::IsSuccess)
      .def("is_failure", &ArticulationTask::IsFailure)
      .def("is_truncated", &ArticulationTask::IsTruncated)
      .def("get_elapsed", &ArticulationTask::GetElapsed, "Simulated seconds since reset.")
      .def("get_tcp_pose", &ArticulationTask::GetTcpPose)
      .def("get_tcp_velocity", &ArticulationTask::GetTcpVelocity)
      .def("set_tcp_target", &ArticulationTask::SetTcpTarget, py::arg("pose"))
      .def(
          "set_tcp_velocity", [](ArticulationTask& t, const Twist& v) { t.SetTcpVelocity(v); },
          py::arg("twist"))
      .def("set_gripper", &ArticulationTask::SetGripper, py::arg("fraction"), "1 open, 0 closed.")
      .def("get_gripper_opening", &ArticulationTask::GetGripperOpening)
      .def("gripper_touches_target", &ArticulationTask::GripperTouchesTarget)
      .def("apply_action", &ArticulationTask::ApplyAction, py::arg("action"),
           "7 values: TCP twist (vx, vy, vz, wx, wy, wz; world) and gripper in [-1, 1].")
      .def(
          "step", [](ArticulationTask& t) { WithoutGil(t.GetScene(), [&] { t.Step(); }); },
          "Advances one control period.")
      .def("take_pictures",
           [](ArticulationTask& t) { WithoutGil(t.GetScene(), [&] { t.TakePictures(); }); })
      .def("get_cameras", &ArticulationTask::GetCameras, ka)
      .def("get_camera", &ArticulationTask::GetCamera, py::arg("name"), ka)
      .def("get_raw_observation", &ArticulationTask::GetRawObservation)
      .def("get_mobility_observation", &ArticulationTask::GetMobilityObservation)
      .def("get_reward", &ArticulationTask::GetReward, "Dense reward of the last step.");

  py::class_<SolverResult>(m, "SolverResult", "Outcome of a heuristic solver.")
      .def_readonly("success", &SolverResult::success)
      .def_readonly("progress", &SolverResult::progress)
      .def_readonly("seconds", &SolverResult::seconds)
      .def_readonly("stage", &SolverResult::stage)
      .def_readonly("message", &SolverResult::message)
      .def("__repr__", [](const SolverResult& r) {
        return "<SolverResult success=" + std::string(r.success ? "True" : "False") +
               " progress=" + std::to_string(r.progress) + " stage='" + r.stage + "'>";
      });
  py::class_<SolverOptions>(m, "SolverOptions", "Options of the heuristic solvers.")
      .def(py::init<>())
      .def_readwrite("use_cameras", &SolverOptions::use_cameras)
      .def_readwrite("frames_dir", &SolverOptions::frames_dir)
      .def_readwrite("frame_every", &SolverOptions::frame_every);
  auto solver = [&m](const char* name, SolverResult (*f)(ArticulationTask&, const SolverOptions&),
                     const char* doc) {
    m.def(
        name,
        [f](ArticulationTask& task, const SolverOptions& options) {
          return WithoutGil(task.GetScene(), [&] { return f(task, options); });
        },
        py::arg("task"), py::arg("options") = SolverOptions(), doc);
  };
  solver("solve_pull_drawer", &SolvePullDrawer, "The paper's drawer heuristic.");
  solver("solve_open_door", &SolveOpenDoor, "The paper's door heuristic.");
  solver("solve_task", &SolveTask, "The heuristic of the task's type.");
}

}  // namespace partsim::python
