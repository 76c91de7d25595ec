// Kinematics of an articulation from its description, without the physics engine: the dof
// numbering and joint limits, forward kinematics and geometric Jacobians. The scene places
// kinematic articulations with it, the asset readers compute rest poses with it, and robot
// inverse kinematics and planning search over it. Vectors of joint positions have one entry
// per dof, in the order of Articulation::GetActiveJoints().
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/description.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// Link index of every dof of `articulation`: one dof per joint that is not fixed, in link
/// order, a coupled joint (JointCoupling) included. Size dof.
std::vector<int> DofLinks(const ArticulationDesc& articulation);

/// Lower and upper joint limits per dof, dof x 2, metres or radians; -inf and +inf for a
/// continuous joint.
Eigen::MatrixX2d DofLimits(const ArticulationDesc& articulation);

/// Forward kinematics and Jacobians of a fixed- or free-rooted articulation (the free root is
/// held at `root_pose`). A coupled joint (JointCoupling) has its dof, as in Articulation, but
/// moves as its source dictates (multiplier * q[source] + offset), as Articulation::SetQpos
/// places it: its own entry of q is ignored, its Jacobian column is zero, and its motion adds to
/// its source's column.
class KinematicModel {
 public:
  /// The model of a description, its root at `articulation.root_pose`; throws partsim::Error
  /// for a description that Validate rejects.
  explicit KinematicModel(const ArticulationDesc& articulation);
  /// The model of an articulation in a scene, with its current root pose.
  static KinematicModel FromArticulation(const Articulation& articulation);

  int Dof() const;
  int NumLinks() const;
  /// Throws partsim::Error naming `what` unless q has Dof() finite entries.
  void CheckJointPositions(const Eigen::VectorXd& q, const char* what) const;
  /// Throws partsim::IndexError unless 0 <= link < NumLinks().
  void CheckLinkIndex(int link) const;
  /// Index of a link by name; throws partsim::Error naming the missing link.
  int LinkIndex(const std::string& name) const;
  /// Dof index of a joint by name (-1 if it has no dof); throws naming a missing joint.
  int DofIndex(const std::string& joint_name) const;
  /// Lower and upper limits, dof x 2 (+-inf when unlimited), metres or radians.
  Eigen::MatrixX2d Limits() const;
  /// X_WR: the root link R in the world W.
  const Pose& GetRootPose() const;
  /// Sets X_WR (normalised); throws partsim::Error for a pose that is not finite or not unit.
  void SetRootPose(const Pose& pose);

  /// X_WL of every link (NumLinks()) for joint positions q (size Dof(), metres or radians;
  /// throws naming a wrong size or a non-finite entry).
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

}  // namespace partsim
