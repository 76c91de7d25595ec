// MJCF models in a scene: parsed into a MuJoCo specification, attached to the scene's (compiler.cc)
// and given partsim handles: articulations for kinematic trees, actors for free, static and mocap
// bodies, descriptions derived from the compiled model so that kinematics, drives and cameras
// see them as they see the rest.
#include "partsim/physics/mjcf.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>

#include "partsim/core/error.h"
#include "physics/scene_internal.h"

namespace partsim {

using internal::kZToX;
using internal::SceneImpl;

namespace {

Pose PoseOf(const double* pos, const double* quat) {
  return Pose(Eigen::Vector3d(pos[0], pos[1], pos[2]),
              Eigen::Quaterniond(quat[0], quat[1], quat[2], quat[3]).normalized());
}

std::string Name(const mjModel* m, mjtObj type, int id) {
  const char* n = mj_id2name(m, type, id);
  return n ? n : "";
}

// The element names of a model file, without the prefix.
std::string Strip(const std::string& name, const std::string& prefix) {
  return name.compare(0, prefix.size(), prefix) == 0 ? name.substr(prefix.size()) : name;
}

// Gives every unnamed body, joint and geom of a specification a name that no other element of
// its kind has, so that partsim finds them again after each compile.
void NameUnnamed(mjSpec* spec) {
  const std::pair<mjtObj, const char*> kinds[] = {{mjOBJ_BODY, "body"},
                                                  {mjOBJ_JOINT, "joint"},
                                                  {mjOBJ_GEOM, "geom"},
                                                  {mjOBJ_TENDON, "tendon"},
                                                  {mjOBJ_ACTUATOR, "actuator"}};
  for (const auto& [type, kind] : kinds) {
    std::set<std::string> taken;
    for (mjsElement* e = mjs_firstElement(spec, type); e; e = mjs_nextElement(spec, e))
      taken.insert(mjs_getString(mjs_getName(e)));
    int k = 0;
    for (mjsElement* e = mjs_firstElement(spec, type); e; e = mjs_nextElement(spec, e)) {
      if (*mjs_getString(mjs_getName(e)) != '\0') continue;
      std::string name;
      do name = std::string("_") + kind + std::to_string(k++);
      while (taken.count(name));
      taken.insert(name);
      mjs_setName(e, name.c_str());
    }
  }
}

// A mesh of the compiled model, one vertex per face corner (MuJoCo indexes positions, normals
// and texture coordinates separately), in the geom's frame.
std::shared_ptr<MeshData> MeshOf(const mjModel* m, int mesh, const std::string& source) {
  auto out = std::make_shared<MeshData>();
  out->source = source;
  out->name = Name(m, mjOBJ_MESH, mesh);
  const int vadr = m->mesh_vertadr[mesh], fadr = m->mesh_faceadr[mesh];
  const int nface = m->mesh_facenum[mesh];
  const int nadr = m->mesh_normaladr[mesh], tadr = m->mesh_texcoordadr[mesh];
  const bool uv = tadr >= 0 && m->mesh_texcoordnum[mesh] > 0;
  for (int f = 0; f < nface; ++f) {
    Eigen::Vector3i face;
    for (int k = 0; k < 3; ++k) {
      const int i = 3 * (fadr + f) + k;
      const float* v = m->mesh_vert + 3 * (vadr + m->mesh_face[i]);
      const float* n = m->mesh_normal + 3 * (nadr + m->mesh_facenormal[i]);
      face[k] = static_cast<int>(out->vertices.size());
      out->vertices.emplace_back(v[0], v[1], v[2]);
      out->normals.emplace_back(n[0], n[1], n[2]);
      if (uv) {
        const float* t = m->mesh_texcoord + 2 * (tadr + m->mesh_facetexcoord[i]);
        // MuJoCo flips v when it loads an OBJ (its textures start at the top row)
        out->uvs.emplace_back(t[0], 1.0f - t[1]);
      }
    }
    out->faces.push_back(face);
  }
  return out;
}

// What a MuJoCo geom is to partsim: a collision shape (if it collides), a visual (if it is in
// one of the groups MuJoCo draws by default, 0-2), both in the body's frame. False for a type
// partsim has no shape for (ellipsoid, height field, SDF): MuJoCo still simulates it.
struct GeomShapes {
  std::optional<CollisionShape> collision;
  std::optional<VisualShape> visual;
};

GeomShapes ShapesOf(const mjModel* m, int g, const std::string& dir,
                    std::map<int, std::shared_ptr<MeshData>>* meshes,
                    const std::map<std::string, std::string>& texture_files,
                    const std::string& prefix) {
  GeomShapes out;
  CollisionShape c;
  Pose pose = PoseOf(m->geom_pos + 3 * g, m->geom_quat + 4 * g);
  const double* size = m->geom_size + 3 * g;
  switch (m->geom_type[g]) {
    case mjGEOM_BOX:
      c.type = ShapeType::kBox;
      c.half_size = Eigen::Vector3d(size[0], size[1], size[2]);
      break;
    case mjGEOM_SPHERE:
      c.type = ShapeType::kSphere;
      c.radius = size[0];
      break;
    case mjGEOM_CAPSULE:
    case mjGEOM_CYLINDER:
      c.type = m->geom_type[g] == mjGEOM_CAPSULE ? ShapeType::kCapsule : ShapeType::kCylinder;
      c.radius = size[0];
      c.half_length = size[1];
      pose.q = pose.q * kZToX.inverse();
      break;
    case mjGEOM_PLANE:
      c.type = ShapeType::kPlane;
      // an infinite plane (size 0) is drawn 10 m across
      c.half_size = Eigen::Vector3d(size[0] > 0 ? size[0] : 10, size[1] > 0 ? size[1] : 10, 0);
      break;
    case mjGEOM_MESH: {
      const int mesh = m->geom_dataid[g];
      auto it = meshes->find(mesh);
      if (it == meshes->end()) it = meshes->emplace(mesh, MeshOf(m, mesh, dir)).first;
      c.type = ShapeType::kConvexMesh;
      c.mesh = it->second;
      break;
    }
    default:
      return out;
  }
  c.pose = pose;
  c.name = Strip(Name(m, mjOBJ_GEOM, g), prefix);
  c.density = 1000.0;
  PhysicalMaterial material;
  material.static_friction = material.dynamic_friction = m->geom_friction[3 * g];
  c.material = material;
  if (m->geom_contype[g] != 0 || m->geom_conaffinity[g] != 0) out.collision = c;
  const int group = m->geom_group[g];
  const int mat = m->geom_matid[g];
  const float* rgba = mat >= 0 ? m->mat_rgba + 4 * mat : m->geom_rgba + 4 * g;
  if (group >= 0 && group <= 2 && rgba[3] > 0) {
    VisualShape v;
    v.type = c.type;
    v.pose = c.pose;
    v.half_size = c.half_size;
    v.radius = c.radius;
    v.half_length = c.half_length;
    v.mesh = c.mesh;
    v.name = c.name;
    v.material.base_color = Eigen::Vector4f(rgba[0], rgba[1], rgba[2], rgba[3]);
    if (mat >= 0) {
      const int tex = m->mat_texid[mjNTEXROLE * mat + mjTEXROLE_RGB];
      if (tex >= 0) {
        auto f = texture_files.find(Name(m, mjOBJ_TEXTURE, tex));
        if (f != texture_files.end() && c.type == ShapeType::kConvexMesh && !c.mesh->uvs.empty())
          v.material.diffuse_texture = f->second;
      }
    }
    out.visual = v;
  }
  return out;
}

// The texture files of a specification (absolute paths), by texture name with the prefix.
std::map<std::string, std::string> TextureFiles(mjSpec* spec, const std::string& dir,
                                                const std::string& prefix) {
  std::map<std::string, std::string> out;
  const std::string texturedir = mjs_getString(spec->compiler.texturedir);
  for (mjsElement* e = mjs_firstElement(spec, mjOBJ_TEXTURE); e; e = mjs_nextElement(spec, e)) {
    mjsTexture* t = mjs_asTexture(e);
    const std::string file = mjs_getString(t->file);
    if (file.empty()) continue;
    std::filesystem::path p(file);
    if (p.is_relative()) p = std::filesystem::path(dir) / texturedir / p;
    out[prefix + mjs_getString(mjs_getName(e))] = p.lexically_normal().string();
  }
  return out;
}

// Adds the partsim entities of a model just compiled into the scene: one per tree under the
// worldbody, and one static actor for the geoms of its worldbody.
void AddEntities(SceneImpl& s, SceneImpl::MjcfEntry& model) {
  const mjModel* m = s.m();
  const std::string& prefix = model.prefix;
  const std::string dir = std::filesystem::path(model.path).parent_path().string();
  const std::map<std::string, std::string> textures = TextureFiles(model.spec.get(), dir, prefix);
  std::map<int, std::shared_ptr<MeshData>> meshes;
  auto mine = [&](mjtObj type, int id) {
    return Name(m, type, id).compare(0, prefix.size(), prefix) == 0;
  };
  // geoms by body, and the bodies of each tree in MuJoCo's order (parents first)
  std::map<int, std::vector<int>> geoms;
  for (int g = 0; g < m->ngeom; ++g)
    if (mine(mjOBJ_GEOM, g)) geoms[m->geom_bodyid[g]].push_back(g);
  std::map<int, std::vector<int>> trees;
  for (int b = 1; b < m->nbody; ++b)
    if (mine(mjOBJ_BODY, b)) trees[m->body_rootid[b]].push_back(b);

  auto shapes = [&](BodyDesc& desc, int body, std::vector<std::string>* names) {
    for (int g : geoms[body]) {
      GeomShapes gs = ShapesOf(m, g, model.path, &meshes, textures, prefix);
      if (gs.collision) {
        desc.collisions.push_back(*gs.collision);
        names->push_back(Name(m, mjOBJ_GEOM, g));
      }
      if (gs.visual) desc.visuals.push_back(*gs.visual);
    }
    if (body > 0) {
      Inertial inertial;
      inertial.mass = m->body_mass[body];
      inertial.cmass_local_pose = PoseOf(m->body_ipos + 3 * body, m->body_iquat + 4 * body);
      inertial.inertia = Eigen::Vector3d(m->body_inertia[3 * body], m->body_inertia[3 * body + 1],
                                         m->body_inertia[3 * body + 2]);
      if (inertial.mass > 0 && inertial.inertia.minCoeff() > 0) desc.inertial = inertial;
    }
  };
  auto add_actor = [&](ActorDesc desc, int body, std::vector<std::string> geom_names) {
    const int id = s.next_id++;
    SceneImpl::ActorEntry entry;
    entry.id = id;
    entry.desc = std::move(desc);
    entry.render_id = static_cast<uint32_t>(id);
    entry.visual_id_base = s.next_visual_id;
    entry.mjcf = model.id;
    entry.mj_body = Name(m, mjOBJ_BODY, body);
    entry.mj_geoms = std::move(geom_names);
    s.next_visual_id += static_cast<uint32_t>(entry.desc.visuals.size());
    s.actors.push_back(std::move(entry));
    model.actors.push_back(id);
  };

  // the worldbody's own geoms: one static actor
  if (!geoms[0].empty()) {
    ActorDesc desc;
    desc.name = model.name + "/world";
    desc.type = ActorType::kStatic;
    std::vector<std::string> names;
    shapes(desc, 0, &names);
    add_actor(std::move(desc), 0, std::move(names));
  }
  for (const auto& [root, bodies] : trees) {
    const int njnt = m->body_jntnum[root];
    const bool free_root = njnt >= 1 && m->jnt_type[m->body_jntadr[root]] == mjJNT_FREE;
    if (bodies.size() == 1 && (njnt == 0 || (njnt == 1 && free_root))) {
      ActorDesc desc;
      desc.name = Strip(Name(m, mjOBJ_BODY, root), prefix);
      desc.type = free_root                    ? ActorType::kDynamic
                  : m->body_mocapid[root] >= 0 ? ActorType::kKinematic
                                               : ActorType::kStatic;
      desc.pose = PoseOf(s.d()->xpos + 3 * root, s.d()->xquat + 4 * root);
      std::vector<std::string> names;
      shapes(desc, root, &names);
      add_actor(std::move(desc), root, std::move(names));
      continue;
    }
    // a tree: links for its bodies, a chain of links where a body has several joints
    bool representable = m->body_mocapid[root] < 0;
    for (int b : bodies)
      for (int j = m->body_jntadr[b]; j < m->body_jntadr[b] + m->body_jntnum[b]; ++j) {
        const int type = m->jnt_type[j];
        if (type == mjJNT_BALL || (type == mjJNT_FREE && !(b == root && j == m->body_jntadr[b])))
          representable = false;
      }
    if (!representable) {
      for (int b : bodies)
        model.bodies_without_handle.push_back(Strip(Name(m, mjOBJ_BODY, b), prefix));
      continue;
    }
    ArticulationDesc art;
    art.name = Strip(Name(m, mjOBJ_BODY, root), prefix);
    art.fix_root = !free_root;
    art.root_pose = PoseOf(s.d()->xpos + 3 * root, s.d()->xquat + 4 * root);
    SceneImpl::ArticulationEntry entry;
    entry.id = s.next_id;
    entry.mjcf = model.id;
    std::map<int, int> link_of_body;  // MuJoCo body -> the link that holds its shapes
    bool root_joints = false;         // a root that turns or slides on the world
    for (int j = m->body_jntadr[root]; j < m->body_jntadr[root] + m->body_jntnum[root]; ++j)
      root_joints |= m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE;
    if (root_joints) {
      // partsim's root link has no joint: the world is the root, a link without shapes
      LinkDesc anchor;
      anchor.name = art.name + "/world";
      art.links.push_back(anchor);
      art.root_pose = Pose();
      entry.mj_link_body.push_back("world");
      entry.mj_link_joint.push_back("");
      entry.mj_link_geoms.emplace_back();
      link_of_body[0] = 0;
    }
    for (int b : bodies) {
      const std::string body_name = Name(m, mjOBJ_BODY, b);
      int parent = b == root && !root_joints ? -1 : link_of_body.at(m->body_parentid[b]);
      // the body's frame in its parent's at qpos0, then one link per joint
      Pose X_PB = PoseOf(m->body_pos + 3 * b, m->body_quat + 4 * b);
      const int first = m->body_jntadr[b], count = m->body_jntnum[b];
      std::vector<int> joints;
      for (int j = first; j < first + count; ++j)
        if (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE) joints.push_back(j);
      const size_t nlinks = std::max<size_t>(1, joints.size());
      for (size_t k = 0; k < nlinks; ++k) {
        LinkDesc link;
        const bool last = k + 1 == nlinks;
        link.name = Strip(body_name, prefix);
        if (!last) link.name += "/" + Strip(Name(m, mjOBJ_JOINT, joints[k]), prefix);
        link.parent = parent;
        std::string joint_name;
        if (parent >= 0) {
          if (joints.empty()) {
            link.joint.type = JointType::kFixed;
            link.joint.pose_in_parent = X_PB;
          } else {
            const int j = joints[k];
            joint_name = Name(m, mjOBJ_JOINT, j);
            JointDesc& jd = link.joint;
            jd.name = Strip(joint_name, prefix);
            jd.type = m->jnt_type[j] == mjJNT_SLIDE ? JointType::kPrismatic : JointType::kRevolute;
            const Eigen::Vector3d axis =
                Eigen::Vector3d(m->jnt_axis[3 * j], m->jnt_axis[3 * j + 1], m->jnt_axis[3 * j + 2])
                    .normalized();
            // the joint frame: at the anchor, x along the axis, in the body's frame at qpos0
            const Pose X_BJ(
                Eigen::Vector3d(m->jnt_pos[3 * j], m->jnt_pos[3 * j + 1], m->jnt_pos[3 * j + 2]),
                Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), axis));
            jd.pose_in_parent = (k == 0 ? X_PB : Pose()) * X_BJ;
            jd.pose_in_child = X_BJ;
            if (m->jnt_limited[j]) {
              jd.lower = m->jnt_range[2 * j];
              jd.upper = m->jnt_range[2 * j + 1];
            } else if (jd.type == JointType::kRevolute) {
              jd.type = JointType::kContinuous;
            }
            const int dof = m->jnt_dofadr[j];
            jd.damping = m->dof_damping[dof];
            jd.friction = m->dof_frictionloss[dof];
            jd.armature = m->dof_armature[dof];
          }
        }
        std::vector<std::string> geom_names;
        if (last) shapes(link, b, &geom_names);
        entry.mj_link_body.push_back(body_name);
        entry.mj_link_joint.push_back(joint_name);
        entry.mj_link_geoms.push_back(std::move(geom_names));
        art.links.push_back(std::move(link));
        parent = static_cast<int>(art.links.size()) - 1;
      }
      link_of_body[b] = static_cast<int>(art.links.size()) - 1;
    }
    entry.desc = std::move(art);
    entry.render_id_base = static_cast<uint32_t>(entry.id + 1);
    uint32_t visual_id = s.next_visual_id;
    for (const LinkDesc& l : entry.desc.links) {
      entry.visual_id_base.push_back(visual_id);
      visual_id += static_cast<uint32_t>(l.visuals.size());
    }
    s.next_visual_id = visual_id;
    s.next_id += 1 + static_cast<int>(entry.desc.links.size());
    model.articulations.push_back(entry.id);
    s.articulations.push_back(std::move(entry));
  }
}

// The first element of a file: <mujoco ...> for MJCF.
std::string RootElement(const std::string& path) {
  std::ifstream in(path);
  std::string text;
  char c;
  while (in.get(c) && text.size() < 4096) {
    text += c;
    const size_t lt = text.rfind('<');
    if (lt == std::string::npos) continue;
    if (text.size() > lt + 1 && (text[lt + 1] == '?' || text[lt + 1] == '!')) {
      // a declaration or comment: skip to its end
      const std::string end = text[lt + 1] == '?' ? "?>" : "-->";
      if (text.find(end, lt) == std::string::npos) continue;
      text.clear();
      continue;
    }
    const size_t stop = text.find_first_of(" \t\r\n>/", lt + 1);
    if (stop != std::string::npos) return text.substr(lt + 1, stop - lt - 1);
  }
  return "";
}

}  // namespace

namespace internal {

SceneImpl::MjcfEntry& SceneImpl::GetMjcf(int id) {
  for (auto& e : mjcf_models)
    if (e.id == id) return e;
  throw Error("MJCF model " + std::to_string(id) + " is not in the scene");
}

}  // namespace internal

bool IsMjcfFile(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  return (ext == ".xml" || ext == ".XML" || ext == ".mjcf") && RootElement(path) == "mujoco";
}

SceneConfig SceneConfigFromMjcf(const std::string& path) {
  char err[1024] = "";
  std::unique_ptr<mjSpec, internal::MjSpecDeleter> spec(
      mj_parseXML(path.c_str(), nullptr, err, sizeof(err)));
  if (!spec) throw Error(path + ": " + err);
  const mjOption& o = spec->option;
  SceneConfig c;
  c.timestep = o.timestep;
  c.gravity = Eigen::Vector3d(o.gravity[0], o.gravity[1], o.gravity[2]);
  c.solver_iterations = std::max(1, o.iterations);
  c.integrator = o.integrator == mjINT_EULER      ? Integrator::kEuler
                 : o.integrator == mjINT_RK4      ? Integrator::kRK4
                 : o.integrator == mjINT_IMPLICIT ? Integrator::kImplicit
                                                  : Integrator::kImplicitFast;
  // MuJoCo's own contacts (the file's solref and solimp stay as it gives them)
  return c;
}

MjcfModel LoadMjcf(Scene& scene, const std::string& path, const Pose& pose) {
  SceneImpl& s = scene.impl();
  s.CheckUser();
  if (!std::filesystem::exists(path)) throw Error("load_mjcf: no file '" + path + "'");
  // MuJoCo's parser also imports URDF: partsim's URDF loader is the one for those
  const std::string root = RootElement(path);
  if (root != "mujoco")
    throw Error("load_mjcf: " + path + ": " +
                (root.empty()
                     ? std::string("no root element (not an MJCF file)")
                     : "the root element is <" + root + ">, not <mujoco>" +
                           (root == "robot" ? " (a URDF: load it with the URDF loader)" : "")));
  char err[1024] = "";
  std::shared_ptr<mjSpec> spec(mj_parseXML(path.c_str(), nullptr, err, sizeof(err)),
                               internal::MjSpecDeleter());
  if (!spec) throw Error("load_mjcf: " + path + ": " + err);
  NameUnnamed(spec.get());
  for (mjsElement* e = mjs_firstElement(spec.get(), mjOBJ_MESH); e;
       e = mjs_nextElement(spec.get(), e)) {
    mjsMesh* mesh = mjs_asMesh(e);
    if (mesh->maxhullvert < 0) mesh->maxhullvert = internal::kMaxHullVertices;
  }
  SceneImpl::MjcfEntry entry;
  entry.id = s.next_mjcf_id;
  entry.path = std::filesystem::absolute(path).lexically_normal().string();
  entry.name = mjs_getString(spec->modelname);
  if (entry.name.empty() || entry.name == "MuJoCo Model")
    entry.name = std::filesystem::path(path).stem().string();
  // names of other models' prefixes are never reused in one scene
  std::string prefix = entry.name + "/";
  for (int k = 2; std::any_of(s.mjcf_models.begin(), s.mjcf_models.end(),
                              [&](const auto& e) { return e.prefix == prefix; });
       ++k)
    prefix = entry.name + "#" + std::to_string(k) + "/";
  entry.prefix = prefix;
  Pose placed = pose;
  placed.q.normalize();
  entry.pose = placed;
  entry.spec = spec;
  s.EnsureCompiled();
  s.mjcf_models.push_back(entry);
  s.dirty = true;
  try {
    s.EnsureCompiled();
  } catch (const Error& e) {
    // the compile failed before it replaced anything: the model and data compiled before are
    // the scene's without this entry, state and all
    s.mjcf_models.pop_back();
    s.dirty = false;
    throw Error(std::string("load_mjcf: ") + path + ": " + e.what());
  }
  ++s.next_mjcf_id;
  SceneImpl::MjcfEntry& added = s.mjcf_models.back();
  s.EnsureKinematics();
  AddEntities(s, added);
  // again, with the drives of its articulations
  s.dirty = true;
  s.EnsureCompiled();
  return MjcfModel(&scene, added.id);
}

std::vector<MjcfModel> GetMjcfModels(const Scene& scene) {
  std::vector<MjcfModel> out;
  for (const auto& e : scene.impl().mjcf_models) out.emplace_back(const_cast<Scene*>(&scene), e.id);
  return out;
}

// ---------------------------------------------------------------------------------------------
// MjcfModel

namespace {

SceneImpl::MjcfEntry& Entry(Scene* scene, int id) {
  if (!scene) throw Error("MjcfModel: the handle is empty");
  return scene->impl().GetMjcf(id);
}

// The ids of a model's elements of one type (bodies, joints, actuators, tendons), in MuJoCo's
// order.
std::vector<int> Elements(SceneImpl& s, const std::string& prefix, mjtObj type) {
  s.EnsureCompiled();
  const mjModel* m = s.m();
  const long long count = type == mjOBJ_BODY       ? m->nbody
                          : type == mjOBJ_JOINT    ? m->njnt
                          : type == mjOBJ_ACTUATOR ? m->nu
                          : type == mjOBJ_TENDON   ? m->ntendon
                                                   : 0;
  std::vector<int> out;
  for (int i = 0; i < count; ++i) {
    const char* n = mj_id2name(m, type, i);
    if (n && std::strncmp(n, prefix.c_str(), prefix.size()) == 0) out.push_back(i);
  }
  return out;
}

// The names (without the prefix) of a model's elements of one type, in MuJoCo's order.
std::vector<std::string> ElementNames(Scene* scene, int id, mjtObj type) {
  SceneImpl& s = scene->impl();
  const std::string& prefix = Entry(scene, id).prefix;
  std::vector<std::string> out;
  for (int e : Elements(s, prefix, type)) out.push_back(Strip(Name(s.m(), type, e), prefix));
  return out;
}

}  // namespace

const std::string& MjcfModel::GetName() const { return Entry(scene_, id_).name; }
const std::string& MjcfModel::GetPath() const { return Entry(scene_, id_).path; }
const std::string& MjcfModel::GetPrefix() const { return Entry(scene_, id_).prefix; }

std::vector<Articulation> MjcfModel::GetArticulations() const {
  std::vector<Articulation> out;
  for (int id : Entry(scene_, id_).articulations) out.emplace_back(scene_, id);
  return out;
}

std::vector<Actor> MjcfModel::GetActors() const {
  std::vector<Actor> out;
  for (int id : Entry(scene_, id_).actors) out.emplace_back(scene_, id);
  return out;
}

std::vector<std::string> MjcfModel::GetBodiesWithoutHandle() const {
  return Entry(scene_, id_).bodies_without_handle;
}

std::vector<std::string> MjcfModel::GetActuatorNames() const {
  return ElementNames(scene_, id_, mjOBJ_ACTUATOR);
}

Eigen::VectorXd MjcfModel::GetCtrl() const {
  SceneImpl& s = scene_->impl();
  const std::vector<int> ids = Elements(s, Entry(scene_, id_).prefix, mjOBJ_ACTUATOR);
  Eigen::VectorXd out(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) out[static_cast<Eigen::Index>(i)] = s.d()->ctrl[ids[i]];
  return out;
}

void MjcfModel::SetCtrl(const Eigen::VectorXd& ctrl) {
  SceneImpl& s = scene_->impl();
  const std::vector<int> ids = Elements(s, Entry(scene_, id_).prefix, mjOBJ_ACTUATOR);
  if (ctrl.size() != static_cast<Eigen::Index>(ids.size()))
    throw Error("set_ctrl: the model '" + GetName() + "' has " + std::to_string(ids.size()) +
                " actuators, got " + std::to_string(ctrl.size()) + " controls");
  if (!ctrl.allFinite()) throw Error("set_ctrl: controls must be finite");
  s.CheckUser();
  for (size_t i = 0; i < ids.size(); ++i) s.d()->ctrl[ids[i]] = ctrl[static_cast<Eigen::Index>(i)];
  s.Invalidate();
}

void MjcfModel::SetCtrl(const std::string& actuator, double value) {
  const int id = MjId(mjOBJ_ACTUATOR, actuator);
  if (id < 0)
    throw Error("set_ctrl: the model '" + GetName() + "' has no actuator '" + actuator + "'");
  if (!std::isfinite(value)) throw Error("set_ctrl: the control must be finite");
  SceneImpl& s = scene_->impl();
  s.CheckUser();
  s.d()->ctrl[id] = value;
  s.Invalidate();
}

std::vector<std::string> MjcfModel::GetJointNames() const {
  return ElementNames(scene_, id_, mjOBJ_JOINT);
}

namespace {

// The model's slice of qpos (positions) or qvel, joint by joint.
std::vector<std::pair<int, int>> Slices(SceneImpl& s, const std::string& prefix, bool positions) {
  std::vector<std::pair<int, int>> out;  // (address, size)
  const mjModel* m = s.m();
  for (int j : Elements(s, prefix, mjOBJ_JOINT)) {
    const int type = m->jnt_type[j];
    const int nq = type == mjJNT_FREE ? 7 : type == mjJNT_BALL ? 4 : 1;
    const int nv = type == mjJNT_FREE ? 6 : type == mjJNT_BALL ? 3 : 1;
    out.push_back(positions ? std::make_pair(static_cast<int>(m->jnt_qposadr[j]), nq)
                            : std::make_pair(static_cast<int>(m->jnt_dofadr[j]), nv));
  }
  return out;
}

Eigen::VectorXd Gather(const std::vector<std::pair<int, int>>& slices, const double* src) {
  int n = 0;
  for (const auto& sl : slices) n += sl.second;
  Eigen::VectorXd out(n);
  int k = 0;
  for (const auto& [adr, size] : slices)
    for (int i = 0; i < size; ++i) out[k++] = src[adr + i];
  return out;
}

void Scatter(const std::vector<std::pair<int, int>>& slices, const Eigen::VectorXd& v, double* dst,
             const std::string& what) {
  int n = 0;
  for (const auto& sl : slices) n += sl.second;
  if (v.size() != n)
    throw Error(what + ": expected " + std::to_string(n) + " values, got " +
                std::to_string(v.size()));
  if (!v.allFinite()) throw Error(what + ": values must be finite");
  int k = 0;
  for (const auto& [adr, size] : slices)
    for (int i = 0; i < size; ++i) dst[adr + i] = v[k++];
}

}  // namespace

Eigen::VectorXd MjcfModel::GetQpos() const {
  SceneImpl& s = scene_->impl();
  return Gather(Slices(s, Entry(scene_, id_).prefix, true), s.d()->qpos);
}

void MjcfModel::SetQpos(const Eigen::VectorXd& qpos) {
  SceneImpl& s = scene_->impl();
  s.CheckUser();
  Scatter(Slices(s, Entry(scene_, id_).prefix, true), qpos, s.d()->qpos, "set_qpos");
  s.Invalidate();
}

Eigen::VectorXd MjcfModel::GetQvel() const {
  SceneImpl& s = scene_->impl();
  return Gather(Slices(s, Entry(scene_, id_).prefix, false), s.d()->qvel);
}

void MjcfModel::SetQvel(const Eigen::VectorXd& qvel) {
  SceneImpl& s = scene_->impl();
  s.CheckUser();
  Scatter(Slices(s, Entry(scene_, id_).prefix, false), qvel, s.d()->qvel, "set_qvel");
  s.Invalidate();
}

std::vector<std::string> MjcfModel::GetTendonNames() const {
  return ElementNames(scene_, id_, mjOBJ_TENDON);
}

Eigen::VectorXd MjcfModel::GetTendonLengths() const {
  SceneImpl& s = scene_->impl();
  const std::vector<int> ids = Elements(s, Entry(scene_, id_).prefix, mjOBJ_TENDON);
  s.EnsureForward();
  Eigen::VectorXd out(ids.size());
  for (size_t i = 0; i < ids.size(); ++i)
    out[static_cast<Eigen::Index>(i)] = s.d()->ten_length[ids[i]];
  return out;
}

int MjcfModel::MjId(int type, const std::string& name) const {
  SceneImpl& s = scene_->impl();
  s.EnsureCompiled();
  return mj_name2id(s.m(), static_cast<mjtObj>(type), (Entry(scene_, id_).prefix + name).c_str());
}

}  // namespace partsim
