// Python bindings: Robot models and URDF writing.
#include <pybind11/stl.h>

#include "bindings.h"
#include "partsim/robot/robots.h"

namespace partsim::python {

void BindRobots(py::module_& m) {
  py::class_<RobotModel>(m, "RobotModel",
                         "A robot: its articulation and what controllers and tasks need to know "
                         "about it. The TCP frame has z along the approach direction and y along "
                         "the direction in which the fingers open. List attributes are copies: "
                         "assign a whole list to change them.")
      .def(py::init<>())
      .def_readwrite("articulation", &RobotModel::articulation,
                     "ArticulationDesc of the robot (load it with Scene.add_articulation).")
      .def_readwrite("arm_joints", &RobotModel::arm_joints,
                     "Joints that move the hand, base to tip.")
      .def_readwrite("gripper_joints", &RobotModel::gripper_joints,
                     "Finger joints (prismatic, 0 = closed).")
      .def_readwrite("ee_link", &RobotModel::ee_link, "Name of the link that carries the hand.")
      .def_readwrite("tcp_in_ee", &RobotModel::tcp_in_ee, "TCP frame in the ee_link frame.")
      .def_readwrite("gripper_open", &RobotModel::gripper_open,
                     "Finger joint position when fully open (m).")
      .def_readwrite("gripper_closed", &RobotModel::gripper_closed,
                     "Finger joint position when closed (m).")
      .def_readwrite("arm_velocity_limits", &RobotModel::arm_velocity_limits,
                     "rad/s or m/s, one per arm joint.")
      .def_readwrite("arm_effort_limits", &RobotModel::arm_effort_limits,
                     "N m or N, one per arm joint.")
      .def_readwrite("home", &RobotModel::home, "A comfortable arm configuration.")
      .def("__repr__", [](const RobotModel& r) {
        return "<RobotModel '" + r.articulation.name + "': " + std::to_string(r.arm_joints.size()) +
               " arm joints, " + std::to_string(r.gripper_joints.size()) + " finger joints>";
      });

  py::class_<FlyingGripperOptions>(m, "FlyingGripperOptions", "Options of the flying gripper.")
      .def(py::init<>())
      .def_readwrite("name", &FlyingGripperOptions::name,
                     "Articulation name (default 'flying_gripper').")
      .def_readwrite("workspace", &FlyingGripperOptions::workspace,
                     "Limits of the x, y, z slides: +-workspace (m).")
      .def_readwrite("finger_travel", &FlyingGripperOptions::finger_travel,
                     "Each finger slides from 0 (closed) to this (m).")
      .def_readwrite("finger_length", &FlyingGripperOptions::finger_length,
                     "Length of each finger (m).")
      .def_readwrite("finger_force", &FlyingGripperOptions::finger_force,
                     "Force limit of each finger drive (N).")
      .def_readwrite("arm_force", &FlyingGripperOptions::arm_force,
                     "Force limit of the x, y, z slides (N).")
      .def_readwrite("arm_torque", &FlyingGripperOptions::arm_torque,
                     "Torque limit of the three rotations (N m).");

  m.def("build_flying_gripper", &BuildFlyingGripper, py::arg("options") = FlyingGripperOptions(),
        "A parallel-jaw hand on x, y, z slides and yaw, pitch, roll joints about its TCP; at q = 0 "
        "the TCP frame equals the root frame.");
  m.def("build_panda", &BuildPanda, py::arg("name") = "panda",
        "The Franka Emika Panda from its modified DH parameters, with a two-finger hand.");
  m.def("articulation_to_urdf", &ArticulationToUrdf, py::arg("articulation"),
        py::arg("mesh_dir") = "",
        "URDF text of an articulation (meshes written as OBJ files into mesh_dir), with "
        "partsim's drives as <partsim:drive> elements.");
  m.def("write_urdf", &WriteUrdf, py::arg("articulation"), py::arg("path"),
        "Writes articulation_to_urdf to path (meshes into <stem>_meshes/ beside it); raises "
        "PartsimError naming a file it cannot write.");
}

}  // namespace partsim::python
