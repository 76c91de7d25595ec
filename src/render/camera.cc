// Camera handles: intrinsics, poses and matrices, and pictures taken with the scene's backend.
#include "partsim/render/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "partsim/core/check.h"
#include "partsim/core/constants.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"
#include "render/render_state.h"

namespace partsim {

using internal::CameraEntry;
using internal::RenderOf;

namespace {

CameraEntry& Entry(Scene* scene, int id) {
  if (!scene) throw Error("empty camera handle: it does not belong to a scene");
  for (auto& c : RenderOf(*scene).cameras)
    if (c.id == id) return c;
  throw Error("camera " + std::to_string(id) + " does not exist (it was removed)");
}

const Picture& PictureOf(const CameraEntry& c) {
  if (!c.picture)
    throw Error("camera '" + c.name + "': no picture yet (call take_picture() first)");
  return *c.picture;
}

// the last picture, checked to hold output `bit` (named `name`)
const Picture& PictureWith(const CameraEntry& c, unsigned bit, const char* name) {
  const Picture& p = PictureOf(c);
  if (!(p.outputs & bit))
    throw Error("camera '" + c.name + "': picture '" + name +
                "' was not taken: TakePicture was asked for " + PictureOutputNames(p.outputs));
  return p;
}

constexpr std::pair<unsigned, const char*> kOutputNames[] = {{kColor, "Color"},
                                                             {kAlbedo, "Albedo"},
                                                             {kNormal, "Normal"},
                                                             {kPosition, "Position"},
                                                             {kSegmentation, "Segmentation"}};

}  // namespace

std::string PictureOutputNames(unsigned outputs) {
  std::string names;
  for (const auto& [bit, name] : kOutputNames) {
    if (!(outputs & bit)) continue;
    if (!names.empty()) names += ", ";
    names += name;
  }
  return names.empty() ? "none" : names;
}

bool IsFloatPictureName(const std::string& name) {
  return name == "Color" || name == "Albedo" || name == "Normal" || name == "Position";
}

unsigned PictureOutputFromName(const std::string& name) {
  for (const auto& [bit, known] : kOutputNames)
    if (name == known) return bit;
  throw Error("unknown picture name '" + name +
              "' (expected Color, Albedo, Normal, Position or Segmentation)");
}

const std::string& Camera::GetName() const { return Entry(scene_, id_).name; }
int Camera::GetWidth() const { return Entry(scene_, id_).width; }
int Camera::GetHeight() const { return Entry(scene_, id_).height; }
double Camera::GetNear() const { return Entry(scene_, id_).near; }
double Camera::GetFar() const { return Entry(scene_, id_).far; }

void Camera::SetNearFar(double near, double far) {
  CameraEntry& c = Entry(scene_, id_);
  if (!std::isfinite(near) || near <= 0)
    throw Error("camera '" + c.name + "': near must be finite and > 0, got " + FormatNumber(near));
  if (!std::isfinite(far) || far <= near)
    throw Error("camera '" + c.name + "': far must be finite and > near (" + FormatNumber(near) +
                "), got " + FormatNumber(far));
  c.near = near;
  c.far = far;
}

void Camera::SetFovy(double fovy) {
  CameraEntry& c = Entry(scene_, id_);
  if (!std::isfinite(fovy) || fovy <= 0 || fovy >= kPi)
    throw Error("camera '" + c.name + "': fovy must be in (0, pi) radians, got " +
                FormatNumber(fovy));
  Eigen::Matrix3d K = IntrinsicsFromFovy(c.width, c.height, fovy);
  c.fx = K(0, 0);
  c.fy = K(1, 1);
  c.cx = K(0, 2);
  c.cy = K(1, 2);
}

double Camera::GetFovy() const {
  const CameraEntry& c = Entry(scene_, id_);
  return 2 * std::atan(0.5 * c.height / c.fy);
}

double Camera::GetFovx() const {
  const CameraEntry& c = Entry(scene_, id_);
  return 2 * std::atan(0.5 * c.width / c.fx);
}

void Camera::SetIntrinsics(double fx, double fy, double cx, double cy) {
  CameraEntry& c = Entry(scene_, id_);
  std::string what = "camera '" + c.name + "': ";
  if (!std::isfinite(fx) || fx <= 0)
    throw Error(what + "fx must be finite and > 0, got " + FormatNumber(fx));
  if (!std::isfinite(fy) || fy <= 0)
    throw Error(what + "fy must be finite and > 0, got " + FormatNumber(fy));
  if (!std::isfinite(cx)) throw Error(what + "cx must be finite, got " + FormatNumber(cx));
  if (!std::isfinite(cy)) throw Error(what + "cy must be finite, got " + FormatNumber(cy));
  c.fx = fx;
  c.fy = fy;
  c.cx = cx;
  c.cy = cy;
}

Eigen::Matrix3d Camera::GetIntrinsicMatrix() const {
  const CameraEntry& c = Entry(scene_, id_);
  Eigen::Matrix3d K;
  K << c.fx, 0, c.cx,  //
      0, c.fy, c.cy,   //
      0, 0, 1;
  return K;
}

Eigen::Matrix<double, 3, 4> Camera::GetExtrinsicMatrix() const {
  // X_OW = (X_WC R_CO)^-1
  Eigen::Matrix4d X_WO = GetPose().ToMatrix();
  X_WO.topLeftCorner<3, 3>() = X_WO.topLeftCorner<3, 3>() * RotationCameraToCv();
  Eigen::Matrix3d R_OW = X_WO.topLeftCorner<3, 3>().transpose();
  Eigen::Matrix<double, 3, 4> Rt;
  Rt.leftCols<3>() = R_OW;
  Rt.col(3) = -R_OW * X_WO.topRightCorner<3, 1>();
  return Rt;
}

Eigen::Matrix4d Camera::GetModelMatrix() const {
  Eigen::Matrix4d X_WG = GetPose().ToMatrix();
  X_WG.topLeftCorner<3, 3>() = X_WG.topLeftCorner<3, 3>() * RotationCameraToGl();
  return X_WG;
}

Eigen::Matrix4d Camera::GetProjectionMatrix() const {
  const CameraEntry& c = Entry(scene_, id_);
  return ProjectionFromIntrinsics(GetIntrinsicMatrix(), c.width, c.height, c.near, c.far);
}

Pose Camera::GetPose() const { return Entry(scene_, id_).X_WC; }

void Camera::LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                    const Eigen::Vector3d& up) {
  Pose pose;
  try {
    pose = CameraLookAt(eye, target, up);
  } catch (const Error& e) {
    throw Error("camera '" + GetName() + "': " + e.what());
  }
  SetLocalPose(pose);
}

void Camera::SetLocalPose(const Pose& pose) {
  CameraEntry& c = Entry(scene_, id_);
  CheckPose("camera '" + c.name + "': pose", pose);
  if (c.mount_actor >= 0 || c.mount_articulation >= 0) {
    // keep the mount where it was at the last UpdateRender: X_WM = X_WC X_MC^-1
    c.X_WC = c.X_WC * c.local_pose.Inverse() * pose;
  } else {
    c.X_WC = pose;
  }
  c.local_pose = pose;
}

Pose Camera::GetLocalPose() const { return Entry(scene_, id_).local_pose; }

namespace {

// remounts camera `c` on a parent now at X_WP (identity for the world)
void Remount(CameraEntry& c, const Pose& X_WP, bool keep_pose) {
  if (keep_pose) {
    c.local_pose = X_WP.Inverse() * c.X_WC;
  } else {
    c.X_WC = X_WP * c.local_pose;
  }
  c.mount_actor = c.mount_articulation = c.mount_link = -1;
}

}  // namespace

void Camera::SetParent(const Actor& parent, bool keep_pose) {
  CameraEntry& c = Entry(scene_, id_);
  if (parent.GetScene() != scene_)
    throw Error("camera '" + c.name + "': set_parent: the actor belongs to another scene");
  Remount(c, parent.GetPose(), keep_pose);  // GetPose throws when the actor was removed
  c.mount_actor = parent.GetId();
}

void Camera::SetParent(const Link& parent, bool keep_pose) {
  CameraEntry& c = Entry(scene_, id_);
  if (parent.GetScene() != scene_)
    throw Error("camera '" + c.name + "': set_parent: the link belongs to another scene");
  // throws when the articulation was removed
  const size_t links = Articulation(scene_, parent.GetArticulationId()).GetLinks().size();
  if (parent.GetIndex() < 0 || parent.GetIndex() >= static_cast<int>(links))
    throw Error("camera '" + c.name + "': set_parent: link index " +
                std::to_string(parent.GetIndex()) + " out of range");
  Remount(c, parent.GetPose(), keep_pose);
  c.mount_articulation = parent.GetArticulationId();
  c.mount_link = parent.GetIndex();
}

void Camera::ClearParent(bool keep_pose) { Remount(Entry(scene_, id_), Pose(), keep_pose); }

namespace {

/// The picture a camera renders into next: its last one, unless that is still viewed (from
/// Python), then a fresh one.
std::shared_ptr<Picture> NextPicture(const CameraEntry& c) {
  std::shared_ptr<Picture> picture =
      c.picture && c.picture.use_count() == 1 ? c.picture : std::make_shared<Picture>();
  picture->width = c.width;
  picture->height = c.height;
  return picture;
}

/// After a backend threw: a half-written picture (Render marks it as holding no outputs) is
/// not the last picture; a refused argument leaves the last picture as it was.
void DropIfHalfWritten(CameraEntry& c, const std::shared_ptr<Picture>& picture) {
  if (picture == c.picture && picture->outputs == 0) c.picture.reset();
}

/// Keeps `picture` as the camera's last one, taken from X_WC; a backend that filled the wrong
/// sizes is a bug: its picture is refused.
void KeepPicture(CameraEntry& c, std::shared_ptr<Picture> picture, unsigned outputs,
                 const Pose& X_WC, const RenderBackend& backend) {
  size_t n = static_cast<size_t>(c.width) * static_cast<size_t>(c.height);
  auto sized = [&](const auto& v, unsigned bit, size_t channels) {
    return !(outputs & bit) || v.size() == channels * n;
  };
  if (picture->width != c.width || picture->height != c.height ||
      !sized(picture->color, kColor, 4) || !sized(picture->albedo, kAlbedo, 4) ||
      !sized(picture->normal, kNormal, 4) || !sized(picture->position, kPosition, 4) ||
      !sized(picture->segmentation, kSegmentation, 2)) {
    if (picture == c.picture) c.picture.reset();
    throw Error("camera '" + c.name + "': backend '" + backend.Name() +
                "' returned a picture of the wrong size");
  }
  c.picture = std::move(picture);
  c.picture_X_WC = X_WC;
}

}  // namespace

void Camera::TakePicture(unsigned outputs) {
  CameraEntry& c = Entry(scene_, id_);
  // the backend's Render checks `outputs` and the camera, for every backend
  internal::RenderState& s = RenderOf(*scene_);
  // the first picture of a scene needs a render world: build it now
  if (!s.render_world_built) UpdateRender(*scene_);
  RenderBackend& backend = GetRenderBackend(*scene_);
  CameraParams params = GetParams();
  std::shared_ptr<Picture> picture = NextPicture(c);
  try {
    backend.Render(s.render_world, params, picture.get(), outputs);
  } catch (...) {
    DropIfHalfWritten(c, picture);
    throw;
  }
  KeepPicture(c, std::move(picture), outputs, params.X_WC, backend);
}

void TakePictures(const std::vector<Camera>& cameras, unsigned outputs) {
  if (cameras.empty()) return;
  Scene* scene = cameras[0].GetScene();
  for (const Camera& camera : cameras)
    if (camera.GetScene() != scene)
      throw Error("TakePictures: camera '" + camera.GetName() +
                  "' belongs to another scene than camera '" + cameras[0].GetName() + "'");
  internal::RenderState& s = RenderOf(*scene);
  if (!s.render_world_built) UpdateRender(*scene);
  RenderBackend& backend = GetRenderBackend(*scene);
  std::vector<CameraParams> params;
  std::vector<std::shared_ptr<Picture>> pictures;
  std::vector<Picture*> out;
  for (size_t i = 0; i < cameras.size(); ++i) {
    params.push_back(cameras[i].GetParams());
    // a camera given twice renders into a fresh picture at its later places
    bool repeated = false;
    for (size_t j = 0; j < i; ++j) repeated = repeated || cameras[j].GetId() == cameras[i].GetId();
    pictures.push_back(repeated ? std::make_shared<Picture>()
                                : NextPicture(Entry(scene, cameras[i].GetId())));
    out.push_back(pictures.back().get());
  }
  try {
    backend.RenderMany(s.render_world, params, out, outputs);
  } catch (...) {
    for (size_t i = 0; i < cameras.size(); ++i)
      DropIfHalfWritten(Entry(scene, cameras[i].GetId()), pictures[i]);
    throw;
  }
  for (size_t i = 0; i < cameras.size(); ++i)
    KeepPicture(Entry(scene, cameras[i].GetId()), pictures[i], outputs, params[i].X_WC, backend);
}

const Picture& Camera::GetPictureData() const { return PictureOf(Entry(scene_, id_)); }

std::shared_ptr<const Picture> Camera::GetSharedPicture() const {
  const CameraEntry& c = Entry(scene_, id_);
  PictureOf(c);
  return c.picture;
}

const std::vector<float>& Camera::GetFloatPicture(const std::string& name) const {
  const CameraEntry& c = Entry(scene_, id_);
  if (!IsFloatPictureName(name))
    throw Error("camera '" + c.name + "': unknown picture name '" + name +
                "' (float pictures: Color, Albedo, Normal, Position; uint32: Segmentation)");
  const Picture& p = PictureWith(c, PictureOutputFromName(name), name.c_str());
  if (name == "Color") return p.color;
  if (name == "Albedo") return p.albedo;
  if (name == "Normal") return p.normal;
  return p.position;
}

const std::vector<uint32_t>& Camera::GetUintPicture(const std::string& name) const {
  const CameraEntry& c = Entry(scene_, id_);
  if (name != "Segmentation")
    throw Error("camera '" + c.name + "': unknown picture name '" + name +
                "' (uint32 pictures: Segmentation; float: Color, Albedo, Normal, Position)");
  return PictureWith(c, kSegmentation, "Segmentation").segmentation;
}

std::vector<uint8_t> Camera::GetColorRGBA8() const {
  return ToRgba8(PictureWith(Entry(scene_, id_), kColor, "Color").color);
}

std::vector<float> Camera::GetDepth() const {
  return DepthImage(PictureWith(Entry(scene_, id_), kPosition, "Position"));
}

CameraParams Camera::GetParams() const {
  const CameraEntry& c = Entry(scene_, id_);
  return MakeCameraParams(c.width, c.height, GetIntrinsicMatrix(), c.near, c.far, c.X_WC);
}

}  // namespace partsim
