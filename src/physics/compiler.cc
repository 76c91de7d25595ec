// Compiles partsim's scene description into MJCF text for MuJoCo, and after MuJoCo has loaded it,
// resolves the ids that partsim's handles use.
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <utility>

#include "core/number_text.h"
#include "physics/scene_internal.h"

namespace partsim {
namespace internal {
namespace {

void SetQuat(double out[4], const Eigen::Quaterniond& q) {
  const Eigen::Quaterniond n = q.normalized();
  out[0] = n.w();
  out[1] = n.x();
  out[2] = n.y();
  out[3] = n.z();
}

void SetVec(double out[3], const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k) out[k] = v[k];
}

void SetPose(double pos[3], double quat[4], const Pose& pose) {
  SetVec(pos, pose.p);
  SetQuat(quat, pose.q);
}

void SetName(mjsElement* element, const std::string& name) { mjs_setName(element, name.c_str()); }

// Builds the model specification (mjSpec) of a scene through MuJoCo's model-editing API: the
// compiler, option and size settings are parsed from a few lines of MJCF, the bodies, meshes,
// constraints and actuators are added by calls, so that no limit of the XML parser (its nesting
// depth: MuJoCo reads bodies nested in XML) applies to partsim's scenes. Kept as a class so that
// the emitters share the specification and the mesh table.
class SpecWriter {
 public:
  explicit SpecWriter(const SceneImpl& scene) : scene_(scene) {}

  /// After Build(): the first geom that uses each mesh asset.
  const std::map<std::string, std::string>& MeshUsers() const { return mesh_users_; }

  /// The specification, or null with *error set (MuJoCo's message).
  MjSpecPtr Build(std::string* error) {
    const SceneConfig& c = scene_.config;
    const char* integrator = c.integrator == Integrator::kEuler      ? "Euler"
                             : c.integrator == Integrator::kRK4      ? "RK4"
                             : c.integrator == Integrator::kImplicit ? "implicit"
                                                                     : "implicitfast";
    std::ostringstream header;
    header << "<mujoco model=\"partsim\">\n"
           << "  <compiler angle=\"radian\" inertiafromgeom=\"auto\" boundmass=\"1e-6\" "
              "boundinertia=\"1e-9\" autolimits=\"false\"/>\n"
           << "  <option timestep=\"" << Num(c.timestep) << "\" gravity=\"" << Vec(c.gravity)
           << "\" iterations=\"" << c.solver_iterations << "\" integrator=\"" << integrator
           << "\"/>\n"
           << "</mujoco>\n";
    char err[1024] = "";
    spec_.reset(mj_parseXMLString(header.str().c_str(), nullptr, err, sizeof(err)));
    if (!spec_) {
      *error = err;
      return nullptr;
    }
    world_ = mjs_findBody(spec_.get(), "world");
    for (const auto& a : scene_.actors)
      if (a.mjcf < 0) AddActor(a.id, a.desc);
    for (const auto& a : scene_.articulations)
      if (a.mjcf < 0) AddArticulation(a.id, a.desc);
    // MJCF models: each attached (copied) at its pose with its prefix, then the drives partsim
    // gives the joints of the articulations made of them
    mjs_setDeepCopy(spec_.get(), 1);
    for (const auto& model : scene_.mjcf_models) {
      mjsFrame* frame = mjs_addFrame(world_, nullptr);
      SetPose(frame->pos, frame->quat, model.pose);
      if (!mjs_attach(frame->element, model.spec->element, model.prefix.c_str(), "")) {
        *error =
            "MJCF model '" + model.path + "' could not be attached: " + mjs_getError(spec_.get());
        return nullptr;
      }
    }
    for (const auto& a : scene_.articulations)
      if (a.mjcf >= 0) AddMjcfDrives(a);
    AddIgnoreGroupExcludes();
    for (const auto& [a, b] : excludes_) {
      mjsExclude* e = mjs_addExclude(spec_.get());
      mjs_setString(e->bodyname1, a.c_str());
      mjs_setString(e->bodyname2, b.c_str());
    }
    // MuJoCo's arena: contacts, constraint rows and the scratch stack share it, and MuJoCo
    // takes what each step needs from it. Its own estimate sizes it (about 14 MB for a few
    // bodies, growing with the square of the geoms), unless a step has needed more
    // (SceneImpl::arena_capacity, doubled by Step when a step runs out). A scene without
    // collision shapes has no contacts (a rendered dataset object, a kinematic model): it
    // starts with what its dofs need, and grows like the others if a step needs more.
    const long long nv = num_dofs_;
    long long memory = scene_.arena_capacity;
    if (memory == 0 && num_collision_geoms_ == 0)
      memory = (1ll << 19) + 8 * (64 * nv + 4 * nv * nv);
    if (memory > 0) spec_->memory = memory;
    return std::move(spec_);
  }

 private:
  void AddInertial(mjsBody* body, const std::optional<Inertial>& inertial, bool has_collision) {
    if (inertial) {
      body->mass = inertial->mass;
      SetPose(body->ipos, body->iquat, inertial->cmass_local_pose);
      SetVec(body->inertia, inertial->inertia);
      body->explicitinertial = 1;
    } else if (!has_collision) {
      // a body with nothing to derive mass from gets a small one, so it can move
      body->mass = 0.001;
      SetVec(body->ipos, Eigen::Vector3d::Zero());
      SetQuat(body->iquat, Eigen::Quaterniond::Identity());
      SetVec(body->inertia, Eigen::Vector3d::Constant(1e-6));
      body->explicitinertial = 1;
    }
  }

  void AddShapes(mjsBody* body, const std::vector<CollisionShape>& shapes,
                 const std::string& prefix) {
    const SceneConfig& config = scene_.config;
    // SAPIEN's rest offset is the surface's inflation (MuJoCo's margin: force within it) and its
    // contact offset the distance at which contacts are found (MuJoCo's margin + gap); MuJoCo
    // adds up the two shapes' values of a pair, as PhysX does. The skin makes bodies placed
    // exactly touching (distance 0) push from the first step: MuJoCo applies force below the
    // margin only.
    const double margin = config.rest_offset + 0.5 * kTouchSkin;
    const double gap = std::max(0.0, config.contact_offset - config.rest_offset);
    const double dmin = config.contact_impedance, dmax = std::max(dmin, 0.95);
    for (size_t i = 0; i < shapes.size(); ++i) {
      const CollisionShape& s = shapes[i];
      const PhysicalMaterial& mat = s.material ? *s.material : config.default_material;
      const std::string name = prefix + "_g" + std::to_string(i);
      mjsGeom* g = mjs_addGeom(body, nullptr);
      SetName(g->element, name);
      Pose pose = s.pose;
      switch (s.type) {
        case ShapeType::kBox:
          g->type = mjGEOM_BOX;
          SetVec(g->size, s.half_size);
          break;
        case ShapeType::kSphere:
          g->type = mjGEOM_SPHERE;
          g->size[0] = s.radius;
          break;
        case ShapeType::kCapsule:
        case ShapeType::kCylinder:
          g->type = s.type == ShapeType::kCapsule ? mjGEOM_CAPSULE : mjGEOM_CYLINDER;
          g->size[0] = s.radius;
          g->size[1] = s.half_length;
          pose.q = pose.q * kZToX;
          break;
        case ShapeType::kPlane:
          g->type = mjGEOM_PLANE;
          g->size[0] = 0;
          g->size[1] = 0;
          g->size[2] = 1;
          break;
        case ShapeType::kConvexMesh:
          g->type = mjGEOM_MESH;
          mjs_setString(g->meshname, MeshAsset(*s.mesh, name).c_str());
          break;
      }
      SetPose(g->pos, g->quat, pose);
      g->density = s.density;
      g->friction[0] = mat.static_friction;
      g->friction[1] = 0.005;
      g->friction[2] = 0.0001;
      g->solref[0] = 0.02;
      g->solref[1] = RestitutionToDampingRatio(mat.restitution);
      g->solimp[0] = dmin;
      g->solimp[1] = dmax;
      g->margin = margin;
      g->gap = gap;
      // SAPIEN's g0 / g1 follow MuJoCo's contype / conaffinity rule; MuJoCo stores them as
      // signed 32-bit integers
      g->contype = static_cast<int32_t>(s.collision_groups[0]);
      g->conaffinity = static_cast<int32_t>(s.collision_groups[1]);
      ++num_collision_geoms_;
    }
    NoteIgnoreGroups(prefix, shapes);
  }

  // A body can only be ignored as a whole by another when each of its shapes has g2 != 0 and
  // they share one g3; such bodies are kept, by g3, for AddIgnoreGroupExcludes.
  void NoteIgnoreGroups(const std::string& body, const std::vector<CollisionShape>& shapes) {
    if (shapes.empty()) return;
    uint32_t g3 = shapes[0].collision_groups[3];
    for (const CollisionShape& s : shapes)
      if (s.collision_groups[2] == 0 || s.collision_groups[3] != g3) return;
    ignore_candidates_[g3].push_back({body, &shapes});
  }

  // SAPIEN's g2 / g3: shapes A and B never collide when A.g2 & B.g2 != 0 and A.g3 == B.g3.
  // MuJoCo excludes contacts per body pair only, so two bodies are excluded when every pair of
  // their shapes is ignored. Limitation: where only some shape pairs of two bodies are ignored,
  // all of them keep colliding. Only the candidates noted above are compared, pairwise within
  // each g3, so scenes that leave g2 at 0 cost nothing.
  void AddIgnoreGroupExcludes() {
    for (const auto& [g3, bodies] : ignore_candidates_) {
      for (size_t i = 0; i < bodies.size(); ++i) {
        for (size_t j = i + 1; j < bodies.size(); ++j) {
          bool all_ignored = true;
          for (const CollisionShape& a : *bodies[i].second)
            for (const CollisionShape& b : *bodies[j].second)
              all_ignored = all_ignored && (a.collision_groups[2] & b.collision_groups[2]) != 0;
          if (all_ignored) Exclude(bodies[i].first, bodies[j].first);
        }
      }
    }
  }

  // Contacts between two bodies are never generated.
  void Exclude(const std::string& a, const std::string& b) {
    if (a != b) excludes_.insert(a < b ? std::make_pair(a, b) : std::make_pair(b, a));
  }

  // Links joined by a joint never collide. MuJoCo filters a body against its parent's weld group
  // (the bodies fixed to it) only when neither is welded to the world, so the links of a fixed
  // root would still touch their children. Excluded here, for every moving joint: each link
  // rigidly attached (through fixed joints) to its parent against each link rigidly attached to
  // its child; and every pair joined by a fixed joint. Then the pairs the description disables.
  void AddCollisionExcludes(int id, const ArticulationDesc& art) {
    size_t n = art.links.size();
    // rigid group of a link: the topmost link reached through fixed joints (parents come first)
    std::vector<int> group(n);
    std::vector<std::vector<int>> members(n);  // links with shapes, by group
    for (size_t i = 0; i < n; ++i) {
      const LinkDesc& l = art.links[i];
      bool fixed = l.parent >= 0 && l.joint.type == JointType::kFixed;
      group[i] = fixed ? group[l.parent] : static_cast<int>(i);
      if (!l.collisions.empty()) members[group[i]].push_back(static_cast<int>(i));
    }
    auto body = [&](int link) { return LinkBodyName(id, link); };
    for (size_t i = 0; i < n; ++i) {
      const LinkDesc& l = art.links[i];
      if (l.parent < 0) continue;
      if (l.joint.type == JointType::kFixed) {
        if (!l.collisions.empty() && !art.links[l.parent].collisions.empty())
          Exclude(body(l.parent), body(static_cast<int>(i)));
        continue;
      }
      // a rigid group without shapes (the helper link of a compound joint, such as the slide
      // under a rotating slider) is seen through: the group above it counts as the parent
      int p = group[l.parent];
      while (members[p].empty() && art.links[p].parent >= 0) p = group[art.links[p].parent];
      for (int a : members[p])
        for (int b : members[i]) Exclude(body(a), body(b));
    }
    std::map<std::string, int> index;
    for (size_t i = 0; i < n; ++i) index[art.links[i].name] = static_cast<int>(i);
    for (const auto& [a, b] : art.disabled_collisions)
      Exclude(body(index.at(a)), body(index.at(b)));  // Validate() has checked the names
  }

  // Registers a mesh asset (once per MeshData) and returns its name.
  std::string MeshAsset(const MeshData& mesh, const std::string& geom) {
    auto it = mesh_names_.find(&mesh);
    if (it != mesh_names_.end()) return it->second;
    std::string name = "mesh" + std::to_string(mesh_names_.size());
    mesh_names_[&mesh] = name;
    mesh_users_[name] = geom;
    mjsMesh* m = mjs_addMesh(spec_.get(), nullptr);
    SetName(m->element, name);
    // the vertices alone: MuJoCo collides with their convex hull
    mjs_setFloat(m->uservert, mesh.vertices.empty() ? nullptr : mesh.vertices[0].data(),
                 static_cast<int>(3 * mesh.vertices.size()));
    m->maxhullvert = kMaxHullVertices;
    return name;
  }

  void AddActor(int id, const ActorDesc& a) {
    std::string name = ActorBodyName(id);
    mjsBody* body = mjs_addBody(world_, nullptr);
    SetName(body->element, name);
    SetPose(body->pos, body->quat, a.pose);
    if (a.type == ActorType::kKinematic) body->mocap = 1;
    if (a.type == ActorType::kDynamic) {
      mjsJoint* free = mjs_addFreeJoint(body);
      SetName(free->element, name + "_free");
      num_dofs_ += 6;
      AddInertial(body, a.inertial, !a.collisions.empty());
    }
    AddShapes(body, a.collisions, name);
  }

  void AddArticulation(int id, const ArticulationDesc& art) {
    AddCollisionExcludes(id, art);
    if (art.kinematic) {
      // every link is a mocap body placed by forward kinematics
      for (size_t i = 0; i < art.links.size(); ++i) {
        std::string name = LinkBodyName(id, static_cast<int>(i));
        mjsBody* body = mjs_addBody(world_, nullptr);
        SetName(body->element, name);
        SetPose(body->pos, body->quat, art.root_pose);
        body->mocap = 1;
        AddShapes(body, art.links[i].collisions, name);
      }
      return;
    }
    // links in the order of a depth-first walk from the root, each under its parent's body
    std::vector<std::vector<int>> children(art.links.size());
    int root = -1;
    for (size_t i = 0; i < art.links.size(); ++i) {
      if (art.links[i].parent < 0)
        root = static_cast<int>(i);
      else
        children[art.links[i].parent].push_back(static_cast<int>(i));
    }
    std::vector<std::pair<int, mjsBody*>> stack = {{root, world_}};
    while (!stack.empty()) {
      const auto [index, parent] = stack.back();
      stack.pop_back();
      mjsBody* body = AddLink(id, art, index, parent);
      for (auto c = children[index].rbegin(); c != children[index].rend(); ++c)
        stack.push_back({*c, body});
    }
    for (const JointCoupling& c : art.couplings) {
      int joint = FindJoint(art, c.joint), source = FindJoint(art, c.source);
      AddJointEquality(JointMjName(id, joint), JointMjName(id, source), c.offset, c.multiplier);
    }
  }

  static int FindJoint(const ArticulationDesc& art, const std::string& name) {
    for (size_t i = 0; i < art.links.size(); ++i)
      if (art.links[i].parent >= 0 && art.links[i].joint.name == name) return static_cast<int>(i);
    return -1;  // Validate() has already rejected unknown names
  }

  // joint1 = offset + multiplier joint2. Couplings must hold tightly even against stiff,
  // implicitly damped drives: the shortest time constant MuJoCo accepts and the highest
  // impedance.
  void AddJointEquality(const std::string& joint1, const std::string& joint2, double offset,
                        double multiplier) {
    mjsEquality* e = mjs_addEquality(spec_.get(), nullptr);
    e->type = mjEQ_JOINT;
    e->objtype = mjOBJ_JOINT;
    e->active = 1;
    mjs_setString(e->name1, joint1.c_str());
    mjs_setString(e->name2, joint2.c_str());
    std::fill(e->data, e->data + mjNEQDATA, 0.0);
    e->data[0] = offset;
    e->data[1] = multiplier;
    e->solref[0] = 2.0 * scene_.config.timestep;
    e->solref[1] = 1.0;
    const double solimp[5] = {0.9999, 0.9999, 0.001, 0.5, 2};
    std::copy(solimp, solimp + 5, e->solimp);
  }

  mjsBody* AddLink(int id, const ArticulationDesc& art, int index, mjsBody* parent) {
    const LinkDesc& link = art.links[index];
    std::string name = LinkBodyName(id, index);
    Pose X_PC = link.parent < 0 ? art.root_pose
                                : link.joint.pose_in_parent * link.joint.pose_in_child.Inverse();
    mjsBody* body = mjs_addBody(parent, nullptr);
    SetName(body->element, name);
    SetPose(body->pos, body->quat, X_PC);
    if (link.parent < 0 && !art.fix_root) {
      mjsJoint* free = mjs_addFreeJoint(body);
      SetName(free->element, JointMjName(id, index));
      num_dofs_ += 6;
    } else if (link.parent >= 0 && link.joint.type != JointType::kFixed) {
      AddJoint(body, id, index, link.joint);
    }
    bool moves = !(art.fix_root && link.parent < 0);
    if (moves)
      AddInertial(body, link.inertial, !link.collisions.empty());
    else if (link.inertial)
      AddInertial(body, link.inertial, true);
    AddShapes(body, link.collisions, name);
    return body;
  }

  // The drives of an articulation made of an MJCF model's tree: an actuator on each joint, and
  // the inertia of its backward-Euler step on the joint's armature.
  void AddMjcfDrives(const SceneImpl::ArticulationEntry& a) {
    const double drive_dt = DriveStep(scene_.config);
    for (size_t i = 0; i < a.desc.links.size(); ++i) {
      const std::string& name = a.mj_link_joint[i];
      if (name.empty()) continue;
      const JointDesc& j = a.desc.links[i].joint;
      mjsJoint* joint = mjs_asJoint(mjs_findElement(spec_.get(), mjOBJ_JOINT, name.c_str()));
      if (!joint) continue;  // the model changed under it: BuildTables will say
      joint->armature = j.armature + DriveArmature(j.drive, drive_dt);
      AddDrive(a.id, static_cast<int>(i), name, j.drive, drive_dt);
    }
  }

  void AddJoint(mjsBody* body, int id, int index, const JointDesc& j) {
    Eigen::Vector3d axis = j.pose_in_child.q * Eigen::Vector3d::UnitX();
    // rotating x leaves rounding (2e-16) where an axis has zeros: exact zeros let MuJoCo's
    // sparse products skip them (0.8% of a step's time in the drawer bench)
    for (int k = 0; k < 3; ++k)
      if (std::abs(axis[k]) < 1e-12) axis[k] = 0.0;
    num_dofs_ += j.type == JointType::kScrew ? 2 : 1;
    mjsJoint* joint = mjs_addJoint(body, nullptr);
    SetName(joint->element, JointMjName(id, index));
    joint->type = j.type == JointType::kPrismatic ? mjJNT_SLIDE : mjJNT_HINGE;
    SetVec(joint->pos, j.pose_in_child.p);
    SetVec(joint->axis, axis);
    // the implicit integrators step drives by backward Euler: their inertia joins the armature
    const double drive_dt = DriveStep(scene_.config);
    joint->damping[0] = j.damping;
    joint->frictionloss = j.friction;
    joint->armature = j.armature + DriveArmature(j.drive, drive_dt);
    const bool limited =
        std::isfinite(j.lower) && std::isfinite(j.upper) && j.type != JointType::kContinuous;
    joint->limited = limited ? mjLIMITED_TRUE : mjLIMITED_FALSE;
    if (limited) {
      // limits hold hard: the shortest time constant MuJoCo accepts, high impedance
      joint->range[0] = j.lower;
      joint->range[1] = j.upper;
      joint->solref_limit[0] = 2.0 * scene_.config.timestep;
      joint->solref_limit[1] = 1.0;
      const double solimp[5] = {0.99, 0.999, 0.001, 0.5, 2};
      std::copy(solimp, solimp + 5, joint->solimp_limit);
    }
    if (j.type == JointType::kScrew) {
      // the translation follows the rotation through an equality constraint
      mjsJoint* slide = mjs_addJoint(body, nullptr);
      SetName(slide->element, ScrewSlideMjName(id, index));
      slide->type = mjJNT_SLIDE;
      SetVec(slide->pos, j.pose_in_child.p);
      SetVec(slide->axis, axis);
      slide->limited = mjLIMITED_FALSE;
      AddJointEquality(ScrewSlideMjName(id, index), JointMjName(id, index), 0.0, j.pitch);
    }
    AddDrive(id, index, JointMjName(id, index), j.drive, drive_dt);
  }

  // Every joint with a dof gets a PD drive actuator; gains are set at run time (SyncDrive).
  // Backward-Euler drives take their velocity gain in ctrl (SceneImpl::ApplyDrives): a velocity
  // gain here would be integrated implicitly a second time.
  void AddDrive(int id, int index, const std::string& joint, const DriveDesc& d, double drive_dt) {
    mjsActuator* drive = mjs_addActuator(spec_.get(), nullptr);
    SetName(drive->element, ActuatorMjName(id, index));
    drive->trntype = mjTRN_JOINT;
    mjs_setString(drive->target, joint.c_str());
    drive->gaintype = mjGAIN_FIXED;
    std::fill(drive->gainprm, drive->gainprm + mjNGAIN, 0.0);
    drive->gainprm[0] = 1.0;
    drive->biastype = mjBIAS_AFFINE;
    std::fill(drive->biasprm, drive->biasprm + mjNBIAS, 0.0);
    drive->biasprm[1] = -d.stiffness;
    drive->biasprm[2] = drive_dt > 0 ? 0.0 : -d.damping;
    drive->ctrllimited = mjLIMITED_FALSE;
    if (std::isfinite(d.force_limit)) {
      drive->forcelimited = mjLIMITED_TRUE;
      drive->forcerange[0] = -d.force_limit;
      drive->forcerange[1] = d.force_limit;
    } else {
      drive->forcelimited = mjLIMITED_FALSE;
    }
  }

  const SceneImpl& scene_;
  MjSpecPtr spec_;
  mjsBody* world_ = nullptr;
  std::map<const MeshData*, std::string> mesh_names_;
  std::map<std::string, std::string> mesh_users_;  ///< mesh asset -> first geom that uses it
  std::set<std::pair<std::string, std::string>> excludes_;  ///< body pairs, first < second
  /// bodies that may be ignored as a whole (NoteIgnoreGroups) by g3: body name and its shapes
  std::map<uint32_t, std::vector<std::pair<std::string, const std::vector<CollisionShape>*>>>
      ignore_candidates_;
  int num_collision_geoms_ = 0;
  int num_dofs_ = 0;  ///< dofs (MuJoCo's arena)
};

int Id(const mjModel* m, mjtObj type, const std::string& name) {
  return mj_name2id(m, type, name.c_str());
}

}  // namespace

std::string ActorBodyName(int id) { return "a" + std::to_string(id); }
std::string LinkBodyName(int art, int link) {
  return "r" + std::to_string(art) + "_l" + std::to_string(link);
}
std::string JointMjName(int art, int link) {
  return "r" + std::to_string(art) + "_j" + std::to_string(link);
}
std::string ScrewSlideMjName(int art, int link) {
  return "r" + std::to_string(art) + "_s" + std::to_string(link);
}
std::string ActuatorMjName(int art, int link) {
  return "r" + std::to_string(art) + "_d" + std::to_string(link);
}

double RestitutionToDampingRatio(double e) {
  // a linear spring-damper bounces back with e = exp(-zeta pi / sqrt(1 - zeta^2))
  if (e <= 0.0) return 1.0;
  if (e >= 1.0) e = 0.999;
  double l = std::log(e);
  return -l / std::sqrt(M_PI * M_PI + l * l);
}

MjSpecPtr BuildSpec(const SceneImpl& scene, std::string* error,
                    std::map<std::string, std::string>* mesh_users) {
  SpecWriter writer(scene);
  MjSpecPtr spec = writer.Build(error);
  if (mesh_users) *mesh_users = writer.MeshUsers();
  return spec;
}

std::string SaveMjcf(mjSpec* spec) {
  if (!spec) return "";
  char err[1024] = "";
  std::string xml(1 << 16, '\0');
  int need = mj_saveXMLString(spec, xml.data(), static_cast<int>(xml.size()), err, sizeof(err));
  if (need > 0) {
    xml.assign(need + 1, '\0');
    need = mj_saveXMLString(spec, xml.data(), static_cast<int>(xml.size()), err, sizeof(err));
  }
  if (need < 0) return std::string("<!-- MuJoCo could not write the model: ") + err + " -->";
  xml.resize(std::strlen(xml.c_str()));
  return xml;
}

std::string DescribeMjNames(const SceneImpl& scene, const std::string& text,
                            const std::map<std::string, std::string>& mesh_users) {
  auto quoted = [](const std::string& kind, const std::string& name, int id) {
    return name.empty() ? kind + " " + std::to_string(id) : kind + " '" + name + "'";
  };
  // the user's names of a generated MuJoCo name, or "" when it names nothing partsim made
  std::function<std::string(const std::string&)> describe =
      [&](const std::string& name) -> std::string {
    std::smatch m;
    static const std::regex kArt("r(\\d+)_([ljsd])(\\d+)(?:_g(\\d+))?");
    static const std::regex kActor("a(\\d+)(?:_g(\\d+)|(_free))?");
    static const std::regex kMesh("mesh(\\d+)");
    if (std::regex_match(name, m, kArt)) {
      const int id = std::stoi(m[1]), index = std::stoi(m[3]);
      for (const auto& a : scene.articulations) {
        if (a.id != id || index >= static_cast<int>(a.desc.links.size())) continue;
        const LinkDesc& link = a.desc.links[index];
        const std::string art = " of " + quoted("articulation", a.desc.name, id);
        const std::string joint = quoted("joint", link.joint.name, index);
        const char kind = m[2].str()[0];
        if (kind == 'l' && m[4].matched) {
          const size_t k = std::stoul(m[4]);
          std::string out =
              "collision shape " + m[4].str() + " of " + quoted("link", link.name, index) + art;
          if (k < link.collisions.size() && link.collisions[k].mesh &&
              !link.collisions[k].mesh->source.empty())
            out += " (mesh '" + link.collisions[k].mesh->source + "')";
          return out;
        }
        if (kind == 'l') return quoted("link", link.name, index) + art;
        if (kind == 'j' && link.parent < 0) return "the free root joint" + art;
        if (kind == 'j') return joint + art;
        if (kind == 's') return "the slide of screw " + joint + art;
        return "the drive of " + joint + art;
      }
    } else if (std::regex_match(name, m, kActor)) {
      const int id = std::stoi(m[1]);
      for (const auto& a : scene.actors) {
        if (a.id != id) continue;
        const std::string actor = quoted("actor", a.desc.name, id);
        if (m[3].matched) return "the free joint of " + actor;
        if (!m[2].matched) return actor;
        const size_t k = std::stoul(m[2]);
        std::string out = "collision shape " + m[2].str() + " of " + actor;
        if (k < a.desc.collisions.size() && a.desc.collisions[k].mesh &&
            !a.desc.collisions[k].mesh->source.empty())
          out += " (mesh '" + a.desc.collisions[k].mesh->source + "')";
        return out;
      }
    } else if (std::regex_match(name, m, kMesh)) {
      auto it = mesh_users.find(name);
      if (it != mesh_users.end()) {
        std::string user = describe(it->second);
        if (!user.empty()) return "the convex mesh of " + user;
      }
    }
    return "";
  };

  // each generated name (with the kind of element MuJoCo may put before it) becomes the user's
  static const std::regex kName(
      "(?:\\b(?:body|joint|geom|mesh|actuator) )?'?\\b(r\\d+_[ljsd]\\d+(?:_g\\d+)?|a\\d+(?:_g\\d+|_"
      "free)?|mesh\\d+)\\b'?");
  // MuJoCo's "Object name = X" line repeats a name the message may already hold
  std::string message = text;
  static const std::regex kObjectLine(
      "\\s*\\n\\s*(?:Object|Element) name\\s*=?\\s*'?([A-Za-z0-9_]+)'?[^\\n]*");
  std::smatch object;
  if (std::regex_search(message, object, kObjectLine) &&
      message.substr(0, object.position(0)).find(object[1].str()) != std::string::npos)
    message.erase(object.position(0), object.length(0));
  std::string out;
  auto begin = std::sregex_iterator(message.begin(), message.end(), kName);
  size_t last = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    std::string user = describe(m[1]);
    out += message.substr(last, m.position(0) - last);
    out += user.empty() ? m.str(0) : user;
    last = m.position(0) + m.length(0);
  }
  out += message.substr(last);
  // MuJoCo's element ids are its own; a line (of an MJCF model's file) stays
  static const std::regex kWhere(",? ?\\(?id = -?\\d+(?:, line = -?\\d+, column = -?\\d+)?\\)?");
  out = std::regex_replace(out, kWhere, "");
  static const std::regex kId(",? id -?\\d+");
  out = std::regex_replace(out, kId, "");
  static const std::regex kObject("\\s*\\n\\s*(?:Object|Element) name\\s*=?\\s*");
  out = std::regex_replace(out, kObject, " in ");
  static const std::regex kError("^Error: ");
  out = std::regex_replace(out, kError, "");
  while (!out.empty() && std::isspace(static_cast<unsigned char>(out.back()))) out.pop_back();
  return out;
}

void SyncActorDamping(Model& model, const ActorDesc& desc, const CompiledActor& c) {
  if (c.dofadr < 0) return;
  mjModel* m = model.mj.get();
  const int b = c.body;
  // the free joint's translational dofs move the body in the world, its rotational dofs turn it
  // about its own axes: damping b = rate x (mass, or the inertia about that body axis) gives
  // dv/dt = -rate v, and MuJoCo integrates joint damping implicitly
  const Eigen::Quaterniond q(m->body_iquat[4 * b], m->body_iquat[4 * b + 1],
                             m->body_iquat[4 * b + 2], m->body_iquat[4 * b + 3]);
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  const Eigen::Vector3d principal(m->body_inertia[3 * b], m->body_inertia[3 * b + 1],
                                  m->body_inertia[3 * b + 2]);
  const Eigen::Matrix3d inertia = R * principal.asDiagonal() * R.transpose();
  for (int k = 0; k < 3; ++k) {
    m->dof_damping[c.dofadr + k] = desc.linear_damping * m->body_mass[b];
    m->dof_damping[c.dofadr + 3 + k] = desc.angular_damping * inertia(k, k);
  }
}

CompiledDrive CompileDrive(const DriveDesc& drive, double dt) {
  CompiledDrive out;
  out.stiffness = drive.stiffness;
  out.damping = drive.damping;
  // backward Euler (the implicit integrator): the velocity gain acts on the velocity at the
  // step's start and the armature makes up the rest; explicit integrators: the damping is in
  // the actuator's bias
  out.velocity_gain = dt > 0 ? DriveVelocityGain(drive, dt) : 0.0;
  out.armature = DriveArmature(drive, dt);
  return out;
}

void BuildTables(const SceneImpl& s, Model& model) {
  const mjModel* m = model.mj.get();
  model.actors.clear();
  model.articulations.clear();
  model.geom_owner.assign(m->ngeom, GeomOwner());
  const double drive_dt = DriveStep(s.config);

  auto own_geoms = [&](const std::string& prefix, size_t count, GeomOwner owner) {
    for (size_t i = 0; i < count; ++i) {
      int g = Id(m, mjOBJ_GEOM, prefix + "_g" + std::to_string(i));
      owner.shape_index = static_cast<int>(i);
      if (g >= 0) model.geom_owner[g] = owner;
    }
  };

  // an MJCF entity's geoms, by their names in the model
  auto own_named_geoms = [&](const std::vector<std::string>& names, GeomOwner owner) {
    for (size_t i = 0; i < names.size(); ++i) {
      int g = Id(m, mjOBJ_GEOM, names[i]);
      owner.shape_index = static_cast<int>(i);
      if (g >= 0) model.geom_owner[g] = owner;
    }
  };
  for (const auto& a : s.actors) {
    CompiledActor c;
    const bool mjcf = a.mjcf >= 0;
    std::string name = mjcf ? a.mj_body : ActorBodyName(a.id);
    c.body = Id(m, mjOBJ_BODY, name);
    if (c.body < 0)
      throw Error("the MJCF body '" + name + "' of actor '" + a.desc.name +
                  "' is no longer in the model");
    c.mocap = m->body_mocapid[c.body];
    int j = mjcf ? (c.body > 0 && m->body_jntnum[c.body] == 1 &&
                            m->jnt_type[m->body_jntadr[c.body]] == mjJNT_FREE
                        ? m->body_jntadr[c.body]
                        : -1)
                 : Id(m, mjOBJ_JOINT, name + "_free");
    if (j >= 0) {
      c.qposadr = m->jnt_qposadr[j];
      c.dofadr = m->jnt_dofadr[j];
    }
    model.actors[a.id] = c;
    if (!mjcf) SyncActorDamping(model, a.desc, c);
    GeomOwner owner;
    owner.actor_id = a.id;
    if (mjcf)
      own_named_geoms(a.mj_geoms, owner);
    else
      own_geoms(name, a.desc.collisions.size(), owner);
  }

  for (const auto& a : s.articulations) {
    const ArticulationDesc& desc = a.desc;
    CompiledArticulation c;
    c.kinematic = desc.kinematic;
    size_t n = desc.links.size();
    c.link_body.resize(n);
    c.link_mocap.assign(n, -1);
    c.joints.resize(n);
    std::map<std::string, int> link_of_joint;
    const bool mjcf = a.mjcf >= 0;
    for (size_t i = 0; i < n; ++i) {
      std::string name = mjcf ? a.mj_link_body[i] : LinkBodyName(a.id, static_cast<int>(i));
      c.link_body[i] = Id(m, mjOBJ_BODY, name);
      if (c.link_body[i] < 0)
        throw Error("the MJCF body '" + name + "' of articulation '" + desc.name +
                    "' is no longer in the model");
      c.link_mocap[i] = m->body_mocapid[c.link_body[i]];
      GeomOwner owner;
      owner.articulation_id = a.id;
      owner.link_index = static_cast<int>(i);
      if (mjcf)
        own_named_geoms(a.mj_link_geoms[i], owner);
      else
        own_geoms(name, desc.links[i].collisions.size(), owner);
      if (desc.links[i].parent >= 0) link_of_joint[desc.links[i].joint.name] = static_cast<int>(i);
    }
    // free root
    if (!desc.kinematic && !desc.fix_root) {
      for (size_t i = 0; i < n; ++i) {
        if (desc.links[i].parent >= 0) continue;
        int j = mjcf ? m->body_jntadr[c.link_body[i]]
                     : Id(m, mjOBJ_JOINT, JointMjName(a.id, static_cast<int>(i)));
        c.root_qposadr = m->jnt_qposadr[j];
        c.root_dofadr = m->jnt_dofadr[j];
      }
    }
    // dofs as the kinematic model numbers them (DofLinks); a coupled joint (URDF mimic) is a
    // dof of its own with its own drive, held to its source by an equality constraint
    c.dof_links = DofLinks(desc);
    for (size_t k = 0; k < c.dof_links.size(); ++k) {
      const size_t i = static_cast<size_t>(c.dof_links[k]);
      const LinkDesc& link = desc.links[i];
      CompiledJoint& cj = c.joints[i];
      if (!desc.kinematic) {
        cj.mj_joint =
            Id(m, mjOBJ_JOINT, mjcf ? a.mj_link_joint[i] : JointMjName(a.id, static_cast<int>(i)));
        cj.qposadr = m->jnt_qposadr[cj.mj_joint];
        cj.dofadr = m->jnt_dofadr[cj.mj_joint];
        if (link.joint.type == JointType::kScrew) {
          int sj = Id(m, mjOBJ_JOINT, ScrewSlideMjName(a.id, static_cast<int>(i)));
          cj.screw_slide_qposadr = m->jnt_qposadr[sj];
          cj.screw_slide_dofadr = m->jnt_dofadr[sj];
        }
      }
      cj.dof_index = static_cast<int>(k);
      if (!desc.kinematic) {
        cj.actuator = Id(m, mjOBJ_ACTUATOR, ActuatorMjName(a.id, static_cast<int>(i)));
        cj.drive = CompileDrive(link.joint.drive, drive_dt);
      }
    }
    for (const JointCoupling& cp : desc.couplings) {
      CompiledCoupling cc;
      cc.dof = c.joints[link_of_joint[cp.joint]].dof_index;
      cc.source_dof = c.joints[link_of_joint[cp.source]].dof_index;
      cc.multiplier = cp.multiplier;
      cc.offset = cp.offset;
      c.couplings.push_back(cc);
    }
    // G: partsim dof velocities -> MuJoCo dof velocities of this articulation
    if (!desc.kinematic) {
      std::vector<std::pair<int, std::pair<int, double>>> rows;  // mj dof -> (dof, factor)
      for (int li : c.dof_links) {
        const CompiledJoint& cj = c.joints[li];
        rows.push_back({cj.dofadr, {cj.dof_index, 1.0}});
        if (cj.screw_slide_dofadr >= 0)
          rows.push_back({cj.screw_slide_dofadr, {cj.dof_index, desc.links[li].joint.pitch}});
      }
      std::sort(rows.begin(), rows.end());
      c.G = Eigen::MatrixXd::Zero(rows.size(), c.dof_links.size());
      for (size_t r = 0; r < rows.size(); ++r) {
        c.mj_dofs.push_back(rows[r].first);
        if (rows[r].second.first >= 0) c.G(r, rows[r].second.first) = rows[r].second.second;
      }
    }
    model.articulations[a.id] = std::move(c);
  }
}

}  // namespace internal
}  // namespace partsim
