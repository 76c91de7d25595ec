// Cameras: SAPIEN's scene.add_camera / update_render / take_picture / get_picture, on either
// rendering backend.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"

namespace partsim {

/// Picture names accepted by Camera::GetPicture* (SAPIEN's names).
/// "Color" (h x w x 4 float), "Albedo" (h x w x 4 float), "Normal" (h x w x 4 float),
/// "Position" (h x w x 4 float), "Segmentation" (h x w x 2 uint32).
bool IsFloatPictureName(const std::string& name);

/// The PictureOutput bit of a picture name ("Color" -> kColor, ...); throws partsim::Error naming
/// `name` when it names no picture.
unsigned PictureOutputFromName(const std::string& name);

/// Handle to a camera of a scene. A camera sits in the world, or is mounted on an actor or a link
/// and moves with it. Its pose uses x forward, y left, z up.
class Camera {
 public:
  Camera() = default;
  Camera(Scene* scene, int id) : scene_(scene), id_(id) {}

  int GetId() const { return id_; }
  const std::string& GetName() const;
  int GetWidth() const;
  int GetHeight() const;
  double GetNear() const;
  double GetFar() const;
  /// Near and far clipping distances (m), 0 < near < far.
  void SetNearFar(double near, double far);
  /// Vertical field of view (rad); fx = fy, principal point at the image centre.
  void SetFovy(double fovy);
  double GetFovy() const;
  double GetFovx() const;
  /// Intrinsics in pixels (OpenCV convention).
  void SetIntrinsics(double fx, double fy, double cx, double cy);
  /// 3x3 OpenCV intrinsic matrix K.
  Eigen::Matrix3d GetIntrinsicMatrix() const;
  /// 3x4 [R | t] mapping world points into the OpenCV camera frame (x right, y down, z forward).
  Eigen::Matrix<double, 3, 4> GetExtrinsicMatrix() const;
  /// 4x4 model matrix: OpenGL camera frame (x right, y up, z backward) to world.
  Eigen::Matrix4d GetModelMatrix() const;
  /// 4x4 OpenGL projection matrix built from K, near and far.
  Eigen::Matrix4d GetProjectionMatrix() const;

  /// World pose X_WC (x forward, y left, z up); for a mounted camera, from the mount's pose at
  /// the last UpdateRender(scene).
  Pose GetPose() const;
  /// For a free camera, its world pose; for a mounted one, its pose in the mount's frame.
  void SetLocalPose(const Pose& pose);
  /// Points the camera from `eye` at `target` with its z as close to `up` as possible
  /// (CameraLookAt), all in the world frame for a free camera and in the mount's frame for a
  /// mounted one: SetLocalPose(CameraLookAt(eye, target, up)). Throws partsim::Error naming the
  /// camera when eye and target coincide, up is zero or a value is not finite.
  void LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
              const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());
  Pose GetLocalPose() const;
  /// Mounts the camera on an actor or a link of its scene, or frees it (ClearParent). With
  /// `keep_pose` the camera stays where it is in the world (its local pose is recomputed);
  /// otherwise its local pose is kept and now counts in the new parent's frame.
  void SetParent(const Actor& parent, bool keep_pose);
  void SetParent(const Link& parent, bool keep_pose);
  void ClearParent(bool keep_pose);

  /// Renders the scene as of the last UpdateRender(scene) with the scene's backend.
  /// `outputs` (PictureOutput bits, at least one) names the outputs to render; the others stay
  /// empty and asking for them (GetFloatPicture, GetDepth, ...) throws. Color and Position alone
  /// take the rasterizer's faster forward pass.
  void TakePicture(unsigned outputs = kAllOutputs);
  /// All outputs of the last picture; throws if none was taken.
  const Picture& GetPictureData() const;
  /// The last picture, shared: it stays valid (and unchanged) after later TakePicture calls,
  /// which then render into a new Picture. Python's numpy views hold this. Throws if none.
  std::shared_ptr<const Picture> GetSharedPicture() const;
  /// One float output by name ("Color", "Albedo", "Normal", "Position"): h x w x 4 values.
  /// Throws when the last picture did not render it.
  const std::vector<float>& GetFloatPicture(const std::string& name) const;
  /// "Segmentation": h x w x 2 (visual id, entity id).
  const std::vector<uint32_t>& GetUintPicture(const std::string& name) const;
  /// Colour as 8-bit RGBA (h x w x 4), sRGB-encoded.
  std::vector<uint8_t> GetColorRGBA8() const;
  /// Depth in metres (h x w), 0 where nothing was hit.
  std::vector<float> GetDepth() const;

  /// What the backends receive.
  CameraParams GetParams() const;
  Scene* GetScene() const { return scene_; }

 private:
  Scene* scene_ = nullptr;
  int id_ = -1;
};

/// A scene-wide render id and what it names: an actor, or a link of an articulation.
struct RenderEntityInfo {
  uint32_t id = 0;
  bool is_link = false;
  std::string name;  ///< actor or link name
  int actor_id = -1;
  int articulation_id = -1;
  int link_index = -1;
  std::string articulation_name;
  std::string semantic_label;  ///< the link's part label, "" if none
};

/// A scene-wide visual id and what it names.
struct RenderVisualInfo {
  uint32_t id = 0;
  uint32_t entity_id = 0;
  std::string name;  ///< the visual's name (e.g. a PartNet-Mobility part "handle-15")
};

/// TakePicture of each camera (all of one scene), the pictures rendered together by the scene's
/// backend (RenderBackend::RenderMany: the rasterizer uploads the world once and overlaps the
/// read-back of one picture with the drawing of the next); each picture is the one TakePicture
/// would give. Throws partsim::Error naming a camera of another scene, or what Render throws
/// (naming the camera's index).
void TakePictures(const std::vector<Camera>& cameras, unsigned outputs = kAllOutputs);

}  // namespace partsim
