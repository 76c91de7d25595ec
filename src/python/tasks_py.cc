// Python bindings: door-opening and drawer-pulling tasks and their heuristic solvers. The
// Gymnasium-style environments (python/partsim/envs.py) are built on these.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "partsim/core/check.h"
#include "partsim/tasks/tasks.h"

namespace partsim::python {

void BindTasks(py::module_& m) {
  py::enum_<TaskType>(m, "TaskType",
                      "The two interaction tasks of the SAPIEN paper: PULL_DRAWER ('drawer') "
                      "and OPEN_DOOR ('door').")
      .value("PULL_DRAWER", TaskType::kPullDrawer)
      .value("OPEN_DOOR", TaskType::kOpenDoor);
  m.def("parse_task_type", &ParseTaskType, py::arg("name"),
        "'drawer' or 'door' to a TaskType; raises PartsimError naming anything else.");
  m.def("task_target_label", &TaskTargetLabel, py::arg("type"),
        "The semantics.txt label of the task's targets: 'drawer' or 'rotation_door'.");
  m.def("find_task_targets", &FindTaskTargets, py::arg("object"), py::arg("type"),
        "link ids N (of link_N) of a PartNetMobilityObject that the task can target: labelled "
        "task_target_label(type), with a handle and a finite joint range.");

  py::class_<TaskOptions>(m, "TaskOptions", "Settings of a door or drawer task.")
      .def(py::init<>(), "The defaults: a drawer task on generated object 0.")
      .def_readwrite("type", &TaskOptions::type, "TaskType (default PULL_DRAWER).")
      .def_readwrite("object_index", &TaskOptions::object_index,
                     "Index of the generated StorageFurniture object.")
      .def_readwrite("dataset_seed", &TaskOptions::dataset_seed,
                     "Seed of the object generator (default 0).")
      .def_readwrite("object_folder", &TaskOptions::object_folder,
                     "A PartNet-Mobility folder (real or generated) instead of the generator's "
                     "object; '' uses object_index and dataset_seed.")
      .def_readwrite("target", &TaskOptions::target,
                     "Which drawer (door) of the object; -1: drawn by reset's seed.")
      .def_readwrite("asset_dir", &TaskOptions::asset_dir,
                     "Folder for the generated object ('' = a temporary folder).")
      .def_readwrite("cameras", &TaskOptions::cameras,
                     "Add the left, right and front cameras (default True).")
      .def_readwrite("camera_width", &TaskOptions::camera_width,
                     "Camera image width in pixels (default 320).")
      .def_readwrite("camera_height", &TaskOptions::camera_height,
                     "Camera image height in pixels (default 240).")
      .def_readwrite("render_backend", &TaskOptions::render_backend,
                     "'rasterizer' (default), 'pathtracer' or 'null'.")
      .def_readwrite("timestep", &TaskOptions::timestep, "Physics step in s (default 1/500).")
      .def_readwrite("control_rate", &TaskOptions::control_rate,
                     "Control rate in Hz (default 50): step() advances one control period.")
      .def_readwrite("max_seconds", &TaskOptions::max_seconds,
                     "Episode length in simulated seconds before truncation (default 20).")
      .def_readwrite("success_fraction", &TaskOptions::success_fraction,
                     "Fraction of the target joint's range that counts as success (default "
                     "0.9).")
      .def_readwrite("init_on_handle", &TaskOptions::init_on_handle,
                     "reset() places the gripper, closed, on the handle (default False).")
      .def_readwrite("video_width", &TaskOptions::video_width,
                     "With video_height, both > 0: a 'video' camera of this many pixels across "
                     "with a three-quarter view, a floor only cameras see and shadows, for "
                     "recording (get_video_camera, SolverOptions.video_path); 0 (default) for "
                     "none. The episode's dynamics do not change.")
      .def_readwrite("video_height", &TaskOptions::video_height,
                     "Height in pixels of the 'video' camera (see video_width); 0 for none.")
      .def_readwrite("filter_collisions", &TaskOptions::filter_collisions,
                     "The cabinet's links never collide with each other (its base is fixed, its "
                     "parts move along their joints and stop at joint limits); the gripper "
                     "collides with all of them. Default True: it saves most of the collision "
                     "detection and leaves the heuristic solvers' results on generated "
                     "cabinets unchanged; set False for an object where one part blocks "
                     "another (a drawer behind a closed door), which would pass through.")
      .def_readwrite("box_primitives", &TaskOptions::box_primitives,
                     "The cabinet's collision meshes that are axis-aligned boxes collide as "
                     "boxes (the engine's box collider); masses and inertias unchanged. Default "
                     "True.");

  m.def("find_task_objects", &FindTaskObjects, py::arg("type"), py::arg("count"),
        py::arg("dataset_seed") = 0,
        "The first `count` generated StorageFurniture indices (from 0, for dataset_seed) whose "
        "object has a drawer (door) with a handle, as a list of int.");

  using Twist = Eigen::Matrix<double, 6, 1>;
  auto ka = py::keep_alive<0, 1>();
  py::class_<ArticulationTask>(
      m, "ArticulationTask",
      "A drawer-pulling or door-opening episode: a generated cabinet facing +x, the flying "
      "gripper and three cameras (left, right, front). Actions: TCP twist (world, 6) and gripper "
      "command in [-1, 1].")
      .def(py::init<const TaskOptions&>(), py::arg("options"),
           py::call_guard<py::gil_scoped_release>(),
           "Builds the task's scene: the object (generated or from object_folder), the gripper "
           "and the cameras. Releases the GIL.")
      .def(
          "reset",
          [](ArticulationTask& t, std::uint64_t seed) {
            WithoutGil(t.GetScene(), [&] { t.Reset(seed); });
          },
          py::arg("seed") = 0,
          "Starts a new episode: the same cabinet, joints closed, the target drawn from `seed` "
          "(unless options.target is set), the gripper open at a pose drawn from `seed` in "
          "front of the cabinet (or on the handle with init_on_handle).")
      .def_property_readonly(
          "options", [](const ArticulationTask& t) { return t.GetOptions(); },
          "A copy of the task's options (they are fixed when the task is made).")
      .def_property_readonly("scene", &ArticulationTask::GetSharedScene,
                             "The task's scene (shared).")
      .def_property_readonly("robot_model", &ArticulationTask::GetRobotModel,
                             "RobotModel of the flying gripper.")
      .def_property_readonly("robot", &ArticulationTask::GetRobot, ka,
                             "The flying gripper's Articulation.")
      .def_property_readonly("object", &ArticulationTask::GetObject, ka,
                             "The cabinet's Articulation (base on z = 0, front facing +x).")
      .def_property_readonly("target_link", &ArticulationTask::GetTargetLink, ka,
                             "Link of the target drawer or door.")
      .def_property_readonly("target_joint", &ArticulationTask::GetTargetJoint, ka,
                             "Joint of the target drawer or door.")
      .def("get_target_candidates", &ArticulationTask::GetTargetCandidates,
           "Link names of the target's candidates (links with the task's label and a "
           "handle).")
      .def("get_handle_visual_ids", &ArticulationTask::GetHandleVisualIds,
           "Render visual ids (segmentation channel 0) of the target's handle pieces.")
      .def("get_target_entity_id", &ArticulationTask::GetTargetEntityId,
           "Render entity id (segmentation channel 1) of the target link.")
      .def("get_progress", &ArticulationTask::GetProgress,
           "Fraction of the target joint's range opened (0 closed, 1 fully open).")
      .def("is_success", &ArticulationTask::IsSuccess,
           "True when progress reached options.success_fraction.")
      .def("is_failure", &ArticulationTask::IsFailure,
           "True when the joint moved the wrong way past its closed end by more than 2% of "
           "the range.")
      .def("is_truncated", &ArticulationTask::IsTruncated,
           "True when more than options.max_seconds have passed since reset.")
      .def("get_elapsed", &ArticulationTask::GetElapsed, "Simulated seconds since reset.")
      .def("get_tcp_pose", &ArticulationTask::GetTcpPose,
           "World pose of the gripper's tool centre point (TCP).")
      .def("get_tcp_velocity", &ArticulationTask::GetTcpVelocity,
           "TCP twist (6,) in the world frame: linear (m/s) then angular (rad/s).")
      .def("set_tcp_target", &ArticulationTask::SetTcpTarget, py::arg("pose"),
           "Moves the hand towards a world pose by position control of the six arm joints.")
      .def(
          "set_tcp_velocity", [](ArticulationTask& t, const Twist& v) { t.SetTcpVelocity(v); },
          py::arg("twist"),
          "Moves the hand with a world twist (6,), linear m/s then angular rad/s, held until "
          "changed.")
      .def("set_gripper", &ArticulationTask::SetGripper, py::arg("fraction"),
           "Finger opening as a fraction: 1 fully open, 0 closed (clamped to [0, 1]).")
      .def("get_gripper_opening", &ArticulationTask::GetGripperOpening,
           "Current finger opening, 0 (closed) to 1 (open).")
      .def("gripper_touches_target", &ArticulationTask::GripperTouchesTarget,
           "True when a finger touches the target link (handle or panel).")
      .def("apply_action", &ArticulationTask::ApplyAction, py::arg("action"),
           "7 values: TCP twist (vx, vy, vz in m/s, wx, wy, wz in rad/s; world frame) and the "
           "gripper command in [-1, 1] (-1 close, 1 open). Speeds are clamped to 1 m/s and 3 "
           "rad/s; a NaN, infinite or wrongly sized action raises PartsimError and changes "
           "nothing.")
      .def(
          "step", [](ArticulationTask& t) { WithoutGil(t.GetScene(), [&] { t.Step(); }); },
          "Advances one control period: timestep-long physics steps for 1 / control_rate s; the "
          "GIL is released.")
      .def(
          "take_pictures",
          [](ArticulationTask& t) { WithoutGil(t.GetScene(), [&] { t.TakePictures(); }); },
          "Renders the cameras (left, right, front) at the current state; the GIL is released.")
      .def("get_cameras", &ArticulationTask::GetCameras, ka,
           "The task's cameras (left, right, front; empty without options.cameras).")
      .def("get_video_camera", &ArticulationTask::GetVideoCamera, ka,
           "The 'video' camera of TaskOptions.video_width / video_height; raises PartsimError "
           "when the task has none.")
      .def("get_camera", &ArticulationTask::GetCamera, py::arg("name"), ka,
           "The camera named `name` ('left', 'right' or 'front'); raises PartsimError when the "
           "task has none of that name.")
      .def("get_raw_observation", &ArticulationTask::GetRawObservation,
           "float64 vector: the cabinet's qpos and qvel, then the TCP pose (p (3,) in m, q (4,) "
           "w, x, y, z; world), the TCP twist (6,) and the gripper opening.")
      .def("get_mobility_observation", &ArticulationTask::GetMobilityObservation,
           "float64 vector: the target joint's axis origin (3,) and direction (3,) in the "
           "world, the target part's average outward normal (3,), the joint's position and "
           "velocity (2,), then the robot state as in get_raw_observation.")
      .def("get_reward", &ArticulationTask::GetReward,
           "Dense reward of the last step: 10 x progress gained, +1 per step at success, -0.1 "
           "when a grasp was lost, minus 0.5 x the TCP's distance (m) to the handle until it is "
           "grasped.");

  py::class_<SolverResult>(m, "SolverResult", "Outcome of a heuristic solver.")
      .def_readonly("success", &SolverResult::success, "True when the task succeeded.")
      .def_readonly("progress", &SolverResult::progress,
                    "Final fraction of the target joint's range opened.")
      .def_readonly("seconds", &SolverResult::seconds, "Simulated time used, s.")
      .def_readonly("stage", &SolverResult::stage,
                    "Stage reached: 'perceive', 'grasp', 'pull', 'open' or 'done'.")
      .def_readonly("message", &SolverResult::message, "Why it failed ('' on success).")
      .def("__repr__", [](const SolverResult& r) {
        return "<SolverResult success=" + std::string(r.success ? "True" : "False") +
               " progress=" + FormatNumber(r.progress) + " stage='" + r.stage + "'>";
      });
  py::class_<SolverOptions>(m, "SolverOptions", "Options of the heuristic solvers.")
      .def(py::init<>(), "The defaults.")
      .def_readwrite("use_cameras", &SolverOptions::use_cameras,
                     "True (default): find the handle in the cameras' segmented point clouds; "
                     "False: from the handle's mesh in the scene (ground truth).")
      .def_readwrite("frames_dir", &SolverOptions::frames_dir,
                     "Folder for frame_NNNNN.png colour frames of the recording camera ('video' "
                     "if the task has one, else 'front'); '' (default) writes none.")
      .def_readwrite("video_path", &SolverOptions::video_path,
                     "An H.264 MP4 of the same frames as frames_dir, at control_rate / "
                     "frame_every frames per second (real time); '' (default) writes none.")
      .def_readwrite("frame_every", &SolverOptions::frame_every,
                     "Control steps between two written frames (default 10).");
  auto solver = [&m](const char* name, SolverResult (*f)(ArticulationTask&, const SolverOptions&),
                     const char* doc) {
    m.def(
        name,
        [f](ArticulationTask& task, const SolverOptions& options) {
          return WithoutGil(task.GetScene(), [&] { return f(task, options); });
        },
        py::arg("task"), py::arg("options") = SolverOptions(), doc);
  };
  solver("solve_pull_drawer", &SolvePullDrawer,
         "The paper's drawer heuristic: find the handle in the segmented point cloud, grasp it, "
         "pull along the joint axis with a velocity controller. Returns a SolverResult; the GIL "
         "is released.");
  solver("solve_open_door", &SolveOpenDoor,
         "The paper's door heuristic: grasp the handle, open a little, then follow the door by "
         "visual servoing while turning about the hinge, re-grasping when the grip is lost. "
         "Returns a SolverResult; the GIL is released.");
  solver("solve_task", &SolveTask,
         "solve_pull_drawer or solve_open_door, by the task's type. Returns a SolverResult.");

  m.def("step_tasks", &StepTasks, py::call_guard<py::gil_scoped_release>(), py::arg("tasks"),
        py::arg("actions"),
        "apply_action(actions[i]) and step() of every task in `tasks` (distinct tasks), in "
        "parallel: on the calling thread and threads kept between calls (up to one per core), "
        "each task taken by the next thread free, the GIL released. `actions` has shape "
        "(len(tasks), 7); a "
        "wrong shape or a non-finite entry raises PartsimError before any task moves. Used by "
        "partsim.envs.VectorOpenCabinetEnv: one call per vector step instead of a hand-off to "
        "a worker thread per environment.");
}

}  // namespace partsim::python
