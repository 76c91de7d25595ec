// The scene's rendering (partsim/render/scene_render.h): cameras, lights, the render world that
// backends draw, and the tables that name segmentation ids.
#include "partsim/render/scene_render.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "partsim/core/check.h"
#include "partsim/core/constants.h"
#include "partsim/physics/observer.h"
#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"
#include "render/render_state.h"

namespace partsim {

using internal::CameraEntry;
using internal::RenderSource;
using internal::RenderState;

namespace {

constexpr int kMaxImageSize = 16384;

// checks what every camera needs; `what` names the call for the message
void CheckCameraArgs(const std::string& what, int width, int height, double fovy, double near,
                     double far) {
  if (width < 1 || width > kMaxImageSize)
    throw Error(what + ": width must be in [1, " + std::to_string(kMaxImageSize) + "], got " +
                std::to_string(width));
  if (height < 1 || height > kMaxImageSize)
    throw Error(what + ": height must be in [1, " + std::to_string(kMaxImageSize) + "], got " +
                std::to_string(height));
  if (!std::isfinite(fovy) || fovy <= 0 || fovy >= kPi)
    throw Error(what + ": fovy must be in (0, pi) radians, got " + FormatNumber(fovy));
  if (!std::isfinite(near) || near <= 0)
    throw Error(what + ": near must be finite and > 0, got " + FormatNumber(near));
  if (!std::isfinite(far) || far <= near)
    throw Error(what + ": far must be finite and > near (" + FormatNumber(near) + "), got " +
                FormatNumber(far));
}

void CheckColor(const std::string& what, const Eigen::Vector3f& c) {
  if (!c.allFinite() || (c.array() < 0).any())
    throw Error(what + ": color must be finite and >= 0, got " + FormatVector(c));
}

Eigen::Vector3d CheckDirection(const std::string& what, const Eigen::Vector3d& d) {
  if (!d.allFinite() || d.norm() < 1e-12)
    throw Error(what + ": direction must be finite and non-zero, got " + FormatVector(d));
  return d.normalized();
}

CameraEntry MakeEntry(int id, const std::string& name, int width, int height, double fovy,
                      double near, double far) {
  double f = 0.5 * height / std::tan(0.5 * fovy);
  CameraEntry c{};
  c.id = id;
  c.name = name;
  c.width = width;
  c.height = height;
  c.fx = c.fy = f;
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  c.near = near;
  c.far = far;
  return c;
}

bool SameMaterial(const RenderMaterial& a, const RenderMaterial& b) {
  return a.base_color == b.base_color && a.roughness == b.roughness && a.metallic == b.metallic &&
         a.diffuse_texture == b.diffuse_texture;
}

// true when two instance lists draw the same meshes with the same materials and ids
bool SameGeometry(const std::vector<RenderInstance>& a, const std::vector<RenderInstance>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].mesh != b[i].mesh || a[i].visual_id != b[i].visual_id ||
        a[i].entity_id != b[i].entity_id || !SameMaterial(a[i].material, b[i].material))
      return false;
  }
  return true;
}

// World pose of a camera's mount; false when the mount no longer exists.
bool MountPose(Scene* scene, const CameraEntry& c, Pose* X_WM) {
  if (c.mount_actor >= 0) {
    if (!HasActor(*scene, c.mount_actor)) return false;
    *X_WM = Actor(scene, c.mount_actor).GetPose();
    return true;
  }
  if (!HasArticulation(*scene, c.mount_articulation)) return false;
  if (c.mount_link >= static_cast<int>(Articulation(scene, c.mount_articulation).GetLinks().size()))
    return false;
  *X_WM = Link(scene, c.mount_articulation, c.mount_link).GetPose();
  return true;
}

bool IsMounted(const CameraEntry& c) { return c.mount_actor >= 0 || c.mount_articulation >= 0; }

}  // namespace

// ---------------------------------------------------------------------------------------------
// the render state attached to each scene

namespace internal {

std::unique_ptr<SceneAttachment> RenderState::CloneFor(Scene&) const {
  auto copy = std::make_unique<RenderState>();
  copy->lights = lights;
  copy->ambient = ambient;
  for (const CameraEntry& cam : cameras) {
    CameraEntry c = cam;
    c.picture.reset();
    c.picture_X_WC = Pose();
    copy->cameras.push_back(std::move(c));
  }
  return copy;
}

RenderState& RenderOf(const Scene& scene) {
  return static_cast<RenderState&>(
      GetAttachment(scene, "render", [] { return std::make_unique<RenderState>(); }));
}

}  // namespace internal

using internal::RenderOf;

// ---------------------------------------------------------------------------------------------
// cameras

Camera AddCamera(Scene& scene, const std::string& name, int width, int height, double fovy,
                 double near, double far) {
  CheckCameraArgs("add_camera '" + name + "'", width, height, fovy, near, far);
  int id = NewEntityId(scene);
  RenderOf(scene).cameras.push_back(MakeEntry(id, name, width, height, fovy, near, far));
  return Camera(&scene, id);
}

Camera AddMountedCamera(Scene& scene, const std::string& name, const Actor& mount,
                        const Pose& local_pose, int width, int height, double fovy, double near,
                        double far) {
  std::string what = "add_mounted_camera '" + name + "'";
  CheckCameraArgs(what, width, height, fovy, near, far);
  CheckPose(what + ": local_pose", local_pose);
  if (mount.GetScene() != &scene) throw Error(what + ": the mount actor belongs to another scene");
  // the pose is known at once, before the first UpdateRender (GetPose throws when removed)
  Pose X_WC = mount.GetPose() * local_pose;
  RenderState& s = RenderOf(scene);
  int id = NewEntityId(scene);
  CameraEntry c = MakeEntry(id, name, width, height, fovy, near, far);
  c.local_pose = local_pose;
  c.mount_actor = mount.GetId();
  c.X_WC = X_WC;
  s.cameras.push_back(std::move(c));
  return Camera(&scene, id);
}

Camera AddMountedCamera(Scene& scene, const std::string& name, const Link& mount,
                        const Pose& local_pose, int width, int height, double fovy, double near,
                        double far) {
  std::string what = "add_mounted_camera '" + name + "'";
  CheckCameraArgs(what, width, height, fovy, near, far);
  CheckPose(what + ": local_pose", local_pose);
  if (mount.GetScene() != &scene) throw Error(what + ": the mount link belongs to another scene");
  // throws when the articulation was removed
  const size_t links = Articulation(&scene, mount.GetArticulationId()).GetLinks().size();
  if (mount.GetIndex() < 0 || mount.GetIndex() >= static_cast<int>(links))
    throw Error(what + ": link index " + std::to_string(mount.GetIndex()) + " out of range");
  Pose X_WC = mount.GetPose() * local_pose;
  RenderState& s = RenderOf(scene);
  int id = NewEntityId(scene);
  CameraEntry c = MakeEntry(id, name, width, height, fovy, near, far);
  c.local_pose = local_pose;
  c.mount_articulation = mount.GetArticulationId();
  c.mount_link = mount.GetIndex();
  c.X_WC = X_WC;
  s.cameras.push_back(std::move(c));
  return Camera(&scene, id);
}

void RemoveCamera(Scene& scene, const Camera& camera) {
  RenderState& s = RenderOf(scene);
  for (auto it = s.cameras.begin(); it != s.cameras.end(); ++it)
    if (it->id == camera.GetId() && camera.GetScene() == &scene) {
      s.cameras.erase(it);
      return;
    }
  throw Error("remove_camera: camera " + std::to_string(camera.GetId()) +
              " does not exist (it was removed, or belongs to another scene)");
}

std::vector<Camera> GetCameras(const Scene& scene) {
  std::vector<Camera> out;
  for (const auto& c : RenderOf(scene).cameras) out.emplace_back(const_cast<Scene*>(&scene), c.id);
  return out;
}

// ---------------------------------------------------------------------------------------------
// lights

void AddDirectionalLight(Scene& scene, const Eigen::Vector3d& direction,
                         const Eigen::Vector3f& color, bool shadow) {
  LightDesc l;
  l.type = LightType::kDirectional;
  l.direction = CheckDirection("add_directional_light", direction);
  CheckColor("add_directional_light", color);
  l.color = color;
  l.shadow = shadow;
  l.name = "directional_" + std::to_string(RenderOf(scene).lights.size());
  RenderOf(scene).lights.push_back(l);
}

void AddPointLight(Scene& scene, const Eigen::Vector3d& position, const Eigen::Vector3f& color) {
  CheckFinite("add_point_light: position", position);
  CheckColor("add_point_light", color);
  LightDesc l;
  l.type = LightType::kPoint;
  l.position = position;
  l.color = color;
  l.name = "point_" + std::to_string(RenderOf(scene).lights.size());
  RenderOf(scene).lights.push_back(l);
}

void AddSpotLight(Scene& scene, const Eigen::Vector3d& position, const Eigen::Vector3d& direction,
                  double inner_angle, double outer_angle, const Eigen::Vector3f& color,
                  bool shadow) {
  CheckFinite("add_spot_light: position", position);
  LightDesc l;
  l.type = LightType::kSpot;
  l.direction = CheckDirection("add_spot_light", direction);
  if (!std::isfinite(outer_angle) || outer_angle <= 0 || outer_angle > 0.5 * kPi)
    throw Error("add_spot_light: outer_angle must be in (0, pi/2] radians, got " +
                FormatNumber(outer_angle));
  if (!std::isfinite(inner_angle) || inner_angle < 0 || inner_angle > outer_angle)
    throw Error("add_spot_light: inner_angle must be in [0, outer_angle] radians, got " +
                FormatNumber(inner_angle));
  CheckColor("add_spot_light", color);
  l.position = position;
  l.inner_angle = inner_angle;
  l.outer_angle = outer_angle;
  l.color = color;
  l.shadow = shadow;
  l.name = "spot_" + std::to_string(RenderOf(scene).lights.size());
  RenderOf(scene).lights.push_back(l);
}

void SetAmbientLight(Scene& scene, const Eigen::Vector3f& color) {
  CheckColor("set_ambient_light", color);
  RenderOf(scene).ambient = color;
}

const std::vector<LightDesc>& GetLights(const Scene& scene) { return RenderOf(scene).lights; }

// ---------------------------------------------------------------------------------------------
// backend (by name: backend_registry.cc)

void SetRenderBackend(Scene& scene, std::unique_ptr<RenderBackend> backend) {
  if (!backend) throw Error("set_render_backend: backend is null");
  RenderOf(scene).render_backend = std::move(backend);
}

// ---------------------------------------------------------------------------------------------
// render world

void UpdateRender(Scene& scene) {
  RenderState& s = RenderOf(scene);
  const uint64_t version = GetDescriptionVersion(scene);  // compiles pending additions
  RenderWorld& world = s.render_world;

  // rebuild the instances when actors or articulations changed
  if (!s.render_world_built || s.render_world_description != version) {
    std::map<std::string, std::shared_ptr<const MeshData>> cache;
    std::vector<RenderInstance> instances;
    std::vector<RenderSource> sources;
    auto add = [&](const VisualShape& v, uint32_t visual_id, uint32_t entity_id, RenderSource src) {
      RenderInstance inst;
      if (v.type == ShapeType::kConvexMesh) {
        if (!v.mesh) return;
        inst.mesh = v.mesh;
      } else {
        // primitives share one mesh per size, stable across rebuilds
        std::string key = internal::PrimitiveKey(v);
        auto it = s.primitive_meshes.find(key);
        std::shared_ptr<const MeshData> mesh =
            it != s.primitive_meshes.end() ? it->second : MakePrimitiveMesh(v);
        cache[key] = mesh;
        inst.mesh = mesh;
      }
      inst.material = v.material;
      inst.visual_id = visual_id;
      inst.entity_id = entity_id;
      src.X_BV = v.pose;
      instances.push_back(std::move(inst));
      sources.push_back(src);
    };
    for (const VisualBody& b : GetVisualBodies(scene)) {
      for (size_t j = 0; j < b.visuals.size(); ++j) {
        RenderSource src;
        src.actor_id = b.actor_id;
        src.articulation_id = b.articulation_id;
        src.link_index = b.link_index;
        add(b.visuals[j], b.visual_id_base + static_cast<uint32_t>(j), b.entity_id, src);
      }
    }
    // the version changes exactly when meshes, materials or ids change
    if (!s.render_world_built || !SameGeometry(instances, world.instances))
      ++world.geometry_version;
    world.instances = std::move(instances);
    s.render_sources = std::move(sources);
    s.primitive_meshes = std::move(cache);
    s.render_world_description = version;
    s.render_world_built = true;
  }

  // poses of every instance from its body (consecutive instances of one body share its pose)
  Pose X_WB;
  std::tuple<int, int, int> last_body(-2, -2, -2);
  for (size_t k = 0; k < world.instances.size(); ++k) {
    const RenderSource& src = s.render_sources[k];
    std::tuple<int, int, int> body(src.actor_id, src.articulation_id, src.link_index);
    if (body != last_body) {
      X_WB = src.actor_id >= 0 ? Actor(&scene, src.actor_id).GetPose()
                               : Link(&scene, src.articulation_id, src.link_index).GetPose();
      last_body = body;
    }
    world.instances[k].X_WV = (X_WB * src.X_BV).ToMatrix();
  }
  world.lights = s.lights;
  world.ambient = s.ambient;

  // cameras follow their mounts; a camera whose mount was removed stays where it was, unmounted
  for (auto& c : s.cameras) {
    if (!IsMounted(c)) {
      c.X_WC = c.local_pose;
      continue;
    }
    Pose X_WM;
    if (MountPose(&scene, c, &X_WM)) {
      c.X_WC = X_WM * c.local_pose;
    } else {
      c.mount_actor = c.mount_articulation = c.mount_link = -1;
      c.local_pose = c.X_WC;
    }
  }
}

const RenderWorld& GetRenderWorld(const Scene& scene) { return RenderOf(scene).render_world; }

std::vector<RenderEntityInfo> GetRenderEntities(const Scene& scene) {
  std::vector<RenderEntityInfo> out;
  for (const VisualBody& b : GetVisualBodies(scene)) {
    RenderEntityInfo e;
    e.id = b.entity_id;
    e.is_link = b.actor_id < 0;
    e.name = b.name;
    if (e.is_link) {
      e.articulation_id = b.articulation_id;
      e.link_index = b.link_index;
      e.articulation_name = b.articulation_name;
    } else {
      e.actor_id = b.actor_id;
    }
    e.semantic_label = b.semantic_label;
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<RenderVisualInfo> GetRenderVisuals(const Scene& scene) {
  std::vector<RenderVisualInfo> out;
  for (const VisualBody& b : GetVisualBodies(scene))
    for (size_t j = 0; j < b.visuals.size(); ++j)
      out.push_back({b.visual_id_base + static_cast<uint32_t>(j), b.entity_id, b.visuals[j].name});
  return out;
}

}  // namespace partsim
