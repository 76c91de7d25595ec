// Python bindings: Kinematics, IK, trajectories, controllers and the IMU.
//
// Lifetime: a controller keeps the Articulation handle it was built with (and so the scene)
// alive; a ControlLoop keeps its scene and its controllers alive. Controllers have no Python
// subclasses, so ControlLoop.step releases the GIL.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "partsim/robot/controllers.h"
#include "partsim/robot/imu.h"
#include "partsim/robot/kinematics.h"
#include "partsim/robot/trajectory.h"

namespace partsim::python {

void BindControl(py::module_& m) {
  // ------------------------------------------------------------------ kinematics
  py::class_<KinematicModel>(m, "KinematicModel",
                             "Forward kinematics and Jacobians of an articulation without the "
                             "physics engine; joint vectors in get_active_joints() order.")
      .def(py::init<const ArticulationDesc&>(), py::arg("articulation"),
           "The model of an articulation description, its root at the description's root_pose.")
      .def_static("from_articulation", &KinematicModel::FromArticulation, py::arg("articulation"),
                  "The model of an articulation in a scene, with its current root pose.")
      .def("dof", &KinematicModel::Dof, "Degrees of freedom: the length of q.")
      .def("num_links", &KinematicModel::NumLinks, "Number of links.")
      .def("link_index", &KinematicModel::LinkIndex, py::arg("name"),
           "Index of the link named `name`; raises PartsimError naming a missing link.")
      .def("dof_index", &KinematicModel::DofIndex, py::arg("joint_name"),
           "Dof index of a joint (-1 if it has none); raises PartsimError naming a missing "
           "joint.")
      .def("limits", &KinematicModel::Limits,
           "Lower and upper limits, (dof, 2), m or rad; +-inf when unlimited.")
      .def("get_root_pose", &KinematicModel::GetRootPose,
           "X_WR: the root link's pose in the world that forward kinematics starts from.")
      .def("set_root_pose", &KinematicModel::SetRootPose, py::arg("pose"),
           "Sets X_WR, the root link's pose in the world.")
      .def("forward_kinematics", &KinematicModel::ForwardKinematics, py::arg("q"),
           "World poses X_WL of every link (list of Pose, link order) for joint positions q "
           "(dof,), m or rad; raises PartsimError on a wrong size.")
      .def("link_pose", &KinematicModel::LinkPose, py::arg("q"), py::arg("link"),
           py::arg("offset") = Pose(),
           "World pose X_WL * offset of a frame `offset` fixed on link `link` (an index, "
           "e.g. a TCP), for joint positions q (dof,).")
      .def("jacobian", &KinematicModel::Jacobian, py::arg("q"), py::arg("link"),
           py::arg("offset") = Pose(),
           "World-frame geometric Jacobian (6, dof) of `offset` on `link`: rows linear; angular.");

  py::class_<IkOptions>(m, "IkOptions", "Options of inverse_kinematics.")
      .def(py::init<>(), "The defaults.")
      .def_readwrite("offset", &IkOptions::offset,
                     "Pose of the frame to place, in the link's frame (e.g. the TCP).")
      .def_readwrite("position_tolerance", &IkOptions::position_tolerance,
                     "Position tolerance of success, m (default 1e-4).")
      .def_readwrite("rotation_tolerance", &IkOptions::rotation_tolerance,
                     "Rotation tolerance of success, rad (default 1e-3).")
      .def_readwrite("max_iterations", &IkOptions::max_iterations,
                     "Iterations per attempt (default 200).")
      .def_readwrite("damping", &IkOptions::damping,
                     "lambda of damped least squares (default 1e-2).")
      .def_readwrite("max_step", &IkOptions::max_step,
                     "Largest joint change per iteration, rad or m (default 0.2).")
      .def_readwrite("position_only", &IkOptions::position_only,
                     "True: ignore the orientation of the target.")
      .def_readwrite("active", &IkOptions::active,
                     "list of bool (dof): the dofs IK may move; empty (default): all.")
      .def_readwrite("restarts", &IkOptions::restarts,
                     "Random restarts inside the limits after a failed attempt (default 4).")
      .def_readwrite("seed", &IkOptions::seed, "Random seed of the restarts (default 0).");

  py::class_<IkResult>(m, "IkResult", "Result of inverse_kinematics.")
      .def(py::init<>())
      .def_readwrite("success", &IkResult::success,
                     "True when q is within both tolerances of the target.")
      .def_readwrite("q", &IkResult::q,
                     "Best joint positions found (dof,), within the limits, m or rad.")
      .def_readwrite("position_error", &IkResult::position_error, "Position error at q, m.")
      .def_readwrite("rotation_error", &IkResult::rotation_error, "Rotation error at q, rad.")
      .def_readwrite("iterations", &IkResult::iterations, "Iterations used, restarts included.")
      .def_readwrite("message", &IkResult::message, "Why it failed ('' on success).")
      .def("__bool__", [](const IkResult& r) { return r.success; });

  m.def("inverse_kinematics", &InverseKinematics, py::arg("model"), py::arg("link"),
        py::arg("target"), py::arg("q_init"), py::arg("options") = IkOptions(),
        "Joint positions that put options.offset on `link` at world pose `target`, by damped "
        "least squares within the joint limits; success False (and the closest q) when out of "
        "reach. Raises PartsimError for a bad link, a q_init of the wrong size or a "
        "non-finite target.");
  m.def("pose_error", &PoseError, py::arg("current"), py::arg("target"),
        "(p_target - p; axis-angle of R_target R^T), a (6,) array in m and rad.");

  // ------------------------------------------------------------------ trajectories
  py::class_<JointTrajectory>(m, "JointTrajectory",
                              "Timed waypoints (times from the start, s); velocities and "
                              "accelerations may be empty lists.")
      .def(py::init<>(), "An empty trajectory.")
      .def_readwrite("times", &JointTrajectory::times,
                     "list of float: seconds from the start, strictly increasing, first >= 0.")
      .def_readwrite("positions", &JointTrajectory::positions,
                     "list of (dof,) arrays, one per time, m or rad.")
      .def_readwrite("velocities", &JointTrajectory::velocities,
                     "list of (dof,) arrays, one per time (m/s or rad/s), or empty: derived "
                     "by a cubic spline.")
      .def_readwrite("accelerations", &JointTrajectory::accelerations,
                     "list of (dof,) arrays, one per time (m/s^2 or rad/s^2), or empty.")
      .def("validate", &JointTrajectory::Validate, py::arg("dof"),
           "Checks sizes against `dof`, times and values; raises PartsimError naming the "
           "waypoint at fault.")
      .def("duration", &JointTrajectory::Duration, "Time of the last waypoint, s (0 when empty).")
      .def(
          "sample",
          [](const JointTrajectory& t, double time) {
            Eigen::VectorXd q, qd, qdd;
            t.Sample(time, &q, &qd, &qdd);
            return py::make_tuple(q, qd, qdd);
          },
          py::arg("t"),
          "(q, qd, qdd) at time t in s (clamped to [0, duration]), each (dof,): quintic "
          "between waypoints with velocities and accelerations, cubic with velocities only, a "
          "C2 cubic spline at rest at both ends with positions only.");
  py::class_<TrajectorySampler>(
      m, "TrajectorySampler",
      "A JointTrajectory ready to be sampled many times: each segment's polynomial is computed "
      "once (the spline of a positions-only trajectory too), so sample() costs the same "
      "whatever the number of waypoints; JointTrajectory.sample fits the spline again at every "
      "call. Same values as JointTrajectory.sample.")
      .def(py::init<JointTrajectory>(), py::arg("trajectory"),
           "Copies `trajectory`; raises PartsimError when it has no waypoints or positions for "
           "fewer or more times.")
      .def_property_readonly("trajectory", &TrajectorySampler::trajectory,
                             "The JointTrajectory sampled (a copy).")
      .def(
          "sample",
          [](const TrajectorySampler& s, double time) {
            Eigen::VectorXd q, qd, qdd;
            s.Sample(time, &q, &qd, &qdd);
            return py::make_tuple(q, qd, qdd);
          },
          py::arg("t"), "(q, qd, qdd) at time t in s, as JointTrajectory.sample gives them.");
  m.def("time_parameterize", &TimeParameterize, py::arg("path"), py::arg("velocity_limits"),
        py::arg("acceleration_limits"),
        "Times a path (list of (dof,) positions) so that it starts and ends at rest and no "
        "joint exceeds its velocity (dof,) or acceleration (dof,) limit; returns a "
        "JointTrajectory. Raises PartsimError on an empty path, sizes that differ or limits "
        "that are not positive.");

  // ------------------------------------------------------------------ controllers
  py::enum_<ControllerState>(m, "ControllerState", "Where a controller stands.")
      .value("IDLE", ControllerState::kIdle, "no target yet")
      .value("RUNNING", ControllerState::kRunning, "moving towards the target")
      .value("REACHED", ControllerState::kReached, "within tolerance of the target")
      .value("FAILED", ControllerState::kFailed, "the target cannot be reached (see message)");

  py::class_<ControllerStatus>(m, "ControllerStatus",
                               "A controller's state and the message that explains it.")
      .def(py::init<>())
      .def_readwrite("state", &ControllerStatus::state, "ControllerState.")
      .def_readwrite("message", &ControllerStatus::message,
                     "Why it failed, or what was clamped ('' if nothing).")
      .def("__repr__", [](const ControllerStatus& s) {
        return std::string("ControllerStatus(") + ControllerStateName(s.state) +
               (s.message.empty() ? "" : ", '" + s.message + "'") + ")";
      });

  py::class_<JointControllerOptions>(m, "JointControllerOptions",
                                     "Common settings of the joint controllers; a controller "
                                     "made with one out of range raises PartsimError naming "
                                     "it and its value.")
      .def(py::init<>(), "The defaults.")
      .def_readwrite(
          "control_rate", &JointControllerOptions::control_rate,
          "Update rate in Hz, finite and > 0 (default 100): the controller updates every "
          "round(1 / (rate * timestep)) physics steps.")
      .def_readwrite("gravity_compensation", &JointControllerOptions::gravity_compensation,
                     "Add the passive force (gravity, Coriolis) as qf (default True).")
      .def_readwrite("stiffness", &JointControllerOptions::stiffness,
                     "PD stiffness written to the joints' drives, N/m or N m/rad, finite and >= 0 "
                     "(default 1e4).")
      .def_readwrite(
          "damping", &JointControllerOptions::damping,
          "PD damping written to the joints' drives, N s/m or N m s/rad, finite and >= 0 "
          "(default 1e3).")
      .def_readwrite("force_limit", &JointControllerOptions::force_limit,
                     "Per-joint force limit, N or N m, > 0 (default inf); also clamps efforts.")
      .def_readwrite("position_tolerance", &JointControllerOptions::position_tolerance,
                     "Position tolerance for REACHED, rad or m, > 0 (default 1e-2).")
      .def_readwrite("velocity_tolerance", &JointControllerOptions::velocity_tolerance,
                     "Velocity tolerance for REACHED, rad/s or m/s, > 0 (default 5e-2).")
      .def_readwrite("timeout", &JointControllerOptions::timeout,
                     "Seconds without reaching the target before FAILED, > 0 (default 5).");

  using Names = std::vector<std::string>;
  const auto keep_robot = py::keep_alive<1, 2>();
  py::class_<Controller, std::shared_ptr<Controller>>(m, "Controller",
                                                      "Base class of the controllers: a "
                                                      "controller of some joints of one "
                                                      "articulation. Bad input (wrong sizes, "
                                                      "NaN, a setting out of range, named "
                                                      "with its value) raises PartsimError and "
                                                      "changes nothing; an unreachable target "
                                                      "sets status FAILED.")
      .def("get_name", &Controller::GetName, "The controller's name ('' unless set).")
      .def("set_name", &Controller::SetName, py::arg("name"), "Names the controller.")
      .def("num_joints", &Controller::NumJoints, "Number of controlled joints (one dof each).")
      .def("get_dofs", &Controller::GetDofs,
           "Indices of the controlled joints' dofs in the articulation's qpos.")
      .def("get_joint_names", &Controller::GetJointNames, "Names of the controlled joints.")
      .def("get_options", &Controller::GetOptions, "The JointControllerOptions (a copy).")
      .def("get_status", &Controller::GetStatus, "ControllerStatus: state and message.")
      .def_property_readonly("status", &Controller::GetStatus,
                             "ControllerStatus: state and message.")
      .def("get_robot", &Controller::GetRobot, "The controlled Articulation.")
      .def("period", &Controller::Period, "Physics steps between two updates.")
      .def("update", &Controller::Update,
           "One control update; ControlLoop calls it every period() steps, before the physics "
           "steps.")
      .def("get_qpos", &Controller::GetQpos,
           "Current positions of the controlled joints (num_joints,), m or rad.")
      .def("get_qvel", &Controller::GetQvel,
           "Current velocities of the controlled joints (num_joints,), m/s or rad/s.");

  py::class_<JointEffortController, Controller, std::shared_ptr<JointEffortController>>(
      m, "JointEffortController", "Joint efforts (clamped to force_limit) plus compensation.")
      .def(py::init<const Articulation&, const Names&, const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints") = Names(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def("set_target", &JointEffortController::SetTarget, py::arg("effort"),
           "Efforts (num_joints,), N or N m, clamped to force_limit and each joint's "
           "effort_limit (the status message names the clamped ones); status becomes "
           "REACHED.");

  py::class_<JointPositionController, Controller, std::shared_ptr<JointPositionController>>(
      m, "JointPositionController", "PD position control through the joints' drives.")
      .def(py::init<const Articulation&, const Names&, const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints") = Names(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def("set_target", &JointPositionController::SetTarget, py::arg("q"),
           "Position targets (num_joints,), m or rad; a target outside the joint limits is "
           "clamped to them and the status is FAILED, naming the joint.")
      .def("get_target", &JointPositionController::GetTarget,
           "Current position targets (num_joints,), m or rad.");

  py::class_<JointVelocityController, Controller, std::shared_ptr<JointVelocityController>>(
      m, "JointVelocityController", "Velocity control through the joints' drives.")
      .def(py::init<const Articulation&, const Names&, const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints") = Names(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def("set_target", &JointVelocityController::SetTarget, py::arg("qd"),
           "Velocity targets (num_joints,), m/s or rad/s; FAILED after `timeout` of not "
           "reaching them (e.g. a joint at its limit).");

  py::class_<JointTrajectoryController, Controller, std::shared_ptr<JointTrajectoryController>>(
      m, "JointTrajectoryController", "Follows a JointTrajectory with PD and feed-forward.")
      .def(py::init<const Articulation&, const Names&, const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints") = Names(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def_readwrite(
          "path_tolerance", &JointTrajectoryController::path_tolerance,
          "Largest tracking error before FAILED, rad or m, > 0 (default 0.1); checked by "
          "set_trajectory and at each update.")
      .def("set_trajectory", &JointTrajectoryController::SetTrajectory, py::arg("trajectory"),
           "Follows a JointTrajectory whose times count from now; FAILED (nothing moves) when "
           "a waypoint lies outside the joint limits.")
      .def("set_path", &JointTrajectoryController::SetPath, py::arg("path"),
           py::arg("velocity_limits"), py::arg("acceleration_limits"),
           "Follows a path without times (list of (num_joints,) positions), timed by "
           "time_parameterize with these limits (num_joints,).")
      .def("get_trajectory", &JointTrajectoryController::GetTrajectory,
           "The JointTrajectory being followed.");

  py::enum_<ControlFrame>(m, "ControlFrame",
                          "Frame of end-effector targets: WORLD or BASE (the robot's root "
                          "link).")
      .value("WORLD", ControlFrame::kWorld)
      .value("BASE", ControlFrame::kBase);

  py::class_<EndEffectorController, Controller, std::shared_ptr<EndEffectorController>>(
      m, "EndEffectorController", "Pose or twist targets of a frame on a link, through IK.")
      .def(py::init<const Articulation&, const Names&, const std::string&, const Pose&,
                    const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints"), py::arg("ee_link"), py::arg("tcp") = Pose(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def_readwrite("ik", &EndEffectorController::ik, "IkOptions used for pose targets.")
      .def_readwrite("max_linear_speed", &EndEffectorController::max_linear_speed,
                     "Pose targets are approached no faster than this, m/s, > 0 (default 0.5); "
                     "checked with the other settings when a target is set and at each update.")
      .def_readwrite("max_angular_speed", &EndEffectorController::max_angular_speed,
                     "Pose targets are turned to no faster than this, rad/s, > 0 (default 1.5).")
      .def_readwrite("position_tolerance", &EndEffectorController::position_tolerance,
                     "Position tolerance of the measured frame for REACHED, m, > 0 (default 2e-3).")
      .def_readwrite("rotation_tolerance", &EndEffectorController::rotation_tolerance,
                     "Rotation tolerance of the measured frame for REACHED, rad, > 0 (default "
                     "1.5e-2).")
      .def("set_target_pose", &EndEffectorController::SetTargetPose, py::arg("target"),
           py::arg("frame") = ControlFrame::kWorld,
           "Pose target of the TCP in `frame`, approached along a commanded pose limited to "
           "the max speeds; FAILED when IK cannot reach it (the robot stays) or it is not "
           "reached `timeout` after the commanded pose arrived.")
      .def("set_target_twist", &EndEffectorController::SetTargetTwist, py::arg("twist"),
           py::arg("frame") = ControlFrame::kWorld,
           "twist: (6,) linear (m/s) and angular (rad/s) velocity, held until changed.")
      .def("get_end_effector_pose", &EndEffectorController::GetEndEffectorPose,
           "Current world pose of the controlled frame (the TCP on ee_link).");

  py::class_<ControlLoop>(m, "ControlLoop",
                          "Steps a scene and updates controllers every period() steps.")
      .def(py::init<Scene*>(), py::arg("scene"), py::keep_alive<1, 2>(),
           "A loop that steps `scene`.")
      .def("add", &ControlLoop::Add, py::arg("controller"), py::keep_alive<1, 2>(),
           "Adds a controller (its drive gains are written to its joints); its first update "
           "happens at the next step.")
      .def("remove", &ControlLoop::Remove, py::arg("controller"), "Stops updating a controller.")
      .def(
          "step", [](ControlLoop& l, int n) { WithoutGil(*l.GetScene(), [&] { l.Step(n); }); },
          py::arg("n") = 1, "Steps n times (the GIL released, the scene held: see Scene.step).")
      .def(
          "run_until_done",
          [](ControlLoop& l, double max_seconds) {
            return WithoutGil(*l.GetScene(), [&] { return l.RunUntilDone(max_seconds); });
          },
          py::arg("max_seconds"),
          "Steps until every controller is reached, failed or idle; True if none failed.")
      .def("get_scene", &ControlLoop::GetScene, py::return_value_policy::reference,
           "The Scene this loop steps.");

  // ------------------------------------------------------------------ IMU
  py::class_<ImuReading>(m, "ImuReading", "What an IMU reads, in its own frame.")
      .def(py::init<>())
      .def_readwrite("orientation", &ImuReading::orientation,
                     "Quaternion (4,) w, x, y, z of the sensor frame in the world.")
      .def_readwrite("linear_acceleration", &ImuReading::linear_acceleration,
                     "Proper acceleration (3,) in the sensor frame, m/s^2: +9.81 up at rest.")
      .def_readwrite("angular_velocity", &ImuReading::angular_velocity,
                     "Angular velocity (3,) in the sensor frame, rad/s.")
      .def_readwrite("time", &ImuReading::time, "Simulated time of the reading, s.");

  py::class_<Imu>(m, "Imu", "An IMU fixed to a link or an actor at local_pose.")
      .def(py::init<const Link&, const Pose&>(), py::arg("link"), py::arg("local_pose") = Pose(),
           py::keep_alive<1, 2>(), "An IMU on a link, at local_pose in the link frame.")
      .def(py::init<const Actor&, const Pose&>(), py::arg("actor"), py::arg("local_pose") = Pose(),
           py::keep_alive<1, 2>(), "An IMU on an actor, at local_pose in the actor frame.")
      .def("read", &Imu::Read, "The ImuReading at the current state (after the last step).");
}

}  // namespace partsim::python
