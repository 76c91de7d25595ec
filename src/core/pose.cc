#include "partsim/core/pose.h"

#include <cmath>

#include "partsim/core/check.h"

namespace partsim {

Pose Pose::FromMatrix(const Eigen::Matrix4d& m) {
  Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  return Pose(m.topRightCorner<3, 1>(), Eigen::Quaterniond(r).normalized());
}

Pose Pose::FromPQ(const Eigen::Vector3d& p, const Eigen::Vector4d& wxyz) {
  return Pose(p, Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]));
}

Eigen::Matrix4d Pose::ToMatrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = q.normalized().toRotationMatrix();
  m.topRightCorner<3, 1>() = p;
  return m;
}

bool Pose::IsValid() const {
  return p.allFinite() && q.coeffs().allFinite() && std::abs(q.norm() - 1.0) < 1e-3;
}

std::string Pose::ToString() const {
  return "Pose(" + FormatVector(p) + ", " + FormatVector(Wxyz()) + ")";
}

}  // namespace partsim
