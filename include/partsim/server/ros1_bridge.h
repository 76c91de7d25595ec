// Native ROS 1 interface of a ServedRobot: an optional build (library partsim_ros1, which
// defines PARTSIM_WITH_ROS1) made when Debian's roscpp, actionlib and message packages are
// installed. A roscpp node publishes what the
// rosbridge server publishes, over TCPROS to any ROS 1 node (rospy, rostopic, MoveIt):
//   /clock (rosgraph_msgs/Clock), /joint_states (sensor_msgs/JointState), /tf
//   (tf2_msgs/TFMessage: links and camera optical frames in "world"), /<camera>/image_raw,
//   /<camera>/camera_info, /<camera>/points (sensor_msgs/Image, CameraInfo, PointCloud2), /imu;
// takes commands on /<robot>/joint_{position,velocity,effort}_controller/command
// (std_msgs/Float64MultiArray) and /<robot>/joint_trajectory_controller/command
// (trajectory_msgs/JointTrajectory); serves the action
// /<robot>/joint_trajectory_controller/follow_joint_trajectory
// (control_msgs/FollowJointTrajectory, the action MoveIt sends arm motions to) and the services
// /partsim/pause, /partsim/resume, /partsim/reset (std_srvs/Empty), /partsim/step
// (partsim_msgs/Step) and /<robot>/plan (partsim_msgs/PlanMotion). Message stamps are simulation
// time; with use_sim_time the node sets /use_sim_time so that nodes started afterwards follow
// /clock.
#pragma once

#include <memory>
#include <string>

#include "partsim/server/served_robot.h"

namespace partsim {

struct Ros1Options {
  std::string node_name = "partsim";  ///< the roscpp node's name
  /// Set the /use_sim_time parameter to true at Start (nodes started later follow /clock).
  bool use_sim_time = true;
  double master_timeout = 5.0;  ///< s to wait for the ROS master at Start
};

class Ros1Bridge {
 public:
  /// Serves `robot` (commanded under /<robot name>/...); adds a step callback to its SimServer
  /// (construct before sim->Start()). The robot must outlive the bridge, and the SimServer must
  /// be stopped (and the robot's planning worker closed) before the bridge is destroyed.
  explicit Ros1Bridge(ServedRobot* robot, const Ros1Options& options = {});
  ~Ros1Bridge();
  Ros1Bridge(const Ros1Bridge&) = delete;
  Ros1Bridge& operator=(const Ros1Bridge&) = delete;

  /// Starts the roscpp node (the master named by ROS_MASTER_URI, default
  /// http://localhost:11311) and its callback threads; throws partsim::Error when the master
  /// cannot be reached within master_timeout. One node per process.
  void Start();
  /// Shuts the node down. Idempotent.
  void Stop();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace partsim
