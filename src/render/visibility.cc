// Which moving parts of an object no camera sees, from segmentation in ten views around it.
#include "partsim/render/visibility.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "partsim/core/error.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/scene_render.h"

namespace partsim {

std::vector<std::string> FindHiddenMovingLinks(Scene& scene, const Articulation& art,
                                               const std::string& backend, int image_size) {
  // the object's extent from its links' rest positions and shapes' offsets
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (const Link& l : art.GetLinks()) {
    Pose X = l.GetPose();
    for (const VisualShape& v : l.GetDesc().visuals) {
      if (!v.mesh) continue;
      for (const auto& p : v.mesh->vertices) {
        Eigen::Vector3d w = X.Transform(v.pose.Transform(p.cast<double>()));
        lo = lo.cwiseMin(w);
        hi = hi.cwiseMax(w);
      }
    }
  }
  if (lo.x() > hi.x()) throw Error("the object has no mesh visuals");
  Eigen::Vector3d centre = 0.5 * (lo + hi);
  double radius = std::max(0.5 * (hi - lo).norm(), 0.02);
  const double fovy = 0.8;
  double distance = radius / std::sin(0.5 * fovy) * 1.05;
  SetRenderBackend(scene, backend);
  AddDirectionalLight(scene, Eigen::Vector3d(-0.3, 0.4, -1), Eigen::Vector3f(1, 1, 1));
  std::vector<Camera> cams;
  // five views around from above (front first: the object's front faces world -y), four
  // around from below (wheels, undersides), one from the top
  std::vector<Eigen::Vector3d> dirs;
  auto around = [&](int n, double pitch, double yaw0) {
    for (int i = 0; i < n; ++i) {
      double yaw = yaw0 + i * 2 * M_PI / n;
      dirs.emplace_back(std::cos(yaw) * std::cos(pitch), std::sin(yaw) * std::cos(pitch),
                        std::sin(pitch));
    }
  };
  around(5, 0.45, -M_PI / 2);
  around(4, -0.5, -M_PI / 4);
  dirs.push_back(Eigen::Vector3d(0.01, -0.3, 1.0).normalized());
  for (size_t i = 0; i < dirs.size(); ++i) {
    const Eigen::Vector3d& dir = dirs[i];
    Eigen::Vector3d eye = centre + distance * dir;
    Camera cam = AddCamera(scene, "quality_" + std::to_string(i), image_size, image_size, fovy,
                           0.01, 10 * distance + 1);
    cam.SetLocalPose(CameraLookAt(eye, centre));
    cams.push_back(cam);
  }
  UpdateRender(scene);
  std::set<uint32_t> seen;
  for (Camera& cam : cams) {
    cam.TakePicture();
    const std::vector<uint32_t>& seg = cam.GetUintPicture("Segmentation");
    for (size_t p = 1; p < seg.size(); p += 2) seen.insert(seg[p]);
  }
  for (Camera& cam : cams) RemoveCamera(scene, cam);
  // map entity ids to links of this articulation
  std::vector<std::string> hidden;
  std::vector<RenderEntityInfo> entities = GetRenderEntities(scene);
  for (const Joint& j : art.GetActiveJoints()) {
    int link = j.GetChildLink().GetIndex();
    for (const RenderEntityInfo& e : entities) {
      if (!e.is_link || e.articulation_id != art.GetId() || e.link_index != link) continue;
      if (!seen.count(e.id) && !art.GetLink(link).GetDesc().visuals.empty())
        hidden.push_back(e.name);
    }
  }
  return hidden;
}

std::function<std::vector<std::string>(Scene&, const Articulation&)> HiddenMovingLinksFinder(
    const std::string& backend, int image_size) {
  return [backend, image_size](Scene& scene, const Articulation& object) {
    return FindHiddenMovingLinks(scene, object, backend, image_size);
  };
}

}  // namespace partsim
