// Inverse kinematics of an articulation without the physics engine: damped least squares over
// the forward kinematics and Jacobians of KinematicModel (partsim/physics/kinematics.h, included
// here for the users of the robot layer). Vectors of joint positions have one entry per dof, in
// the order of Articulation::GetActiveJoints().
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/description.h"
#include "partsim/physics/kinematics.h"
#include "partsim/physics/scene.h"

namespace partsim {

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
