// Internals of the tasks: the episode state behind ArticulationTask, and grasp geometry shared by
// the task (ground truth) and the heuristic solvers (perception).
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "partsim/assets/generator.h"
#include "partsim/physics/kinematics.h"
#include "partsim/tasks/tasks.h"

namespace partsim::internal {

constexpr double kMaxLinearSpeed = 1.0;   // m/s
constexpr double kMaxAngularSpeed = 3.0;  // rad/s

/// Ids of the object's links that are task targets (label and a handle).
std::vector<int> TargetLinks(const GeneratedObject& object, TaskType type);
/// The object's PartNet-Mobility folder under asset_dir, written if missing.
std::string EnsureObjectFolder(const GeneratedObject& object, const std::string& asset_dir);
/// TaskOptions::filter_collisions: every pair of links with collision shapes never collides.
void DisableCollisionsWithin(ArticulationDesc& articulation);
/// The box a convex mesh collision shape is, when its vertices are exactly the corners of an
/// axis-aligned box in the shape's frame (a kBox shape, same pose of the volume, material,
/// density, groups and name); nullopt otherwise.
std::optional<CollisionShape> BoxOfMesh(const CollisionShape& shape);
/// TaskOptions::box_primitives: BoxOfMesh for every collision shape of the articulation.
void BoxesForBoxMeshes(ArticulationDesc& articulation);
/// Z-Y-X Euler angles (yaw, pitch, roll) of R nearest to `near`.
Eigen::Vector3d EulerZyx(const Eigen::Matrix3d& R, const Eigen::Vector3d& near);
/// Matrix mapping Euler angle rates to angular velocity.
Eigen::Matrix3d EulerRateMatrix(const Eigen::Vector3d& ypr);

/// A grasp of a handle seen as points: TCP pose with z along -front_normal (approach) and the
/// fingers closing across the handle's long axis; `depth` is how far the handle stands out.
struct HandleGrasp {
  Pose tcp;
  Eigen::Vector3d centre;
  Eigen::Vector3d long_axis;
  double depth = 0.0;
  bool knob = false;
};
/// Grasp of a handle from its points (world), the outward normal of the panel it sits on and a
/// point of that panel's front face. `fingers_vertical_if_round`: for knobs, close the fingers
/// along world z (drawers) or horizontally (doors).
HandleGrasp GraspFromHandlePoints(const std::vector<Eigen::Vector3d>& points,
                                  const Eigen::Vector3d& front_normal, double face_offset,
                                  bool fingers_vertical_if_round);

struct TaskImpl {
  explicit TaskImpl(const TaskOptions& o);
  void Reset(std::uint64_t seed);
  double Progress() const;
  Pose TcpPose() const;
  Eigen::Matrix<double, 6, 1> TcpVelocity() const;
  Eigen::VectorXd ArmJointsFor(const Pose& tcp) const;
  void PlaceGripper(const Pose& tcp, double opening);
  double FingerPosition(double fraction) const;
  void SetTcpTarget(const Pose& target);
  void SetTcpVelocity(const Eigen::Matrix<double, 6, 1>& twist);
  void SetGripper(double fraction);
  double GripperOpening() const;
  bool TouchesTarget() const;
  void ApplyAction(const Eigen::VectorXd& action);
  void StepControl();
  /// Generalized force that cancels gravity on the robot's dofs (what
  /// Articulation::ComputePassiveForce(true, false, false) returns) from the links' centres of
  /// mass and the joints' world frames: the forward kinematics only, no mj_forward (no collision
  /// detection, no constraint solve) as ComputePassiveForce needs.
  Eigen::VectorXd GravityCompensation() const;
  void TakePictures();
  Eigen::VectorXd RobotState() const;
  Eigen::VectorXd RawObservation() const;
  Eigen::VectorXd MobilityObservation() const;
  /// World points of the target's handle meshes (ground truth).
  std::vector<Eigen::Vector3d> HandlePoints() const;
  /// Centre of the target's handle (mean of its mesh vertices), in the world.
  Eigen::Vector3d HandleCentre() const;
  Eigen::Vector3d HandleCentreInLink() const;
  /// Outward normal of the target's front (it faces +x at rest).
  Eigen::Vector3d AverageNormal() const;
  /// Signed distance of the target's front face along AverageNormal (a point on the face, dotted
  /// with the normal).
  double FrontFaceOffset() const;
  Pose GroundTruthGrasp() const;

  TaskOptions options;
  std::shared_ptr<Scene> scene;
  RobotModel robot_model;
  Articulation robot, object;
  std::vector<int> candidates;  // link indices of the object
  std::map<int, uint32_t> entity_ids;
  std::map<int, std::vector<uint32_t>> handle_visuals;
  std::vector<int> arm_dofs, finger_dofs, finger_links;
  int ee_link = -1;
  /// Per robot dof (qpos order): the joint index, whether it turns, and the robot's links moved
  /// by it (the child's subtree) with their total mass.
  struct GravityJoint {
    int joint = -1;
    bool revolute = false;
    std::vector<int> links;
    double mass = 0.0;
  };
  std::vector<GravityJoint> gravity_joints;
  std::vector<double> robot_link_mass;
  std::vector<Eigen::Vector3d> robot_link_com;  ///< centre of mass in the link frame
  std::vector<Pose> robot_joint_in_child;       ///< per robot link: its joint in the link
  /// The robot's forward kinematics: its link poses from its qpos alone (the scene's
  /// kinematics would place every body of the scene).
  std::optional<KinematicModel> robot_kinematics;
  std::vector<Camera> cameras;
  std::optional<Camera> video_camera;  // TaskOptions::video_width
  std::vector<char> initial_state;
  int substeps = 1;
  double cabinet_half_depth = 0, cabinet_half_width = 0, cabinet_height = 0;

  // episode
  int target_link = -1;
  bool closed_at_lower = true;
  double range = 0.0;
  double start_time = 0.0;
  Eigen::Quaterniond rest_orientation = Eigen::Quaterniond::Identity();  // target link at rest
  Eigen::Vector3d handle_centre_in_link = Eigen::Vector3d::Zero();
  Pose tcp_target;
  Eigen::Matrix<double, 6, 1> twist = Eigen::Matrix<double, 6, 1>::Zero();
  bool velocity_mode = false;
  double gripper_fraction = 1.0;
  double last_reward = 0.0;
  bool grasped_once = false;
};

}  // namespace partsim::internal

namespace partsim {
struct ArticulationTask::Impl : internal::TaskImpl {
  using internal::TaskImpl::TaskImpl;
};
}  // namespace partsim
