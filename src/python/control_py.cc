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
#include "partsim/robot/kinematics.h"
#include "partsim/robot/trajectory.h"

namespace partsim::python {

void BindControl(py::module_& m) {
  // ------------------------------------------------------------------ kinematics
  py::class_<KinematicModel>(m, "KinematicModel",
                             "Forward kinematics and Jacobians of an articulation without the "
                             "physics engine; joint vectors in get_active_joints() order.")
      .def(py::init<const ArticulationDesc&>(), py::arg("articulation"))
      .def_static("from_articulation", &KinematicModel::FromArticulation, py::arg("articulation"),
                  "The model of an articulation in a scene, with its current root pose.")
      .def("dof", &KinematicModel::Dof)
      .def("num_links", &KinematicModel::NumLinks)
      .def("link_index", &KinematicModel::LinkIndex, py::arg("name"))
      .def("dof_index", &KinematicModel::DofIndex, py::arg("joint_name"),
           "Dof index of a joint (-1 if it has none).")
      .def("limits", &KinematicModel::Limits, "Lower and upper limits, (dof, 2).")
      .def("get_root_pose", &KinematicModel::GetRootPose)
      .def("set_root_pose", &KinematicModel::SetRootPose, py::arg("pose"))
      .def("forward_kinematics", &KinematicModel::ForwardKinematics, py::arg("q"),
           "World poses X_WL of every link for joint positions q (dof,).")
      .def("link_pose", &KinematicModel::LinkPose, py::arg("q"), py::arg("link"),
           py::arg("offset") = Pose(), "World pose of `offset` on `link` (an index).")
      .def("jacobian", &KinematicModel::Jacobian, py::arg("q"), py::arg("link"),
           py::arg("offset") = Pose(),
           "World-frame geometric Jacobian (6, dof) of `offset` on `link`: rows linear; angular.");

  py::class_<IkOptions>(m, "IkOptions", "Options of inverse_kinematics.")
      .def(py::init<>())
      .def_readwrite("offset", &IkOptions::offset, "frame on the link to place (e.g. the TCP)")
      .def_readwrite("position_tolerance", &IkOptions::position_tolerance, "m")
      .def_readwrite("rotation_tolerance", &IkOptions::rotation_tolerance, "rad")
      .def_readwrite("max_iterations", &IkOptions::max_iterations)
      .def_readwrite("damping", &IkOptions::damping, "lambda of damped least squares")
      .def_readwrite("max_step", &IkOptions::max_step, "largest joint change per iteration")
      .def_readwrite("position_only", &IkOptions::position_only)
      .def_readwrite("active", &IkOptions::active, "dofs IK may move (empty: all)")
      .def_readwrite("restarts", &IkOptions::restarts)
      .def_readwrite("seed", &IkOptions::seed);

  py::class_<IkResult>(m, "IkResult", "Result of inverse_kinematics.")
      .def(py::init<>())
      .def_readwrite("success", &IkResult::success)
      .def_readwrite("q", &IkResult::q, "best joint positions found (within the limits)")
      .def_readwrite("position_error", &IkResult::position_error, "m")
      .def_readwrite("rotation_error", &IkResult::rotation_error, "rad")
      .def_readwrite("iterations", &IkResult::iterations)
      .def_readwrite("message", &IkResult::message)
      .def("__bool__", [](const IkResult& r) { return r.success; });

  m.def("inverse_kinematics", &InverseKinematics, py::arg("model"), py::arg("link"),
        py::arg("target"), py::arg("q_init"), py::arg("options") = IkOptions(),
        "Joint positions that put options.offset on `link` at world pose `target`, by damped "
        "least squares within the joint limits; success False (and the closest q) when out of "
        "reach.");
  m.def("pose_error", &PoseError, py::arg("current"), py::arg("target"),
        "(p_target - p; axis-angle of R_target R^T), a (6,) array in m and rad.");

  // ------------------------------------------------------------------ trajectories
  py::class_<JointTrajectory>(m, "JointTrajectory",
                              "Timed waypoints (times from the start, s); velocities and "
                              "accelerations may be empty lists.")
      .def(py::init<>())
      .def_readwrite("times", &JointTrajectory::times)
      .def_readwrite("positions", &JointTrajectory::positions)
      .def_readwrite("velocities", &JointTrajectory::velocities)
      .def_readwrite("accelerations", &JointTrajectory::accelerations)
      .def("validate", &JointTrajectory::Validate, py::arg("dof"))
      .def("duration", &JointTrajectory::Duration)
      .def(
          "sample",
          [](const JointTrajectory& t, double time) {
            Eigen::VectorXd q, qd, qdd;
            t.Sample(time, &q, &qd, &qdd);
            return py::make_tuple(q, qd, qdd);
          },
          py::arg("t"), "(q, qd, qdd) at time t (clamped to [0, duration]).");
  m.def("time_parameterize", &TimeParameterize, py::arg("path"), py::arg("velocity_limits"),
        py::arg("acceleration_limits"),
        "Times a path of joint positions so that it starts and ends at rest within the limits.");

  // ------------------------------------------------------------------ controllers
  py::enum_<ControllerState>(m, "ControllerState", "Where a controller stands.")
      .value("IDLE", ControllerState::kIdle)
      .value("RUNNING", ControllerState::kRunning)
      .value("REACHED", ControllerState::kReached)
      .value("FAILED", ControllerState::kFailed);

  py::class_<ControllerStatus>(m, "ControllerStatus")
      .def(py::init<>())
      .def_readwrite("state", &ControllerStatus::state)
      .def_readwrite("message", &ControllerStatus::message)
      .def("__repr__", [](const ControllerStatus& s) {
        return std::string("ControllerStatus(") + ControllerStateName(s.state) +
               (s.message.empty() ? "" : ", '" + s.message + "'") + ")";
      });

  py::class_<JointControllerOptions>(m, "JointControllerOptions",
                                     "Common settings of the joint controllers.")
      .def(py::init<>())
      .def_readwrite("control_rate", &JointControllerOptions::control_rate, "Hz")
      .def_readwrite("gravity_compensation", &JointControllerOptions::gravity_compensation)
      .def_readwrite("stiffness", &JointControllerOptions::stiffness)
      .def_readwrite("damping", &JointControllerOptions::damping)
      .def_readwrite("force_limit", &JointControllerOptions::force_limit)
      .def_readwrite("position_tolerance", &JointControllerOptions::position_tolerance)
      .def_readwrite("velocity_tolerance", &JointControllerOptions::velocity_tolerance)
      .def_readwrite("timeout", &JointControllerOptions::timeout, "s");

  using Names = std::vector<std::string>;
  const auto keep_robot = py::keep_alive<1, 2>();
  py::class_<Controller, std::shared_ptr<Controller>>(m, "Controller",
                                                      "Base class of the controllers.")
      .def("get_name", &Controller::GetName)
      .def("set_name", &Controller::SetName, py::arg("name"))
      .def("num_joints", &Controller::NumJoints)
      .def("get_dofs", &Controller::GetDofs)
      .def("get_joint_names", &Controller::GetJointNames)
      .def("get_options", &Controller::GetOptions)
      .def("get_status", &Controller::GetStatus)
      .def_property_readonly("status", &Controller::GetStatus)
      .def("get_robot", &Controller::GetRobot)
      .def("period", &Controller::Period, "Physics steps between two updates.")
      .def("update", &Controller::Update)
      .def("get_qpos", &Controller::GetQpos)
      .def("get_qvel", &Controller::GetQvel);

  py::class_<JointEffortController, Controller, std::shared_ptr<JointEffortController>>(
      m, "JointEffortController", "Joint efforts (clamped to force_limit) plus compensation.")
      .def(py::init<const Articulation&, const Names&, const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints") = Names(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def("set_target", &JointEffortController::SetTarget, py::arg("effort"));

  py::class_<JointPositionController, Controller, std::shared_ptr<JointPositionController>>(
      m, "JointPositionController", "PD position control through the joints' drives.")
      .def(py::init<const Articulation&, const Names&, const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints") = Names(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def("set_target", &JointPositionController::SetTarget, py::arg("q"))
      .def("get_target", &JointPositionController::GetTarget);

  py::class_<JointVelocityController, Controller, std::shared_ptr<JointVelocityController>>(
      m, "JointVelocityController", "Velocity control through the joints' drives.")
      .def(py::init<const Articulation&, const Names&, const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints") = Names(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def("set_target", &JointVelocityController::SetTarget, py::arg("qd"));

  py::class_<JointTrajectoryController, Controller, std::shared_ptr<JointTrajectoryController>>(
      m, "JointTrajectoryController", "Follows a JointTrajectory with PD and feed-forward.")
      .def(py::init<const Articulation&, const Names&, const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints") = Names(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def_readwrite("path_tolerance", &JointTrajectoryController::path_tolerance)
      .def("set_trajectory", &JointTrajectoryController::SetTrajectory, py::arg("trajectory"))
      .def("set_path", &JointTrajectoryController::SetPath, py::arg("path"),
           py::arg("velocity_limits"), py::arg("acceleration_limits"))
      .def("get_trajectory", &JointTrajectoryController::GetTrajectory);

  py::enum_<ControlFrame>(m, "ControlFrame", "Frame of end-effector targets.")
      .value("WORLD", ControlFrame::kWorld)
      .value("BASE", ControlFrame::kBase);

  py::class_<EndEffectorController, Controller, std::shared_ptr<EndEffectorController>>(
      m, "EndEffectorController", "Pose or twist targets of a frame on a link, through IK.")
      .def(py::init<const Articulation&, const Names&, const std::string&, const Pose&,
                    const JointControllerOptions&>(),
           py::arg("robot"), py::arg("joints"), py::arg("ee_link"), py::arg("tcp") = Pose(),
           py::arg("options") = JointControllerOptions(), keep_robot)
      .def_readwrite("ik", &EndEffectorController::ik)
      .def_readwrite("max_linear_speed", &EndEffectorController::max_linear_speed, "m/s")
      .def_readwrite("max_angular_speed", &EndEffectorController::max_angular_speed, "rad/s")
      .def_readwrite("position_tolerance", &EndEffectorController::position_tolerance, "m")
      .def_readwrite("rotation_tolerance", &EndEffectorController::rotation_tolerance, "rad")
      .def("set_target_pose", &EndEffectorController::SetTargetPose, py::arg("target"),
           py::arg("frame") = ControlFrame::kWorld)
      .def("set_target_twist", &EndEffectorController::SetTargetTwist, py::arg("twist"),
           py::arg("frame") = ControlFrame::kWorld,
           "twist: (6,) linear (m/s) and angular (rad/s) velocity, held until changed.")
      .def("get_end_effector_pose", &EndEffectorController::GetEndEffectorPose);

  py::class_<ControlLoop>(m, "ControlLoop",
                          "Steps a scene and updates controllers every period() steps.")
      .def(py::init<Scene*>(), py::arg("scene"), py::keep_alive<1, 2>())
      .def("add", &ControlLoop::Add, py::arg("controller"), py::keep_alive<1, 2>())
      .def("remove", &ControlLoop::Remove, py::arg("controller"))
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
      .def("get_scene", &ControlLoop::GetScene, py::return_value_policy::reference);

  // ------------------------------------------------------------------ IMU
  py::class_<ImuReading>(m, "ImuReading", "What an IMU reads, in its own frame.")
      .def(py::init<>())
      .def_readwrite("orientation", &ImuReading::orientation, "quaternion w, x, y, z (world)")
      .def_readwrite("linear_acceleration", &ImuReading::linear_acceleration,
                     "proper acceleration (m/s^2): +9.81 up at rest")
      .def_readwrite("angular_velocity", &ImuReading::angular_velocity, "rad/s")
      .def_readwrite("time", &ImuReading::time, "s");

  py::class_<Imu>(m, "Imu", "An IMU fixed to a link or an actor at local_pose.")
      .def(py::init<const Link&, const Pose&>(), py::arg("link"), py::arg("local_pose") = Pose(),
           py::keep_alive<1, 2>())
      .def(py::init<const Actor&, const Pose&>(), py::arg("actor"), py::arg("local_pose") = Pose(),
           py::keep_alive<1, 2>())
      .def("read", &Imu::Read);
}

}  // namespace partsim::python
