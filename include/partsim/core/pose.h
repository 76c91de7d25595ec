// Rigid transforms. A Pose X_AB is frame B expressed in frame A: a position p (metres) and a unit
// quaternion q, stored by Eigen as (x, y, z, w) but read and written by partsim's API as w, x, y,
// z.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace partsim {

/// A rigid transform: position `p` (metres) and rotation `q` (unit quaternion).
struct Pose {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();

  Pose() = default;
  Pose(const Eigen::Vector3d& p_in, const Eigen::Quaterniond& q_in) : p(p_in), q(q_in) {}
  explicit Pose(const Eigen::Vector3d& p_in) : p(p_in) {}

  /// From a 4x4 homogeneous matrix; its upper-left block must be a rotation.
  static Pose FromMatrix(const Eigen::Matrix4d& m);
  /// From position and quaternion given as w, x, y, z.
  static Pose FromPQ(const Eigen::Vector3d& p, const Eigen::Vector4d& wxyz);

  /// Composition: X_AC = X_AB * X_BC.
  Pose operator*(const Pose& other) const { return Pose(p + q * other.p, q * other.q); }
  /// Inverse: X_BA from X_AB.
  Pose Inverse() const {
    Eigen::Quaterniond qi = q.conjugate();
    return Pose(-(qi * p), qi);
  }
  /// Maps a point expressed in B to A.
  Eigen::Vector3d Transform(const Eigen::Vector3d& x) const { return p + q * x; }
  /// 4x4 homogeneous matrix.
  Eigen::Matrix4d ToMatrix() const;
  /// Quaternion as w, x, y, z.
  Eigen::Vector4d Wxyz() const { return {q.w(), q.x(), q.y(), q.z()}; }
  /// True when p and q hold only finite numbers and q has unit norm (within 1e-3).
  bool IsValid() const;
  /// "Pose([x, y, z], [w, x, y, z])", each number as FormatNumber writes it: the shortest text
  /// that reads back to the same double (0.1, 1e-07, 0.30000000000000004).
  std::string ToString() const;
};

}  // namespace partsim
