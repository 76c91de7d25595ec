// Compiles partsim's scene description into MJCF text for MuJoCo, and after MuJoCo has loaded it,
// resolves the ids that partsim's handles use.
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
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

// MuJoCo capsules and cylinders lie along z; partsim's along x: rotate z onto x.
const Eigen::Quaterniond kZToX(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));

std::string Quat(const Eigen::Quaterniond& q) {
  Eigen::Quaterniond n = q.normalized();
  return Num(n.w()) + " " + Num(n.x()) + " " + Num(n.y()) + " " + Num(n.z());
}

std::string PoseAttrs(const Pose& pose) {
  return " pos=\"" + Vec(pose.p) + "\" quat=\"" + Quat(pose.q) + "\"";
}

// Writes the MJCF of a scene. Kept as a class so that the emitters share the output stream and
// the mesh asset table.
class MjcfWriter {
 public:
  explicit MjcfWriter(const SceneImpl& scene) : scene_(scene) {}

  /// After Write(): the first geom that uses each mesh asset.
  const std::map<std::string, std::string>& MeshUsers() const { return mesh_users_; }

  std::string Write() {
    const SceneConfig& c = scene_.config;
    const char* integrator = c.integrator == Integrator::kEuler ? "Euler"
                             : c.integrator == Integrator::kRK4 ? "RK4"
                                                                : "implicit";
    // bodies first: they collect mesh assets and equality constraints
    for (const auto& a : scene_.actors) WriteActor(a.id, a.desc);
    for (const auto& a : scene_.articulations) WriteArticulation(a.id, a.desc);
    WriteIgnoreGroupExcludes();

    std::ostringstream out;
    out << "<mujoco model=\"partsim\">\n"
        << "  <compiler angle=\"radian\" inertiafromgeom=\"auto\" boundmass=\"1e-6\" "
           "boundinertia=\"1e-9\"/>\n"
        << "  <option timestep=\"" << Num(c.timestep) << "\" gravity=\"" << Vec(c.gravity)
        << "\" iterations=\"" << c.solver_iterations << "\" integrator=\"" << integrator
        << "\"/>\n";
    // Contact and constraint buffers. MuJoCo 2.2.2 allocates them in mj_makeData, with dense
    // njmax x njmax and njmax x nv matrices, so they are sized from the contacts the scene has
    // needed (SceneImpl::Step doubles them when a step fills them), not from its size: memory
    // grows with the contacts, not with the square of the bodies. The rows always cover every
    // contact (4 rows each: condim 3, pyramidal cone), so contacts overflow before rows do.
    // A scene without collision shapes has no contacts (a rendered dataset object, a
    // kinematic model): its buffers start small instead of at about 20 MB, which mj_makeData
    // zeroes, and grow like the others if a step needs more.
    const bool contacts = num_collision_geoms_ > 0;
    const int nconmax = std::max(scene_.contact_capacity, contacts ? kBaseContacts : 4);
    const int njmax =
        4 * nconmax + 4 * num_limits_ + 6 * num_equalities_ + 2 * num_friction_dofs_ + 100;
    // MuJoCo's scratch stack: its own default scales with njmax and came out too small with
    // the buffers above ("Stack overflow" at compile). MuJoCo 2.2.2's implicit integrator works
    // on dense nv x nv matrices: 300 free boxes (nv 1,800) need 33-36 M numbers, about 11 nv^2;
    // the explicit integrators need under nv^2 / 36 (1,000 boxes: 0.5-1 M). Without contacts,
    // the constraint projection's njmax x nv block bounds the rest
    const long long nv = num_dofs_;
    const long long dense = c.integrator == Integrator::kImplicit ? 12 * nv * nv : nv * nv / 32;
    const long long floor = contacts ? 1000000 : 50000 + nv * njmax;
    const long long nstack =
        std::max(floor + 60 * nv + 20ll * njmax + dense, scene_.stack_capacity);
    out << "  <size nconmax=\"" << nconmax << "\" njmax=\"" << njmax << "\" nstack=\"" << nstack
        << "\"/>\n";
    if (!assets_.str().empty()) out << "  <asset>\n" << assets_.str() << "  </asset>\n";
    out << "  <worldbody>\n" << bodies_.str() << "  </worldbody>\n";
    if (!excludes_.empty()) {
      out << "  <contact>\n";
      for (const auto& [a, b] : excludes_)
        out << "    <exclude body1=\"" << a << "\" body2=\"" << b << "\"/>\n";
      out << "  </contact>\n";
    }
    if (!equality_.str().empty()) out << "  <equality>\n" << equality_.str() << "  </equality>\n";
    if (!actuators_.str().empty()) out << "  <actuator>\n" << actuators_.str() << "  </actuator>\n";
    out << "</mujoco>\n";
    return out.str();
  }

 private:
  void Indent(int depth) { bodies_ << std::string(2 * depth + 4, ' '); }

  void WriteInertial(const std::optional<Inertial>& inertial, bool has_collision, int depth) {
    if (inertial) {
      Indent(depth);
      bodies_ << "<inertial" << PoseAttrs(inertial->cmass_local_pose) << " mass=\""
              << Num(inertial->mass) << "\" diaginertia=\"" << Vec(inertial->inertia) << "\"/>\n";
    } else if (!has_collision) {
      // a body with nothing to derive mass from gets a small one, so it can move
      Indent(depth);
      bodies_ << "<inertial pos=\"0 0 0\" mass=\"0.001\" diaginertia=\"1e-6 1e-6 1e-6\"/>\n";
    }
  }

  void WriteShapes(const std::vector<CollisionShape>& shapes, const std::string& prefix,
                   int depth) {
    for (size_t i = 0; i < shapes.size(); ++i) {
      const CollisionShape& s = shapes[i];
      const PhysicalMaterial& mat = s.material ? *s.material : scene_.config.default_material;
      Pose pose = s.pose;
      std::string type, size;
      switch (s.type) {
        case ShapeType::kBox:
          type = "box";
          size = Vec(s.half_size);
          break;
        case ShapeType::kSphere:
          type = "sphere";
          size = Num(s.radius);
          break;
        case ShapeType::kCapsule:
        case ShapeType::kCylinder:
          type = s.type == ShapeType::kCapsule ? "capsule" : "cylinder";
          size = Num(s.radius) + " " + Num(s.half_length);
          pose.q = pose.q * kZToX;
          break;
        case ShapeType::kPlane:
          type = "plane";
          size = "0 0 1";
          break;
        case ShapeType::kConvexMesh: {
          type = "mesh";
          size = "";
          break;
        }
      }
      Indent(depth);
      bodies_ << "<geom name=\"" << prefix << "_g" << i << "\" type=\"" << type << "\"";
      if (!size.empty()) bodies_ << " size=\"" << size << "\"";
      if (s.type == ShapeType::kConvexMesh)
        bodies_ << " mesh=\"" << MeshAsset(*s.mesh, prefix + "_g" + std::to_string(i)) << "\"";
      bodies_ << PoseAttrs(pose) << " density=\"" << Num(s.density) << "\" friction=\""
              << Num(mat.static_friction) << " 0.005 0.0001\" solref=\"0.02 "
              << Num(RestitutionToDampingRatio(mat.restitution)) << "\"";
      // SAPIEN's g0 / g1 follow MuJoCo's contype / conaffinity rule; MuJoCo stores them as
      // signed 32-bit integers (MuJoCo's default is 1)
      const std::array<uint32_t, 4>& g = s.collision_groups;
      if (g[0] != 1u) bodies_ << " contype=\"" << static_cast<int32_t>(g[0]) << "\"";
      if (g[1] != 1u) bodies_ << " conaffinity=\"" << static_cast<int32_t>(g[1]) << "\"";
      bodies_ << "/>\n";
      ++num_collision_geoms_;
    }
    NoteIgnoreGroups(prefix, shapes);
  }

  // A body can only be ignored as a whole by another when each of its shapes has g2 != 0 and
  // they share one g3; such bodies are kept, by g3, for WriteIgnoreGroupExcludes.
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
  void WriteIgnoreGroupExcludes() {
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
  void WriteCollisionExcludes(int id, const ArticulationDesc& art) {
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
    assets_ << "    <mesh name=\"" << name << "\" vertex=\"";
    char buf[64];
    for (const auto& v : mesh.vertices) {
      std::snprintf(buf, sizeof(buf), "%.9g %.9g %.9g ", v.x(), v.y(), v.z());
      assets_ << buf;
    }
    assets_ << "\"/>\n";
    return name;
  }

  void WriteActor(int id, const ActorDesc& a) {
    std::string name = ActorBodyName(id);
    Indent(0);
    bodies_ << "<body name=\"" << name << "\"" << PoseAttrs(a.pose);
    if (a.type == ActorType::kKinematic) bodies_ << " mocap=\"true\"";
    bodies_ << ">\n";
    if (a.type == ActorType::kDynamic) {
      Indent(1);
      bodies_ << "<freejoint name=\"" << name << "_free\"/>\n";
      num_dofs_ += 6;
    }
    if (a.type == ActorType::kDynamic) WriteInertial(a.inertial, !a.collisions.empty(), 1);
    WriteShapes(a.collisions, name, 1);
    Indent(0);
    bodies_ << "</body>\n";
  }

  void WriteArticulation(int id, const ArticulationDesc& art) {
    WriteCollisionExcludes(id, art);
    if (art.kinematic) {
      // every link is a mocap body placed by forward kinematics
      for (size_t i = 0; i < art.links.size(); ++i) {
        std::string name = LinkBodyName(id, static_cast<int>(i));
        Indent(0);
        bodies_ << "<body name=\"" << name << "\" mocap=\"true\"" << PoseAttrs(art.root_pose)
                << ">\n";
        WriteShapes(art.links[i].collisions, name, 1);
        Indent(0);
        bodies_ << "</body>\n";
      }
      return;
    }
    std::vector<std::vector<int>> children(art.links.size());
    int root = -1;
    for (size_t i = 0; i < art.links.size(); ++i) {
      if (art.links[i].parent < 0)
        root = static_cast<int>(i);
      else
        children[art.links[i].parent].push_back(static_cast<int>(i));
    }
    WriteLink(id, art, root, children, 0);
    for (const JointCoupling& c : art.couplings) {
      int joint = FindJoint(art, c.joint), source = FindJoint(art, c.source);
      equality_ << "    <joint joint1=\"" << JointMjName(id, joint) << "\" joint2=\""
                << JointMjName(id, source) << "\" polycoef=\"" << Num(c.offset) << " "
                << Num(c.multiplier) << " 0 0 0\"" << EqualitySolver() << "/>\n";
      ++num_equalities_;
    }
  }

  static int FindJoint(const ArticulationDesc& art, const std::string& name) {
    for (size_t i = 0; i < art.links.size(); ++i)
      if (art.links[i].parent >= 0 && art.links[i].joint.name == name) return static_cast<int>(i);
    return -1;  // Validate() has already rejected unknown names
  }

  // Couplings must hold tightly even against stiff, implicitly damped drives: the shortest time
  // constant MuJoCo accepts and the highest impedance.
  std::string EqualitySolver() const {
    return " solref=\"" + Num(2.0 * scene_.config.timestep) +
           " 1\" solimp=\"0.9999 0.9999 0.001 0.5 2\"";
  }

  void WriteLink(int id, const ArticulationDesc& art, int index,
                 const std::vector<std::vector<int>>& children, int depth) {
    const LinkDesc& link = art.links[index];
    std::string name = LinkBodyName(id, index);
    Pose X_PC = link.parent < 0 ? art.root_pose
                                : link.joint.pose_in_parent * link.joint.pose_in_child.Inverse();
    Indent(depth);
    bodies_ << "<body name=\"" << name << "\"" << PoseAttrs(X_PC) << ">\n";
    if (link.parent < 0 && !art.fix_root) {
      Indent(depth + 1);
      bodies_ << "<freejoint name=\"" << JointMjName(id, index) << "\"/>\n";
    } else if (link.parent >= 0 && link.joint.type != JointType::kFixed) {
      WriteJoint(id, index, link.joint, depth + 1);
    }
    bool moves = !(art.fix_root && link.parent < 0);
    if (moves)
      WriteInertial(link.inertial, !link.collisions.empty(), depth + 1);
    else if (link.inertial)
      WriteInertial(link.inertial, true, depth + 1);
    WriteShapes(link.collisions, name, depth + 1);
    for (int c : children[index]) WriteLink(id, art, c, children, depth + 1);
    Indent(depth);
    bodies_ << "</body>\n";
  }

  void WriteJoint(int id, int index, const JointDesc& j, int depth) {
    Eigen::Vector3d axis = j.pose_in_child.q * Eigen::Vector3d::UnitX();
    // rotating x leaves rounding (2e-16) where an axis has zeros: exact zeros let MuJoCo's
    // sparse products skip them (0.8% of a step's time in the drawer bench)
    for (int k = 0; k < 3; ++k)
      if (std::abs(axis[k]) < 1e-12) axis[k] = 0.0;
    num_dofs_ += j.type == JointType::kScrew ? 2 : 1;
    if (j.friction > 0) num_friction_dofs_ += j.type == JointType::kScrew ? 2 : 1;
    std::string where = " pos=\"" + Vec(j.pose_in_child.p) + "\" axis=\"" + Vec(axis) + "\"";
    // the implicit integrator steps drives by backward Euler: their inertia joins the armature
    const double drive_dt = DriveStep(scene_.config);
    std::string dyn = " damping=\"" + Num(j.damping) + "\" frictionloss=\"" + Num(j.friction) +
                      "\" armature=\"" + Num(j.armature + DriveArmature(j.drive, drive_dt)) + "\"";
    bool limited =
        std::isfinite(j.lower) && std::isfinite(j.upper) && j.type != JointType::kContinuous;
    // limits hold hard: the shortest time constant MuJoCo accepts, high impedance
    std::string limits = limited
                             ? " limited=\"true\" range=\"" + Num(j.lower) + " " + Num(j.upper) +
                                   "\" solreflimit=\"" + Num(2.0 * scene_.config.timestep) +
                                   " 1\" solimplimit=\"0.99 0.999 0.001 0.5 2\""
                             : " limited=\"false\"";
    if (limited) ++num_limits_;
    const char* type = j.type == JointType::kPrismatic ? "slide" : "hinge";
    Indent(depth);
    bodies_ << "<joint name=\"" << JointMjName(id, index) << "\" type=\"" << type << "\"" << where
            << dyn << limits << "/>\n";
    if (j.type == JointType::kScrew) {
      // the translation follows the rotation through an equality constraint
      Indent(depth);
      bodies_ << "<joint name=\"" << ScrewSlideMjName(id, index) << "\" type=\"slide\"" << where
              << " limited=\"false\"/>\n";
      equality_ << "    <joint joint1=\"" << ScrewSlideMjName(id, index) << "\" joint2=\""
                << JointMjName(id, index) << "\" polycoef=\"0 " << Num(j.pitch) << " 0 0 0\""
                << EqualitySolver() << "/>\n";
      ++num_equalities_;
    }
    // every joint with a dof gets a PD drive actuator; gains are set at run time (SyncDrive).
    // Backward-Euler drives take their velocity gain in ctrl (SceneImpl::ApplyDrives): a velocity
    // gain here would be integrated implicitly a second time.
    actuators_ << "    <general name=\"" << ActuatorMjName(id, index) << "\" joint=\""
               << JointMjName(id, index) << "\" gaintype=\"fixed\" gainprm=\"1\" "
               << "biastype=\"affine\" biasprm=\"0 " << Num(-j.drive.stiffness) << " "
               << Num(drive_dt > 0 ? 0.0 : -j.drive.damping) << "\" ctrllimited=\"false\"";
    if (std::isfinite(j.drive.force_limit))
      actuators_ << " forcelimited=\"true\" forcerange=\"" << Num(-j.drive.force_limit) << " "
                 << Num(j.drive.force_limit) << "\"";
    actuators_ << "/>\n";
  }

  const SceneImpl& scene_;
  std::ostringstream bodies_, assets_, equality_, actuators_;
  std::map<const MeshData*, std::string> mesh_names_;
  std::map<std::string, std::string> mesh_users_;  ///< mesh asset -> first geom that uses it
  std::set<std::pair<std::string, std::string>> excludes_;  ///< body pairs, first < second
  /// bodies that may be ignored as a whole (NoteIgnoreGroups) by g3: body name and its shapes
  std::map<uint32_t, std::vector<std::pair<std::string, const std::vector<CollisionShape>*>>>
      ignore_candidates_;
  int num_collision_geoms_ = 0;
  int num_dofs_ = 0;           ///< dofs (MuJoCo's stack)
  int num_friction_dofs_ = 0;  ///< dofs with dry friction (a friction-loss row each)
  int num_limits_ = 0;
  int num_equalities_ = 0;
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

std::string GenerateMjcf(const SceneImpl& scene) { return MjcfWriter(scene).Write(); }

std::string DescribeMjNames(const SceneImpl& scene, const std::string& text) {
  MjcfWriter writer(scene);
  writer.Write();
  const std::map<std::string, std::string>& mesh_users = writer.MeshUsers();
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
  // MuJoCo's positions point into the generated MJCF, which the user never wrote
  static const std::regex kWhere(",? ?\\(?id = -?\\d+(?:, line = -?\\d+, column = -?\\d+)?\\)?");
  out = std::regex_replace(out, kWhere, "");
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

  for (const auto& a : s.actors) {
    CompiledActor c;
    std::string name = ActorBodyName(a.id);
    c.body = Id(m, mjOBJ_BODY, name);
    c.mocap = m->body_mocapid[c.body];
    int j = Id(m, mjOBJ_JOINT, name + "_free");
    if (j >= 0) {
      c.qposadr = m->jnt_qposadr[j];
      c.dofadr = m->jnt_dofadr[j];
    }
    model.actors[a.id] = c;
    SyncActorDamping(model, a.desc, c);
    GeomOwner owner;
    owner.actor_id = a.id;
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
    for (size_t i = 0; i < n; ++i) {
      std::string name = LinkBodyName(a.id, static_cast<int>(i));
      c.link_body[i] = Id(m, mjOBJ_BODY, name);
      c.link_mocap[i] = m->body_mocapid[c.link_body[i]];
      GeomOwner owner;
      owner.articulation_id = a.id;
      owner.link_index = static_cast<int>(i);
      own_geoms(name, desc.links[i].collisions.size(), owner);
      if (desc.links[i].parent >= 0) link_of_joint[desc.links[i].joint.name] = static_cast<int>(i);
    }
    // free root
    if (!desc.kinematic && !desc.fix_root) {
      for (size_t i = 0; i < n; ++i) {
        if (desc.links[i].parent >= 0) continue;
        int j = Id(m, mjOBJ_JOINT, JointMjName(a.id, static_cast<int>(i)));
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
        cj.mj_joint = Id(m, mjOBJ_JOINT, JointMjName(a.id, static_cast<int>(i)));
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
