// The motion of a frame fixed on a body (an actor or a link): what an IMU, a tracked marker or a
// tool-centre point experiences. Computed from the engine's body accelerations at the current
// state (forward dynamics with contacts and drives, as the next step would see them).
#pragma once

#include <Eigen/Core>

#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// Pose, velocities and accelerations of a frame S fixed on a body, in the world frame W.
struct FrameMotion {
  Pose pose;                         ///< X_WS
  Eigen::Vector3d linear_velocity;   ///< of S's origin, m/s
  Eigen::Vector3d angular_velocity;  ///< rad/s
  /// Proper acceleration of S's origin (what an accelerometer measures: the acceleration minus
  /// gravity; a body at rest on the ground reads +g upwards), m/s^2.
  Eigen::Vector3d linear_acceleration;
  Eigen::Vector3d angular_acceleration;  ///< rad/s^2
  double time = 0.0;                     ///< the scene's time, s
};

/// Motion of the frame `offset` (X_LS, fixed in the link) of a link of a dynamic or kinematic
/// articulation. Throws partsim::Error for an empty or removed handle or a non-finite offset.
FrameMotion ComputeFrameMotion(const Link& link, const Pose& offset = Pose());
/// Motion of the frame `offset` (X_AS, fixed in the actor) of an actor.
FrameMotion ComputeFrameMotion(const Actor& actor, const Pose& offset = Pose());

}  // namespace partsim
