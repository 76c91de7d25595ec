// Python bindings: motion planning (MotionPlanner, PlannerOptions, PlanResult).
//
// Lifetime: a planner keeps the Articulation handle it was built with (and so the scene) alive.
// Planning releases the GIL: it touches only the planner's private copy of the scene.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "partsim/planning/planner.h"

namespace partsim::python {

void BindPlanning(py::module_& m) {
  py::class_<PlannerOptions>(m, "PlannerOptions", "Settings of one planning request.")
      .def(py::init<>(), "The defaults.")
      .def_readwrite("time_limit", &PlannerOptions::time_limit,
                     "Seconds of planning (default 2; simplification gets up to 1 s more).")
      .def_readwrite("resolution", &PlannerOptions::resolution,
                     "Largest joint step between two checked states, rad or m (default 0.01).")
      .def_readwrite("clearance", &PlannerOptions::clearance,
                     "Distance in m the arm keeps from the rest of the scene (default 0.005).")
      .def_readwrite("seed", &PlannerOptions::seed,
                     "Seed of the IK restarts of plan_to_pose (default 0).")
      .def_readwrite("algorithm", &PlannerOptions::algorithm,
                     "OMPL planner: 'RRTConnect' (default), 'RRT', 'RRTstar', 'PRM' or "
                     "'KPIECE1'; another name raises PartsimError.")
      .def_readwrite("simplify", &PlannerOptions::simplify,
                     "Shortcut and smooth the path found (default True).")
      .def_readwrite("ik_attempts", &PlannerOptions::ik_attempts,
                     "plan_to_pose: IK solutions tried, from the start then random (default "
                     "8).");

  py::class_<PlanResult>(m, "PlanResult", "What a planning request produced.")
      .def(py::init<>())
      .def_readwrite("success", &PlanResult::success, "True when a path was found.")
      .def_readwrite("message", &PlanResult::message, "Why it failed ('' on success).")
      .def_readwrite("path", &PlanResult::path,
                     "list of (n,) joint waypoints (rad or m), start to goal, one entry per "
                     "planned joint.")
      .def_readwrite("trajectory", &PlanResult::trajectory,
                     "JointTrajectory: the path timed from 0, at rest at both ends.")
      .def_readwrite("planning_time", &PlanResult::planning_time,
                     "Wall-clock seconds spent, IK and timing included.")
      .def("__bool__", [](const PlanResult& r) { return r.success; });

  py::class_<MotionPlanner>(m, "MotionPlanner",
                            "Collision-free joint paths for some joints of an articulation in "
                            "the current scene (OMPL; collisions checked on a private copy).")
      .def(py::init<const Articulation&, const std::vector<std::string>&, const Eigen::VectorXd&,
                    const Eigen::VectorXd&>(),
           py::arg("arm"), py::arg("joints") = std::vector<std::string>(),
           py::arg("velocity_limits") = Eigen::VectorXd(),
           py::arg("acceleration_limits") = Eigen::VectorXd(), py::keep_alive<1, 2>(),
           "Plans for `joints` of `arm` (one dof each; empty: every active joint). Velocity "
           "(rad/s or m/s) and acceleration (rad/s^2 or m/s^2) limits, one per planned joint, "
           "time the trajectory; empty means 1 and 2. Raises PartsimError naming an unknown "
           "joint, a joint without a dof or a bad limit.")
      .def("get_joint_names", &MotionPlanner::GetJointNames,
           "Names of the planned joints, in the order of goal and path entries.")
      .def("get_current_positions", &MotionPlanner::GetCurrentPositions,
           "Current positions of the planned joints (n,), rad or m.")
      .def("plan_to_joints", &MotionPlanner::PlanToJoints, py::arg("goal"),
           py::arg("options") = PlannerOptions(), py::call_guard<py::gil_scoped_release>(),
           "A PlanResult: a path from the current positions to `goal` (one entry per planned "
           "joint, rad or m), collisions checked against a snapshot of the scene taken now. "
           "Releases the GIL.")
      .def("plan_to_pose", &MotionPlanner::PlanToPose, py::arg("link"), py::arg("tcp_offset"),
           py::arg("target"), py::arg("options") = PlannerOptions(),
           py::call_guard<py::gil_scoped_release>(),
           "A PlanResult: a path that brings frame `tcp_offset` (in the frame of link "
           "`link`, a name) to world pose `target`, through IK solutions (the collision-free "
           "one nearest to the start). Raises PartsimError on an unknown link or a non-finite "
           "target. Releases the GIL.")
      .def(
          "is_state_valid",
          [](MotionPlanner& p, const Eigen::VectorXd& q, double clearance) {
            std::string reason;
            bool ok = p.IsStateValid(q, clearance, &reason);
            return py::make_tuple(ok, reason);
          },
          py::arg("q"), py::arg("clearance") = 0.005,
          "(valid, reason) for planned-joint positions q in the last snapshot.")
      .def("update_snapshot", &MotionPlanner::UpdateSnapshot,
           "Takes a new snapshot of the scene for is_state_valid.");
}

}  // namespace partsim::python
