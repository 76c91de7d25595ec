// Placing an articulation on the ground from the bounds of its geometry.
#include <algorithm>
#include <cmath>

#include "partsim/assets/partnet_mobility.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

// Lowest world z of a shape of `type` at X_WS (boxes, spheres, x-aligned capsules and cylinders,
// meshes); +inf for a plane or a shape without geometry.
template <typename Shape>
double LowestZ(const Shape& s, const Pose& X_WS) {
  const Eigen::Matrix3d R = X_WS.q.toRotationMatrix();
  switch (s.type) {
    case ShapeType::kBox:
      return X_WS.p.z() - R.row(2).cwiseAbs().dot(s.half_size);
    case ShapeType::kSphere:
      return X_WS.p.z() - s.radius;
    case ShapeType::kCapsule:
      return X_WS.p.z() - std::abs(R(2, 0)) * s.half_length - s.radius;
    case ShapeType::kCylinder: {
      // the rim's lowest point: the axis end plus the radius across the axis
      const double across = std::sqrt(std::max(0.0, 1.0 - R(2, 0) * R(2, 0)));
      return X_WS.p.z() - std::abs(R(2, 0)) * s.half_length - across * s.radius;
    }
    case ShapeType::kConvexMesh: {
      if (!s.mesh) return kInf;
      double z = kInf;
      for (const Eigen::Vector3f& v : s.mesh->vertices)
        z = std::min(z, X_WS.Transform(v.cast<double>()).z());
      return z;
    }
    case ShapeType::kPlane:
      return kInf;
  }
  return kInf;
}

// How far above the plane the lowest point stands. MuJoCo's contacts are soft and take rounding
// (a few nm) below the plane for a penetration to push out: a drawer of a fixed cabinet that
// touched the ground exactly could not push it out (its slide holds it up), and the contact's
// friction held the drawer shut.
constexpr double kStandClearance = 1e-5;

}  // namespace

Pose StandingRootPose(const Articulation& articulation, double altitude) {
  if (!std::isfinite(altitude)) throw Error("StandingRootPose: altitude must be finite");
  double lowest = kInf;
  for (const Link& link : articulation.GetLinks()) {
    const Pose X_WL = link.GetPose();
    const LinkDesc& desc = link.GetDesc();
    for (const CollisionShape& s : desc.collisions)
      lowest = std::min(lowest, LowestZ(s, X_WL * s.pose));
  }
  if (!std::isfinite(lowest)) {
    for (const Link& link : articulation.GetLinks()) {
      const Pose X_WL = link.GetPose();
      for (const VisualShape& s : link.GetDesc().visuals)
        lowest = std::min(lowest, LowestZ(s, X_WL * s.pose));
    }
  }
  Pose root = articulation.GetRootPose();
  if (!std::isfinite(lowest)) {
    throw Error("StandingRootPose: articulation '" + articulation.GetName() +
                "' has no geometry to stand on");
  }
  root.p.z() += altitude + kStandClearance - lowest;
  return root;
}

void PlaceOnGround(Articulation& articulation, double altitude) {
  articulation.SetRootPose(StandingRootPose(articulation, altitude));
}

}  // namespace partsim
