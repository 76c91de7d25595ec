// Small worlds and a test backend shared by the render tests.
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"

namespace partsim::testing {

/// A visual shape of the given type and pose with a name and a colour.
inline VisualShape MakeVisual(ShapeType type, const Pose& pose, const std::string& name) {
  VisualShape v;
  v.type = type;
  v.pose = pose;
  v.half_size = Eigen::Vector3d(0.1, 0.2, 0.3);
  v.radius = 0.05;
  v.half_length = 0.1;
  v.name = name;
  v.material.base_color = Eigen::Vector4f(0.2f, 0.4f, 0.6f, 1.0f);
  return v;
}

/// A two-link articulation "lamp": a fixed base ("base", label "body") and an arm ("arm", label
/// "lid") on a revolute joint about z at (0, 0, 0.5); each link has two visuals.
inline Articulation AddLamp(Scene& scene) {
  ArticulationDesc desc;
  desc.name = "lamp";
  desc.fix_root = true;
  desc.root_pose = Pose(Eigen::Vector3d(0.3, -0.2, 0.0));
  LinkDesc base;
  base.name = "base";
  base.semantic_label = "body";
  base.collisions.push_back(CollisionShape());
  base.visuals.push_back(MakeVisual(ShapeType::kBox, Pose(Eigen::Vector3d(0, 0, 0.2)), "foot"));
  base.visuals.push_back(
      MakeVisual(ShapeType::kCylinder, Pose(Eigen::Vector3d(0, 0, 0.4)), "post"));
  LinkDesc arm;
  arm.name = "arm";
  arm.semantic_label = "lid";
  arm.parent = 0;
  arm.joint.name = "hinge";
  arm.joint.type = JointType::kRevolute;
  arm.joint.lower = -3;
  arm.joint.upper = 3;
  // joint x axis along world z
  Eigen::Quaterniond x_to_z(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()));
  arm.joint.pose_in_parent = Pose(Eigen::Vector3d(0, 0, 0.5), x_to_z);
  arm.joint.pose_in_child = Pose(Eigen::Vector3d::Zero(), x_to_z);
  CollisionShape c;
  c.half_size = Eigen::Vector3d(0.2, 0.02, 0.02);
  c.pose = Pose(Eigen::Vector3d(0.2, 0, 0));
  arm.collisions.push_back(c);
  arm.visuals.push_back(MakeVisual(ShapeType::kCapsule, Pose(Eigen::Vector3d(0.2, 0, 0)), "bar"));
  arm.visuals.push_back(MakeVisual(
      ShapeType::kSphere,
      Pose(Eigen::Vector3d(0.4, 0, 0),
           Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()))),
      "bulb"));
  desc.links = {base, arm};
  return scene.AddArticulation(desc);
}

/// A dynamic box actor "crate" (label "box") with one box visual.
inline Actor AddCrate(Scene& scene, const Eigen::Vector3d& p, const std::string& name = "crate") {
  ActorDesc desc;
  desc.name = name;
  desc.semantic_label = "box";
  desc.type = ActorType::kDynamic;
  desc.pose = Pose(p);
  CollisionShape c;
  c.half_size = Eigen::Vector3d::Constant(0.1);
  desc.collisions.push_back(c);
  VisualShape v = MakeVisual(ShapeType::kBox, Pose(Eigen::Vector3d(0, 0, 0.05)), "lid_panel");
  v.half_size = Eigen::Vector3d::Constant(0.1);
  desc.visuals.push_back(v);
  return scene.AddActor(desc);
}

/// A backend that sees, at every pixel (u, v), a surface at depth `depth` metres, with colour
/// `color`, normal facing the camera and ids (7, 3); pixels of the left column see nothing.
class PlaneBackend : public RenderBackend {
 public:
  explicit PlaneBackend(double depth = 2.0, float color = 0.5f) : depth_(depth), color_(color) {}
  std::string Name() const override { return "test-plane"; }
  std::string Device() const override { return "test"; }
  int renders = 0;
  unsigned last_outputs = 0;  ///< `outputs` of the last Render

 protected:
  // fills every output whatever `outputs` asks for (RenderBackend::Render drops the others)
  void DoRender(const RenderWorld& world, const CameraParams& camera, Picture* out,
                unsigned outputs) override {
    ++renders;
    last_outputs = outputs;
    int w = camera.width, h = camera.height;
    size_t n = static_cast<size_t>(w) * h;
    out->width = w;
    out->height = h;
    out->color.assign(4 * n, 0.0f);
    out->albedo.assign(4 * n, 0.0f);
    out->normal.assign(4 * n, 0.0f);
    out->position.assign(4 * n, 0.0f);
    out->segmentation.assign(2 * n, 0u);
    const Eigen::Matrix3d& K = camera.K;
    for (int v = 0; v < h; ++v) {
      for (int u = 1; u < w; ++u) {
        size_t i = static_cast<size_t>(v) * w + u;
        // OpenGL camera frame: x right, y up, z backward
        double x = (u - K(0, 2)) * depth_ / K(0, 0);
        double y = -(v - K(1, 2)) * depth_ / K(1, 1);
        float* pos = &out->position[4 * i];
        pos[0] = static_cast<float>(x);
        pos[1] = static_cast<float>(y);
        pos[2] = static_cast<float>(-depth_);
        pos[3] = static_cast<float>(depth_);
        out->normal[4 * i + 2] = 1.0f;
        for (int k = 0; k < 3; ++k) out->color[4 * i + k] = color_;
        out->color[4 * i + 3] = 1.0f;
        out->segmentation[2 * i] = 7;
        out->segmentation[2 * i + 1] = 3;
      }
    }
  }

 private:
  double depth_;
  float color_;
};

}  // namespace partsim::testing
