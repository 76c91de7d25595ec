// Joint trajectories: timed waypoints followed with interpolation, and time parameterisation of a
// path under velocity and acceleration limits.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace partsim {

/// A trajectory_msgs/JointTrajectory: waypoints with times from its start. Velocities and
/// accelerations may be empty (then they are derived: cubic spline through the positions).
struct JointTrajectory {
  std::vector<double> times;                   ///< s, strictly increasing, times[0] >= 0
  std::vector<Eigen::VectorXd> positions;      ///< one per time
  std::vector<Eigen::VectorXd> velocities;     ///< empty or one per time
  std::vector<Eigen::VectorXd> accelerations;  ///< empty or one per time

  /// Throws partsim::Error naming the waypoint at fault (sizes, times, NaN).
  void Validate(int dof) const;
  double Duration() const;
  /// Interpolated position, velocity and acceleration at time t (clamped to [0, Duration()]):
  /// quintic between waypoints with positions, velocities and accelerations; cubic when only
  /// velocities are given; a C2 cubic spline, at rest at both ends, when only positions are
  /// given. Before times[0] it holds positions[0].
  void Sample(double t, Eigen::VectorXd* q, Eigen::VectorXd* qd = nullptr,
              Eigen::VectorXd* qdd = nullptr) const;
};

/// A JointTrajectory made ready to be sampled many times, as a controller samples it at every
/// step: the polynomial of each segment is computed once (for a trajectory of positions only,
/// that includes the clamped spline through all of them), so that Sample costs a binary search
/// and one polynomial whatever the number of waypoints. JointTrajectory::Sample fits the spline
/// again at every call. The values are exactly JointTrajectory::Sample's.
class TrajectorySampler {
 public:
  /// Samples an empty trajectory: Sample throws.
  TrajectorySampler() = default;
  /// Throws partsim::Error when `trajectory` has no waypoints or positions for fewer or more
  /// times (JointTrajectory::Validate checks the rest).
  explicit TrajectorySampler(JointTrajectory trajectory);

  const JointTrajectory& trajectory() const { return trajectory_; }
  /// JointTrajectory::Sample of the trajectory.
  void Sample(double t, Eigen::VectorXd* q, Eigen::VectorXd* qd = nullptr,
              Eigen::VectorXd* qdd = nullptr) const;

 private:
  JointTrajectory trajectory_;
  /// Per pair of consecutive waypoints, the coefficients of its polynomial in the time since the
  /// first of them, ascending powers.
  std::vector<std::array<Eigen::VectorXd, 6>> segments_;
};

/// Times a path of joint positions (no times) so that it starts and ends at rest and no joint
/// exceeds its velocity or acceleration limit anywhere along the interpolated trajectory
/// (checked by sampling). Throws partsim::Error on fewer than one waypoint, sizes that differ,
/// or limits that are not positive.
JointTrajectory TimeParameterize(const std::vector<Eigen::VectorXd>& path,
                                 const Eigen::VectorXd& velocity_limits,
                                 const Eigen::VectorXd& acceleration_limits);

}  // namespace partsim
