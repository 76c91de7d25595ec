// An inertial measurement unit on a link or an actor: orientation, proper linear acceleration and
// angular velocity in the sensor frame, read from the scene's current state.
#pragma once

#include <Eigen/Core>

#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"

namespace partsim {

/// What an IMU reads, in its own frame S.
struct ImuReading {
  Eigen::Vector4d orientation;          ///< quaternion w, x, y, z of S in the world (X_WS.q)
  Eigen::Vector3d linear_acceleration;  ///< proper acceleration in S, m/s^2: +9.81 up at rest
  Eigen::Vector3d angular_velocity;     ///< angular velocity of S in S, rad/s
  double time = 0.0;                    ///< simulation time of the reading, s
};

/// An inertial measurement unit fixed to a link or an actor at `local_pose` (X_BS: the sensor
/// frame S in the body frame B). It holds no state: each Read() reads the scene as it is.
class Imu {
 public:
  /// Throws partsim::Error for an empty or removed link, or a local_pose that is not finite and
  /// unit.
  Imu(const Link& link, const Pose& local_pose = Pose());
  /// Throws partsim::Error for an empty or removed actor, or a local_pose that is not finite and
  /// unit.
  Imu(const Actor& actor, const Pose& local_pose = Pose());
  /// Reading at the current state (after the last step).
  ImuReading Read() const;

 private:
  Scene* scene_;
  bool is_link_;
  int articulation_id_ = -1, link_index_ = -1, actor_id_ = -1;
  Pose local_pose_;
};

}  // namespace partsim
