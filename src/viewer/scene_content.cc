#include "viewer/scene_content.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "partsim/physics/observer.h"
#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"
#include "viewer/http_util.h"

namespace partsim::internal {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

Json PoseJson(const Pose& X) {
  return Json::array({X.p.x(), X.p.y(), X.p.z(), X.q.w(), X.q.x(), X.q.y(), X.q.z()});
}

Json Vec3(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

// a limit as JSON: null when unlimited (JSON has no infinity)
Json Limit(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// the tables that give meshes and textures their indices
struct Indexer {
  SceneContent* content;
  std::map<const MeshData*, int> mesh_index;
  std::map<std::string, int> primitive_index;
  std::map<std::string, int> texture_index;

  int Mesh(const std::shared_ptr<const MeshData>& mesh) {
    auto [it, added] = mesh_index.emplace(mesh.get(), static_cast<int>(content->meshes.size()));
    if (added) content->meshes.push_back(mesh);
    return it->second;
  }
  int Visual(const VisualShape& v) {
    if (v.type == ShapeType::kConvexMesh) return v.mesh ? Mesh(v.mesh) : -1;
    const std::string key = PrimitiveKey(v);
    auto it = primitive_index.find(key);
    if (it != primitive_index.end()) return it->second;
    const int k = Mesh(MakePrimitiveMesh(v));
    primitive_index[key] = k;
    return k;
  }
  int Texture(const VisualShape& v) {
    const std::string& path = v.material.diffuse_texture;
    if (path.empty()) return -1;
    // a mesh file's texture is sent only from the mesh's folder or the one above it
    // (PartNet-Mobility: textured_objs/x.mtl names ../images/y.jpg), links followed: an MTL's
    // map_Kd cannot name /etc/passwd or climb out with ../
    std::string file;
    if (v.mesh && !v.mesh->source.empty()) {
      std::error_code ec;
      const fs::path dir = fs::absolute(v.mesh->source, ec).parent_path();
      file = RegularFileInside(path, dir.string());
      if (file.empty()) file = RegularFileInside(path, dir.parent_path().string());
    } else {
      file = RegularFileInside(path, "/");
    }
    if (file.empty()) {
      std::fprintf(stderr,
                   "partsim viewer: warning: texture '%s' (of %s) is not a file in the folder "
                   "of its mesh or the one above: the page shows the visual without it\n",
                   path.c_str(),
                   v.mesh && !v.mesh->source.empty() ? v.mesh->source.c_str() : "a visual");
      return -1;
    }
    auto [it, added] = texture_index.emplace(file, static_cast<int>(content->textures.size()));
    if (added) content->textures.push_back(file);
    return it->second;
  }
};

Json CollisionJson(const CollisionShape& c, Indexer* index) {
  Json j = {{"type", ShapeTypeName(c.type)}, {"pose", PoseJson(c.pose)}};
  switch (c.type) {
    case ShapeType::kBox:
      j["half_size"] = Vec3(c.half_size);
      break;
    case ShapeType::kSphere:
      j["radius"] = c.radius;
      break;
    case ShapeType::kCapsule:
    case ShapeType::kCylinder:
      j["radius"] = c.radius;
      j["half_length"] = c.half_length;
      break;
    case ShapeType::kConvexMesh:
      j["type"] = "mesh";
      j["mesh"] = c.mesh ? index->Mesh(c.mesh) : -1;
      j["scale"] = Json::array({1, 1, 1});
      break;
    case ShapeType::kPlane:
      break;
  }
  return j;
}

}  // namespace

std::shared_ptr<SceneContent> MakeSceneContent(Scene& scene, long long version) {
  auto content = std::make_shared<SceneContent>();
  content->version = version;
  Indexer index{content.get(), {}, {}, {}};

  // articulations: the page's id is the index in the scene's list
  std::map<int, int> art_index;  // scene id -> page id
  const std::vector<Articulation> arts = scene.GetArticulations();
  for (size_t a = 0; a < arts.size(); ++a) art_index[arts[a].GetId()] = static_cast<int>(a);

  // bodies: actors, then the links of each articulation (GetVisualBodies' order)
  Json bodies = Json::array();
  std::map<std::pair<int, int>, int> link_body;  // (articulation scene id, link) -> body id
  for (const VisualBody& b : GetVisualBodies(scene)) {
    const int id = static_cast<int>(content->bodies.size());
    content->bodies.push_back({b.actor_id, b.articulation_id, b.link_index});
    const bool link = b.actor_id < 0;
    const BodyDesc& desc =
        link ? static_cast<const BodyDesc&>(Link(&scene, b.articulation_id, b.link_index).GetDesc())
             : static_cast<const BodyDesc&>(Actor(&scene, b.actor_id).GetDesc());
    const std::array<uint8_t, 3> seg = SegmentationColor(b.entity_id);
    Json body = {{"id", id},
                 {"name", b.name},
                 {"kind", link ? "link" : "actor"},
                 {"entity_id", b.entity_id},
                 {"label", b.semantic_label},
                 {"partnet_name", desc.partnet_name},
                 {"seg_color", Json::array({seg[0] / 255.0, seg[1] / 255.0, seg[2] / 255.0})}};
    if (link) {
      body["articulation"] = art_index.at(b.articulation_id);
      body["link_index"] = b.link_index;
      link_body[{b.articulation_id, b.link_index}] = id;
    } else {
      body["actor_type"] = ActorTypeName(Actor(&scene, b.actor_id).GetType());
    }
    Json visuals = Json::array();
    for (const VisualShape& v : b.visuals) {
      const int mesh = index.Visual(v);
      if (mesh < 0) continue;
      const Eigen::Vector4f& c = v.material.base_color;
      visuals.push_back({{"mesh", mesh},
                         {"name", v.name},
                         {"pose", PoseJson(v.pose)},
                         {"scale", Json::array({1, 1, 1})},
                         {"color", Json::array({c[0], c[1], c[2], c[3]})},
                         {"roughness", v.material.roughness},
                         {"metallic", v.material.metallic},
                         {"texture", index.Texture(v)}});
    }
    body["visuals"] = std::move(visuals);
    Json collisions = Json::array();
    for (const CollisionShape& c : desc.collisions) collisions.push_back(CollisionJson(c, &index));
    body["collisions"] = std::move(collisions);
    bodies.push_back(std::move(body));
  }

  Json articulations = Json::array();
  for (size_t a = 0; a < arts.size(); ++a) {
    const Articulation& art = arts[a];
    ContentArticulation ca;
    ca.scene_id = art.GetId();
    ca.name = art.GetName();
    Json joints = Json::array();
    for (const Joint& joint : art.GetJoints()) {
      ca.joint_by_name[joint.GetName()] = joint.GetIndex();
      const int dof = joint.GetDofIndex();
      if (dof >= 0) ca.dof_joints.push_back(joint.GetName());
      const Eigen::Vector2d limits = joint.GetLimits();
      const bool driven =
          dof >= 0 && (joint.GetDriveStiffness() > 0 || joint.GetDriveDamping() > 0);
      const int parent = joint.GetParentLink().GetIndex();
      joints.push_back(
          {{"name", joint.GetName()},
           {"type", JointTypeName(joint.GetType())},
           {"dof_index", dof},
           {"parent", parent >= 0 ? Json(link_body.at({ca.scene_id, parent})) : Json(nullptr)},
           {"child", link_body.at({ca.scene_id, joint.GetIndex()})},
           {"lower", dof >= 0 ? Limit(limits[0]) : Json(nullptr)},
           {"upper", dof >= 0 ? Limit(limits[1]) : Json(nullptr)},
           {"pose_in_child", PoseJson(joint.GetPoseInChild())},
           {"axis", Json::array({1, 0, 0})},
           {"driven", driven},
           {"position", dof >= 0 ? Json(joint.GetQpos()) : Json(nullptr)}});
    }
    articulations.push_back({{"id", static_cast<int>(a)},
                             {"name", ca.name},
                             {"dof", art.Dof()},
                             {"fixed_root", art.HasFixedRoot()},
                             {"joints", std::move(joints)}});
    content->articulations.push_back(std::move(ca));
  }

  Json cameras = Json::array();
  for (const Camera& cam : GetCameras(scene))
    cameras.push_back({{"name", cam.GetName()},
                       {"width", cam.GetWidth()},
                       {"height", cam.GetHeight()},
                       {"fovy", cam.GetFovy()},
                       {"pose", PoseJson(cam.GetPose())}});

  const Eigen::Vector3d g = scene.GetGravity();
  content->json = {{"scene_version", version},     {"timestep", scene.GetTimestep()},
                   {"up", Json::array({0, 0, 1})}, {"gravity", Vec3(g)},
                   {"bodies", std::move(bodies)},  {"articulations", std::move(articulations)},
                   {"cameras", std::move(cameras)}};
  return content;
}

std::shared_ptr<MotionSnapshot> TakeMotionSnapshot(Scene& scene, const SceneContent& content,
                                                   bool contacts) {
  auto snap = std::make_shared<MotionSnapshot>();
  snap->version = content.version;
  snap->time = scene.GetTime();
  snap->step = std::llround(snap->time / scene.GetTimestep());
  snap->poses.reserve(7 * content.bodies.size());
  for (const ContentBody& b : content.bodies) {
    const Pose X = b.actor_id >= 0 ? Actor(&scene, b.actor_id).GetPose()
                                   : Link(&scene, b.articulation_id, b.link_index).GetPose();
    const double v[7] = {X.p.x(), X.p.y(), X.p.z(), X.q.w(), X.q.x(), X.q.y(), X.q.z()};
    snap->poses.insert(snap->poses.end(), v, v + 7);
  }
  for (const ContentArticulation& a : content.articulations) {
    const Articulation art(&scene, a.scene_id);
    const Eigen::VectorXd q = art.GetQpos(), qd = art.GetQvel();
    snap->qpos.emplace_back(q.data(), q.data() + q.size());
    snap->qvel.emplace_back(qd.data(), qd.data() + qd.size());
  }
  if (contacts) {
    snap->has_contacts = true;
    for (const Contact& c : scene.GetContacts())
      for (const ContactPoint& p : c.points) {
        for (int k = 0; k < 3; ++k) {
          snap->contact_points.push_back(p.position[k]);
          snap->contact_normals.push_back(p.normal[k]);
        }
        snap->contact_forces.push_back(p.force.dot(p.normal));
      }
  }
  return snap;
}

bool BodyMoved(const std::vector<double>& a, const std::vector<double>& b, size_t i) {
  for (size_t k = 7 * i; k < 7 * i + 7; ++k)
    if (std::abs(a[k] - b[k]) > 1e-5) return true;
  return false;
}

std::string EncodeMesh(const MeshData& mesh) {
  const size_t n = mesh.vertices.size(), m = 3 * mesh.faces.size();
  const bool normals = mesh.normals.size() == n && n > 0;
  const bool uvs = mesh.uvs.size() == n && n > 0;
  std::string out;
  out.reserve(20 + 4 * (3 * n + (normals ? 3 * n : 0) + (uvs ? 2 * n : 0) + m));
  auto u32 = [&out](uint32_t v) {
    for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 255));
  };
  auto f32 = [&u32](float f) {
    uint32_t bits;
    std::memcpy(&bits, &f, 4);
    u32(bits);
  };
  out += "PSMH";
  u32(1);
  u32(static_cast<uint32_t>(n));
  u32(static_cast<uint32_t>(m));
  u32((normals ? 1u : 0u) | (uvs ? 2u : 0u));
  for (const Eigen::Vector3f& v : mesh.vertices)
    for (int k = 0; k < 3; ++k) f32(v[k]);
  if (normals)
    for (const Eigen::Vector3f& v : mesh.normals)
      for (int k = 0; k < 3; ++k) f32(v[k]);
  if (uvs)
    for (const Eigen::Vector2f& v : mesh.uvs)
      for (int k = 0; k < 2; ++k) f32(v[k]);
  for (const Eigen::Vector3i& f : mesh.faces)
    for (int k = 0; k < 3; ++k) u32(static_cast<uint32_t>(f[k]));
  return out;
}

void AppendNumbers(std::string* out, const double* values, size_t n) {
  out->push_back('[');
  char buf[32];
  for (size_t i = 0; i < n; ++i) {
    const double v = std::isfinite(values[i]) ? values[i] : 0.0;
    const int len = std::snprintf(buf, sizeof(buf), i ? ",%.7g" : "%.7g", v);
    out->append(buf, static_cast<size_t>(len));
  }
  out->push_back(']');
}

}  // namespace partsim::internal
