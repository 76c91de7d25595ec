// Grasp geometry of cabinet handles, from points: shared by the tasks (ground-truth meshes) and
// the heuristic solvers (segmented point clouds).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "partsim/core/error.h"
#include "tasks/task_internal.h"

namespace partsim::internal {

namespace {
// The grasp centre sits this far behind the handle's front-most point: the centre of a bar
// (radius 6.5 mm), of a knob's head and of an edge tab's lip.
constexpr double kGraspBehindFront = 0.007;
// A handle whose points spread less than this (standard deviation along the long axis, m) is
// round (a knob).
constexpr double kKnobSpread = 0.02;
}  // namespace

HandleGrasp GraspFromHandlePoints(const std::vector<Eigen::Vector3d>& points,
                                  const Eigen::Vector3d& front_normal, double face_offset,
                                  bool fingers_vertical_if_round) {
  if (points.size() < 3)
    throw Error("grasp: too few handle points (" + std::to_string(points.size()) + ")");
  const Eigen::Vector3d n = front_normal.normalized();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double front = -1e9;
  for (const Eigen::Vector3d& p : points) {
    mean += p;
    front = std::max(front, p.dot(n));
  }
  mean /= static_cast<double>(points.size());
  // in-plane covariance
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    Eigen::Vector3d d = p - mean;
    d -= d.dot(n) * n;
    cov += d * d.transpose();
  }
  cov /= static_cast<double>(points.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  HandleGrasp g;
  g.long_axis = es.eigenvectors().col(2);
  g.knob = std::sqrt(std::max(0.0, es.eigenvalues()[2])) < kKnobSpread;
  g.depth = front - face_offset;
  double grasp_depth = std::max(0.5 * g.depth, g.depth - kGraspBehindFront);
  g.centre = mean - (mean.dot(n) - face_offset - grasp_depth) * n;

  Eigen::Vector3d z = -n;
  Eigen::Vector3d y;
  if (!g.knob) {
    y = n.cross(g.long_axis);
  } else if (fingers_vertical_if_round) {
    y = Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(n) * n;
  } else {
    y = n.cross(Eigen::Vector3d::UnitZ());
  }
  if (y.norm() < 1e-6) y = n.unitOrthogonal();
  y.normalize();
  // keep the fingers' opening direction pointing up or to +y, for repeatable grasps
  if (y.z() < -1e-6 || (std::abs(y.z()) <= 1e-6 && y.y() < 0)) y = -y;
  Eigen::Matrix3d R;
  R.col(1) = y;
  R.col(2) = z;
  R.col(0) = y.cross(z);
  g.tcp = Pose(g.centre, Eigen::Quaterniond(R));
  return g;
}

std::vector<Eigen::Vector3d> TaskImpl::HandlePoints() const {
  Link link = object.GetLink(target_link);
  const Pose X_WL = link.GetPose();
  std::vector<Eigen::Vector3d> out;
  for (const VisualShape& v : link.GetDesc().visuals) {
    if (v.name.rfind("handle-", 0) != 0 || !v.mesh) continue;
    const Pose X = X_WL * v.pose;
    for (const Eigen::Vector3f& p : v.mesh->vertices) out.push_back(X.Transform(p.cast<double>()));
  }
  return out;
}

Eigen::Vector3d TaskImpl::HandleCentreInLink() const {
  // the mean of the handle's vertices, in the target link's frame
  Link link = object.GetLink(target_link);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  size_t n = 0;
  for (const VisualShape& v : link.GetDesc().visuals) {
    if (v.name.rfind("handle-", 0) != 0 || !v.mesh) continue;
    for (const Eigen::Vector3f& p : v.mesh->vertices) sum += v.pose.Transform(p.cast<double>());
    n += v.mesh->vertices.size();
  }
  return n > 0 ? Eigen::Vector3d(sum / static_cast<double>(n)) : Eigen::Vector3d::Zero();
}

Eigen::Vector3d TaskImpl::HandleCentre() const {
  return object.GetLink(target_link).GetPose().Transform(handle_centre_in_link);
}

Eigen::Vector3d TaskImpl::AverageNormal() const {
  // at rest every target faces +x (the cabinet's front); the link turns it with its motion
  Link link = object.GetLink(target_link);
  return link.GetPose().q * (rest_orientation.conjugate() * Eigen::Vector3d::UnitX());
}

double TaskImpl::FrontFaceOffset() const {
  Link link = object.GetLink(target_link);
  const Pose X_WL = link.GetPose();
  const Eigen::Vector3d n = AverageNormal();
  double front = -1e9;
  for (const VisualShape& v : link.GetDesc().visuals) {
    if (v.name.rfind("handle-", 0) == 0 || !v.mesh) continue;
    const Pose X = X_WL * v.pose;
    for (const Eigen::Vector3f& p : v.mesh->vertices)
      front = std::max(front, X.Transform(p.cast<double>()).dot(n));
  }
  return front;
}

Pose TaskImpl::GroundTruthGrasp() const {
  return GraspFromHandlePoints(HandlePoints(), AverageNormal(), FrontFaceOffset(),
                               options.type == TaskType::kPullDrawer)
      .tcp;
}

}  // namespace partsim::internal
