// Robots built piece by piece with the articulation description: a flying parallel-jaw gripper
// and a 7-joint arm with a two-finger hand from the published Franka Panda kinematic parameters.
// Both can be written out as URDF (WriteUrdf) and read back with the URDF loader.
#pragma once

#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/description.h"

namespace partsim {

/// A robot: its articulation and what controllers and tasks need to know about it.
///
/// Tool frame convention (both robots): the tool centre point (TCP) frame has z along the
/// approach direction (out of the palm, between the fingertips) and y along the direction in
/// which the fingers open; x = y cross z.
struct RobotModel {
  ArticulationDesc articulation;
  std::vector<std::string> arm_joints;      ///< joints that move the hand, base to tip
  std::vector<std::string> gripper_joints;  ///< finger joints (prismatic, 0 = closed)
  std::string ee_link;                      ///< link that carries the hand
  Pose tcp_in_ee;                           ///< TCP frame in the ee_link frame
  double gripper_open = 0.04;               ///< finger joint position when fully open (m)
  double gripper_closed = 0.0;              ///< ... when closed (m)
  std::vector<double> arm_velocity_limits;  ///< rad/s or m/s, one per arm joint
  std::vector<double> arm_effort_limits;    ///< N m or N, one per arm joint
  std::vector<double> home;                 ///< a comfortable arm configuration
};

/// Options of the flying gripper.
struct FlyingGripperOptions {
  std::string name = "flying_gripper";
  double workspace = 5.0;       ///< limits of the x, y, z slides: +-workspace (m)
  double finger_travel = 0.05;  ///< each finger slides from 0 (closed) to this (m)
  double finger_length = 0.06;  ///< (m)
  /// Force limit of each finger drive (N). The drive's stiffness is 5000 N/m: a finger stopped
  /// 12 mm short of its target pushes with this force, one stopped 6 mm short (a 13 mm handle
  /// in the closed hand) with about 30 N.
  double finger_force = 60.0;
  double arm_force = 400.0;  ///< force limit of the x, y, z slides (N)
  double arm_torque = 60.0;  ///< torque limit of the three rotations (N m)
};

/// A parallel-jaw hand that flies freely: a fixed root, three prismatic joints x, y, z along the
/// root's axes, then three revolute joints (yaw about z, pitch about y, roll about x), then the
/// palm ("hand") with two prismatic fingers. At q = 0 the TCP frame equals the root frame. The
/// six arm joints and two fingers carry PD drives sized for a 1 kg hand; controllers add gravity
/// compensation, so the hand floats where it is sent.
RobotModel BuildFlyingGripper(const FlyingGripperOptions& options = FlyingGripperOptions());

/// The Franka Emika Panda built from its published modified Denavit-Hartenberg parameters
/// (Craig's convention), joint limits, velocity and torque limits; links are capsules, the hand a
/// box with two prismatic fingers. Mass properties approximate the published ones.
RobotModel BuildPanda(const std::string& name = "panda");

/// URDF text of an articulation: links with visuals, collisions (primitives; meshes written as
/// OBJ files next to `path` when `path` is given) and inertials, joints with axes, limits,
/// dynamics and mimic tags, and partsim's drive parameters as <partsim:drive> elements that other
/// URDF readers ignore. Reading it back with the URDF loader gives the same kinematics, limits,
/// masses and drives.
std::string ArticulationToUrdf(const ArticulationDesc& articulation,
                               const std::string& mesh_dir = "");
/// Writes ArticulationToUrdf to `path` (mesh files beside it); throws partsim::Error naming the
/// file it cannot write.
void WriteUrdf(const ArticulationDesc& articulation, const std::string& path);

}  // namespace partsim
