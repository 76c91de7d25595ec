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
      .def(py::init<>())
      .def_readwrite("time_limit", &PlannerOptions::time_limit, "s of planning")
      .def_readwrite("resolution", &PlannerOptions::resolution,
                     "rad or m: largest joint step between two checked states")
      .def_readwrite("clearance", &PlannerOptions::clearance,
                     "m the arm keeps from the rest of the scene")
      .def_readwrite("seed", &PlannerOptions::seed, "seed of the IK restarts")
      .def_readwrite("algorithm", &PlannerOptions::algorithm,
                     "RRTConnect, RRT, RRTstar, PRM or KPIECE1")
      .def_readwrite("simplify", &PlannerOptions::simplify)
      .def_readwrite("ik_attempts", &PlannerOptions::ik_attempts);

  py::class_<PlanResult>(m, "PlanResult", "What a planning request produced.")
      .def(py::init<>())
      .def_readwrite("success", &PlanResult::success)
      .def_readwrite("message", &PlanResult::message)
      .def_readwrite("path", &PlanResult::path, "joint waypoints, start to goal")
      .def_readwrite("trajectory", &PlanResult::trajectory, "the path timed from 0")
      .def_readwrite("planning_time", &PlanResult::planning_time, "s")
      .def("__bool__", [](const PlanResult& r) { return r.success; });

  py::class_<MotionPlanner>(m, "MotionPlanner",
                            "Collision-free joint paths for some joints of an articulation in "
                            "the current scene (OMPL; collisions checked on a private copy).")
      .def(py::init<const Articulation&, const std::vector<std::string>&, const Eigen::VectorXd&,
                    const Eigen::VectorXd&>(),
           py::arg("arm"), py::arg("joints") = std::vector<std::string>(),
           py::arg("velocity_limits") = Eigen::VectorXd(),
           py::arg("acceleration_limits") = Eigen::VectorXd(), py::keep_alive<1, 2>())
      .def("get_joint_names", &MotionPlanner::GetJointNames)
      .def("get_current_positions", &MotionPlanner::GetCurrentPositions)
      .def("plan_to_joints", &MotionPlanner::PlanToJoints, py::arg("goal"),
           py::arg("options") = PlannerOptions(), py::call_guard<py::gil_scoped_release>(),
           "A path from the current positions to `goal` (one entry per planned joint).")
      .def("plan_to_pose", &MotionPlanner::PlanToPose, py::arg("link"), py::arg("tcp_offset"),
           py::arg("target"), py::arg("options") = PlannerOptions(),
           py::call_guard<py::gil_scoped_release>(),
           "A path that brings frame `tcp_offset` of `link` to world pose `target`.")
      .def(
          "is_state_valid",
          [](MotionPlanner& p, const Eigen::VectorXd& q, double clearance) {
            std::string reason;
            bool ok = p.IsStateValid(q, clearance, &reason);
            return py::make_tuple(ok, reason);
          },
          py::arg("q"), py::arg("clearance") = 0.005,
          "(valid, reason) for planned-joint positions q in the last snapshot.")
      .def("update_snapshot", &MotionPlanner::UpdateSnapshot);
}

}  // namespace partsim::python
