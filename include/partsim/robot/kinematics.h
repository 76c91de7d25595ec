// Kinematics of an articulation without the physics engine: forward kinematics, Jacobians and
// damped least-squares inverse kinematics over an ArticulationDesc. Vectors of joint positions
// have one entry per dof, in the order of Articulation::GetActiveJoints().
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/description.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// Forward kinematics and Jacobians of a fixed- or free-rooted articulation (the free root is
/// held at `root_pose`). A coupled joint (JointCoupling) has its dof, as in Articulation, but
/// moves as its source dictates (multiplier * q[source] + offset), as Articulation::SetQpos
/// places it: its own entry of q is ignored, its Jacobian column is zero, and its motion adds to
/// its source's column.
class KinematicModel {
 public:
  explicit KinematicModel(const ArticulationDesc& articulation);
  /// The model of an articulation in a scene, with its current root pose.
  static KinematicModel FromArticulation(const Articulation& articulation);

  int Dof() const;
  int NumLinks() const;
  /// Index of a link by name; throws partsim::Error naming the missing link.
  int LinkIndex(const std::string& name) const;
  /// Dof index of a joint by name (-1 if it has no dof); throws naming a missing joint.
  int DofIndex(const std::string& joint_name) const;
  /// Lower and upper limits, dof x 2 (+-inf when unlimited).
  Eigen::MatrixX2d Limits() const;
  const Pose& GetRootPose() const;
  void SetRootPose(const Pose& pose);

  /// X_WL of every link for joint positions q (size Dof(); throws naming a wrong size).
  std::vector<Pose> ForwardKinematics(const Eigen::VectorXd& q) const;
  /// X_WL of one link (times `offset`, a frame fixed in the link, e.g. a TCP).
  Pose LinkPose(const Eigen::VectorXd& q, int link, const Pose& offset = Pose()) const;
  /// World-frame geometric Jacobian of the point and frame `offset` on `link`: 6 x dof, rows
  /// (linear velocity; angular velocity).
  Eigen::MatrixXd Jacobian(const Eigen::VectorXd& q, int link, const Pose& offset = Pose()) const;

 private:
  struct Data;
  std::shared_ptr<const Data> data_;
  Pose root_pose_;
};

/// Options of InverseKinematics.
struct IkOptions {
  Pose offset;                       ///< frame on the link to place (e.g. the TCP)
  double position_tolerance = 1e-4;  ///< m
  double rotation_tolerance = 1e-3;  ///< rad
  int max_iterations = 200;
  double damping = 1e-2;       ///< lambda of damped least squares
  double max_step = 0.2;       ///< largest joint change per iteration (rad or m)
  bool position_only = false;  ///< ignore the orientation of the target
  std::vector<bool> active;    ///< dofs IK may move (empty: all)
  int restarts = 4;            ///< random restarts inside the limits after a failure
  unsigned seed = 0;           ///< for the restarts
};

/// Result of InverseKinematics.
struct IkResult {
  bool success = false;
  Eigen::VectorXd q;            ///< best joint positions found (within the limits)
  double position_error = 0.0;  ///< m, at q
  double rotation_error = 0.0;  ///< rad, at q
  int iterations = 0;
  std::string message;  ///< why it failed
};

/// Joint positions that put `offset` on `link` at world pose `target`, starting from `q_init`,
/// by damped least squares with joint limits enforced at every iteration. Returns
/// success = false (and the closest q found) when the target is out of reach. Throws
/// partsim::Error for a bad link, a q_init of the wrong size, or a non-finite target.
IkResult InverseKinematics(const KinematicModel& model, int link, const Pose& target,
                           const Eigen::VectorXd& q_init, const IkOptions& options = IkOptions());

/// Position and rotation error (m, rad) between two poses, as a 6-vector (world frame):
/// (p_target - p; axis-angle of R_target R^T).
Eigen::Matrix<double, 6, 1> PoseError(const Pose& current, const Pose& target);

}  // namespace partsim
