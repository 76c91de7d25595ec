// Reads a PartNet-Mobility folder and cross-checks its files (docs/partnet_mobility_format.md).
#include "partsim/assets/partnet_mobility.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/file_read.h"
#include "core/json_parse.h"
#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "partsim/physics/kinematics.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kAxisTolerance = 1e-4;   // m and unit-vector components
constexpr double kLimitTolerance = 1e-4;  // rad or m

double Radians(double degrees) { return degrees * M_PI / 180.0; }

// Errors name the folder's file and the entry at fault.
[[noreturn]] void Fail(const fs::path& file, const std::string& what) {
  throw Error("PartNet-Mobility " + file.string() + ": " + what);
}

fs::path Require(const fs::path& folder, const char* name) {
  fs::path p = folder / name;
  if (!fs::is_regular_file(p)) Fail(p, "file is missing");
  return p;
}

json ReadJson(const fs::path& file) {
  std::string text;
  try {
    text = internal::ReadWholeFile(file.string(), "file");
  } catch (const Error& e) {
    Fail(file, e.what());
  }
  try {
    return internal::ParseJsonBounded(text);
  } catch (const json::exception& e) {
    Fail(file, std::string("malformed JSON: ") + e.what());
  }
}

// Typed field access with errors naming the entry and field.
class Fields {
 public:
  Fields(const fs::path& file, std::string where) : file_(file), where_(std::move(where)) {}

  const json& Get(const json& obj, const char* key) const {
    if (!obj.is_object() || !obj.contains(key)) Fail(file_, where_ + ": missing '" + key + "'");
    return obj.at(key);
  }
  double Number(const json& obj, const char* key) const {
    const json& v = Get(obj, key);
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      Fail(file_, where_ + ": '" + key + "' must be a finite number");
    return v.get<double>();
  }
  int Int(const json& obj, const char* key) const {
    const json& v = Get(obj, key);
    if (!v.is_number_integer()) Fail(file_, where_ + ": '" + key + "' must be an integer");
    return v.get<int>();
  }
  std::string String(const json& obj, const char* key) const {
    const json& v = Get(obj, key);
    if (!v.is_string()) Fail(file_, where_ + ": '" + key + "' must be a string");
    return v.get<std::string>();
  }
  bool Bool(const json& obj, const char* key, bool fallback) const {
    if (!obj.is_object() || !obj.contains(key)) return fallback;
    const json& v = obj.at(key);
    if (!v.is_boolean()) Fail(file_, where_ + ": '" + key + "' must be true or false");
    return v.get<bool>();
  }
  Eigen::Vector3d Vec3(const json& obj, const char* key) const {
    const json& v = Get(obj, key);
    if (!v.is_array() || v.size() != 3)
      Fail(file_, where_ + ": '" + key + "' must be a list of 3 numbers");
    Eigen::Vector3d out;
    for (int k = 0; k < 3; ++k) {
      if (!v[k].is_number() || !std::isfinite(v[k].get<double>()))
        Fail(file_, where_ + ": '" + key + "' must hold finite numbers");
      out[k] = v[k].get<double>();
    }
    return out;
  }

 private:
  fs::path file_;
  std::string where_;
};

PartNetLink ReadLinkEntry(const json& e, size_t index, const fs::path& file) {
  Fields f(file, "entry " + std::to_string(index));
  PartNetLink l;
  l.id = f.Int(e, "id");
  Fields g(file, "entry " + std::to_string(index) + " (link_" + std::to_string(l.id) + ")");
  l.parent = g.Int(e, "parent");
  l.joint = g.String(e, "joint");
  static const char* kTypes[] = {"hinge", "slider", "free", "heavy", "static"};
  if (std::find(std::begin(kTypes), std::end(kTypes), l.joint) == std::end(kTypes))
    Fail(file, "entry " + std::to_string(index) + " (link_" + std::to_string(l.id) +
                   "): unknown joint type '" + l.joint +
                   "' (expected hinge, slider, free, heavy or static)");
  l.partnet_name = g.String(e, "name");
  l.semantic_label = l.partnet_name;  // until semantics.txt gives the label
  if (e.contains("parts")) {
    const json& parts = e.at("parts");
    if (!parts.is_array()) Fail(file, "link_" + std::to_string(l.id) + ": 'parts' must be a list");
    for (const json& p : parts) {
      if (p.is_null()) continue;  // the dataset leaves holes in some part lists
      l.parts.push_back({g.Int(p, "id"), g.String(p, "name"), {}});
    }
  }
  if (l.joint == "hinge" || l.joint == "slider") {
    const json& data = g.Get(e, "jointData");
    const json& axis = g.Get(data, "axis");
    l.has_axis = true;
    l.axis_origin = g.Vec3(axis, "origin");
    l.axis_direction = g.Vec3(axis, "direction");
    if (l.axis_direction.norm() < 1e-9)
      Fail(file, "link_" + std::to_string(l.id) + ": axis direction is zero");
    l.axis_direction.normalize();
    const json& limit = g.Get(data, "limit");
    l.no_limit = g.Bool(limit, "noLimit", false);
    if (!l.no_limit) {
      l.limit_a = g.Number(limit, "a");
      l.limit_b = g.Number(limit, "b");
    }
    if (l.joint == "slider") {
      l.rotates = g.Bool(limit, "rotates", false);
      l.no_rotation_limit = g.Bool(limit, "noRotationLimit", false);
      if (l.rotates && !l.no_rotation_limit) l.rotation_limit = g.Number(limit, "rotationLimit");
    }
  }
  return l;
}

// Forward kinematics at q = 0 (coupled joints where their sources put them) of a description
// with its root at the origin: X_BL per link.
std::vector<Pose> RestPoses(const ArticulationDesc& desc) {
  KinematicModel model(desc);
  model.SetRootPose(Pose());
  return model.ForwardKinematics(Eigen::VectorXd::Zero(model.Dof()));
}

int FindLink(const ArticulationDesc& desc, const std::string& name) {
  for (size_t i = 0; i < desc.links.size(); ++i)
    if (desc.links[i].name == name) return static_cast<int>(i);
  return -1;
}

// Records what the reader works around: a warning in the object's report, or an error when the
// loader is strict.
class Notes {
 public:
  Notes(bool strict, LoadReport* report) : strict_(strict), report_(report) {}
  void Warn(const fs::path& file, const std::string& what) const {
    if (strict_) Fail(file, what + " (strict loading)");
    report_->Warn("PartNet-Mobility " + file.string(), what);
  }

 private:
  bool strict_;
  LoadReport* report_;
};

// Indices of the visuals of `link` named "<anything>-<part id>".
std::vector<int> VisualsOfPart(const LinkDesc& link, int part_id) {
  const std::string suffix = "-" + std::to_string(part_id);
  std::vector<int> out;
  for (size_t v = 0; v < link.visuals.size(); ++v) {
    const std::string& n = link.visuals[v].name;
    if (n.size() >= suffix.size() &&
        n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0)
      out.push_back(static_cast<int>(v));
  }
  return out;
}

std::string Describe(const PartNetLink& e) {
  return "link_" + std::to_string(e.id) + " ('" + e.partnet_name + "')";
}

// The annotation frame F in the root: the orientation of the object's body link, the child of
// the root joined by a fixed joint (real files turn the y-up meshes z-up there), else of the
// root's first child; identity when the root has none.
Pose AnnotationFrame(const ArticulationDesc& desc) {
  int first = -1, fixed = -1;
  for (size_t i = 0; i < desc.links.size(); ++i) {
    const LinkDesc& l = desc.links[i];
    if (l.parent < 0 || desc.links[l.parent].parent >= 0) continue;
    if (first < 0) first = static_cast<int>(i);
    if (fixed < 0 && l.joint.type == JointType::kFixed) fixed = static_cast<int>(i);
  }
  int pick = fixed >= 0 ? fixed : first;
  if (pick < 0) return Pose();
  const JointDesc& j = desc.links[pick].joint;
  Pose X_BC = j.pose_in_parent * j.pose_in_child.Inverse();
  return Pose(Eigen::Vector3d::Zero(), X_BC.q);
}

// Checks one link's URDF joint(s) against its mobility_v2.json entry, in the root frame B.
// mobility.urdf is the physical truth: a disagreement is a note. `scale` is the loader's: the
// URDF was read scaled, mobility_v2.json's lengths are not.
void CheckLink(const PartNetLink& e, const ArticulationDesc& desc, const std::vector<Pose>& X,
               const Pose& X_BF, const fs::path& folder, double scale, const Notes& notes) {
  const fs::path urdf = folder / "mobility.urdf";
  const fs::path json_file = folder / "mobility_v2.json";
  const std::string link_name = "link_" + std::to_string(e.id);
  const std::string where = Describe(e);
  const int li = FindLink(desc, link_name);
  // a rotating slider hangs from a helper link: the slide is the helper's joint
  int motion = li;
  if (e.rotates) {
    motion = desc.links[li].parent;
    if (motion < 0 || desc.links[motion].name != link_name + "_helper") {
      notes.Warn(urdf, where + " is a rotating slider in mobility_v2.json but its parent is not '" +
                           link_name + "_helper'; its motion is read from mobility.urdf alone");
      return;
    }
  }
  const LinkDesc& m = desc.links[motion];
  // parent
  const std::string parent_name = e.parent < 0 ? "base" : "link_" + std::to_string(e.parent);
  const std::string urdf_parent = m.parent < 0 ? "(none)" : desc.links[m.parent].name;
  if (urdf_parent != parent_name &&
      !(e.parent < 0 && m.parent >= 0 && desc.links[m.parent].parent < 0)) {
    notes.Warn(json_file, where + ": parent is '" + parent_name + "', mobility.urdf says '" +
                              urdf_parent + "'");
  }
  // type
  const JointType expect = PartNetMobilityObject::MotionJointType(e);
  if (m.joint.type != expect) {
    notes.Warn(json_file, where + ": motion '" + e.joint + (e.no_limit ? " without limit" : "") +
                              "' (" + JointTypeName(expect) + "), mobility.urdf's joint '" +
                              m.joint.name + "' is " + JointTypeName(m.joint.type));
    return;
  }
  if (!e.has_axis || m.parent < 0) return;
  // axis: the joint frame's x axis, and the file's axis turned into B
  const Pose X_BJ = X[m.parent] * m.joint.pose_in_parent;
  const Eigen::Vector3d d = X_BJ.q * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d file_d = X_BF.q * e.axis_direction;
  const Eigen::Vector3d file_o = X_BF.q * (e.axis_origin * scale);
  const double dot = d.dot(file_d);
  if (d.cross(file_d).norm() > kAxisTolerance) {
    notes.Warn(json_file, where + ": axis direction differs from mobility.urdf's joint '" +
                              m.joint.name + "'");
  } else if (e.joint == "hinge" && (file_o - X_BJ.p).cross(d).norm() > kAxisTolerance * scale) {
    notes.Warn(json_file, where + ": axis origin is not on the axis of mobility.urdf's joint '" +
                              m.joint.name + "'");
  }
  // limits, flipped when the file's axis points the other way
  if (!e.no_limit) {
    double lo = std::min(e.limit_a, e.limit_b), hi = std::max(e.limit_a, e.limit_b);
    if (e.joint == "hinge")
      lo = Radians(lo), hi = Radians(hi);
    else
      lo *= scale, hi *= scale;  // slider limits are lengths
    if (dot < 0) std::swap(lo, hi), lo = -lo, hi = -hi;
    if (std::abs(m.joint.lower - lo) > kLimitTolerance ||
        std::abs(m.joint.upper - hi) > kLimitTolerance) {
      std::ostringstream s;
      s << where << ": limits [" << lo << ", " << hi << "]"
        << (e.joint == "hinge" ? " (radians)" : " (metres)") << " differ from mobility.urdf's ["
        << m.joint.lower << ", " << m.joint.upper << "]";
      notes.Warn(json_file, s.str());
    }
  }
  if (e.rotates) {
    const JointDesc& r = desc.links[li].joint;
    const JointType rot = e.no_rotation_limit ? JointType::kContinuous : JointType::kRevolute;
    if (r.type != rot) {
      notes.Warn(
          json_file,
          where + ": the turn is " + JointTypeName(rot) +
              (e.no_rotation_limit ? std::string()
                                   : " over [0, " + FormatNumber(e.rotation_limit) + "] degrees") +
              ", mobility.urdf's joint '" + r.name + "' is " + JointTypeName(r.type));
    } else if (!e.no_rotation_limit &&
               (std::abs(r.lower) > kLimitTolerance ||
                std::abs(r.upper - Radians(e.rotation_limit)) > kLimitTolerance)) {
      notes.Warn(json_file,
                 where + ": rotation limits differ from mobility.urdf's joint '" + r.name + "'");
    }
  }
}

// One line of semantics.txt.
struct SemanticsLine {
  std::string link, joint, label;
  int line = 0;
};

std::vector<SemanticsLine> ReadSemantics(const fs::path& file) {
  std::istringstream in;
  try {
    in.str(internal::ReadWholeFile(file.string(), "file"));
  } catch (const Error& e) {
    Fail(file, e.what());
  }
  std::vector<SemanticsLine> out;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    std::istringstream s(line);
    SemanticsLine e;
    e.line = n;
    std::string extra;
    if (!(s >> e.link)) continue;  // blank line
    if (!(s >> e.joint >> e.label) || (s >> extra))
      Fail(file, "line " + std::to_string(n) + ": expected '<link> <joint type> <label>', got '" +
                     line + "'");
    out.push_back(e);
  }
  return out;
}

// The semantics.txt joint kind that a mobility_v2.json motion is written as.
std::string SemanticsKind(const PartNetLink& l) {
  return l.joint == "slider" && l.rotates ? "slider+" : l.joint;
}

// Bounds at rest of the visual meshes (collision shapes' when there are none), in frame F.
void ComputeBounds(PartNetMobilityObject* obj) {
  const ArticulationDesc& art = obj->articulation;
  std::vector<Pose> X = RestPoses(art);
  const Pose X_FB = obj->X_BF.Inverse();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf), hi = -lo;
  for (size_t i = 0; i < art.links.size(); ++i) {
    const Pose X_FL = X_FB * X[i];
    for (const VisualShape& v : art.links[i].visuals) {
      if (!v.mesh) continue;
      const Pose X_FV = X_FL * v.pose;
      for (const Eigen::Vector3f& p : v.mesh->vertices) {
        Eigen::Vector3d q = X_FV.Transform(p.cast<double>());
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
      }
    }
  }
  if (lo.allFinite() && hi.allFinite()) {
    obj->bbox_min = lo;
    obj->bbox_max = hi;
  }
}

}  // namespace

JointType PartNetMobilityObject::MotionJointType(const PartNetLink& link) {
  if (link.joint == "hinge") return link.no_limit ? JointType::kContinuous : JointType::kRevolute;
  if (link.joint == "slider") return JointType::kPrismatic;
  return JointType::kFixed;
}

const PartNetLink& PartNetMobilityObject::Link(int id) const {
  for (const PartNetLink& l : links)
    if (l.id == id) return l;
  throw Error("PartNet-Mobility " + folder + ": no link_" + std::to_string(id));
}

int PartNetMobilityObject::LinkIndex(int id) const {
  int i = FindLink(articulation, "link_" + std::to_string(id));
  if (i < 0) throw Error("PartNet-Mobility " + folder + ": no link_" + std::to_string(id));
  return i;
}

std::vector<int> PartNetMobilityObject::PartVisuals(int id, const std::string& part_name) const {
  const LinkDesc& link = articulation.links[LinkIndex(id)];
  std::vector<int> out;
  for (const PartNetPart& p : Link(id).parts) {
    if (p.name != part_name) continue;
    for (int v : VisualsOfPart(link, p.id)) out.push_back(v);
  }
  return out;
}

std::vector<int> PartNetMobilityObject::LinksWithLabel(const std::string& label) const {
  std::vector<int> out;
  for (const PartNetLink& l : links)
    if (l.semantic_label == label) out.push_back(l.id);
  return out;
}

PartNetMobilityObject PartNetMobilityLoader::Parse(const std::string& folder_in) const {
  last_report_ = LoadReport();
  fs::path folder(folder_in);
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) Fail(folder, "is not a folder");
  const fs::path urdf_file = Require(folder, "mobility.urdf");
  const fs::path json_file = folder / "mobility_v2.json";
  const fs::path sem_file = folder / "semantics.txt";
  const fs::path meta_file = folder / "meta.json";
  const fs::path bbox_file = folder / "bounding_box.json";

  PartNetMobilityObject obj;
  obj.folder = folder.string();
  Notes notes(strict, &obj.report);
  auto present = [&](const fs::path& p) {
    if (fs::is_regular_file(p, ec)) return true;
    notes.Warn(p, "file is missing");
    return false;
  };

  // meta.json: category and model id
  obj.model_id = folder.filename().string();
  if (present(meta_file)) {
    json meta = ReadJson(meta_file);
    if (!meta.is_object()) Fail(meta_file, "must hold a JSON object");
    if (meta.contains("model_cat") && meta["model_cat"].is_string())
      obj.category = meta["model_cat"].get<std::string>();
    else
      notes.Warn(meta_file, "has no string 'model_cat': the category is unknown");
    if (meta.contains("model_id") && meta["model_id"].is_string())
      obj.model_id = meta["model_id"].get<std::string>();
  }

  // mobility_v2.json
  if (present(json_file)) {
    json entries = ReadJson(json_file);
    if (!entries.is_array()) Fail(json_file, "must hold a list of links");
    for (size_t i = 0; i < entries.size(); ++i)
      obj.links.push_back(ReadLinkEntry(entries[i], i, json_file));
    std::sort(obj.links.begin(), obj.links.end(),
              [](const PartNetLink& a, const PartNetLink& b) { return a.id < b.id; });
    for (size_t i = 1; i < obj.links.size(); ++i)
      if (obj.links[i].id == obj.links[i - 1].id)
        Fail(json_file, "link_" + std::to_string(obj.links[i].id) + " appears twice");
    for (const PartNetLink& l : obj.links)
      if (l.parent >= 0 && std::none_of(obj.links.begin(), obj.links.end(),
                                        [&](const PartNetLink& o) { return o.id == l.parent; }))
        notes.Warn(json_file, Describe(l) + " has parent " + std::to_string(l.parent) +
                                  ", which is not in the file");
  }

  // semantics.txt: the movable-part labels; its joint kinds must agree with the JSON's motions
  // (its labels are another vocabulary than the JSON's names, and may differ from them)
  std::vector<SemanticsLine> semantics;
  if (present(sem_file)) semantics = ReadSemantics(sem_file);
  static const char* kKinds[] = {"hinge", "slider", "slider+", "free", "heavy", "static"};
  for (const SemanticsLine& s : semantics) {
    if (std::find(std::begin(kKinds), std::end(kKinds), s.joint) == std::end(kKinds))
      notes.Warn(sem_file, "line " + std::to_string(s.line) + ": unknown joint kind '" + s.joint +
                               "' (expected hinge, slider, slider+, free, heavy or static)");
  }
  for (PartNetLink& l : obj.links) {
    const std::string name = "link_" + std::to_string(l.id);
    auto it = std::find_if(semantics.begin(), semantics.end(),
                           [&](const SemanticsLine& s) { return s.link == name; });
    if (it == semantics.end()) {
      if (fs::is_regular_file(sem_file, ec))
        notes.Warn(sem_file, "has no line for " + name + "; its label is mobility_v2.json's '" +
                                 l.partnet_name + "'");
      continue;
    }
    l.semantic_label = it->label;
    l.semantic_joint = it->joint;
    if (it->joint != SemanticsKind(l))
      notes.Warn(sem_file, "line " + std::to_string(it->line) + ": " + name + " is '" + it->joint +
                               "', mobility_v2.json says '" + SemanticsKind(l) + "'");
  }

  // mobility.urdf, the physical truth, as it is (already z-up)
  UrdfLoader u = urdf;
  u.strict = urdf.strict || strict;
  obj.articulation = u.ParseFile(urdf_file.string());
  obj.report.Append(u.LastReport());
  ArticulationDesc& art = obj.articulation;
  obj.X_BF = AnnotationFrame(art);

  // entries naming links that mobility.urdf lacks are dropped; the rest are cross-checked
  std::vector<PartNetLink> kept;
  for (PartNetLink& l : obj.links) {
    if (FindLink(art, "link_" + std::to_string(l.id)) < 0) {
      notes.Warn(json_file, Describe(l) + " names a link that mobility.urdf lacks; dropped");
      continue;
    }
    kept.push_back(std::move(l));
  }
  obj.links = std::move(kept);
  std::vector<Pose> X = RestPoses(art);
  for (const PartNetLink& l : obj.links) CheckLink(l, art, X, obj.X_BF, folder, u.scale, notes);
  for (PartNetLink& l : obj.links) {
    for (PartNetPart& p : l.parts) {
      p.visuals = VisualsOfPart(art.links[obj.LinkIndex(l.id)], p.id);
      if (p.visuals.empty())
        notes.Warn(urdf_file, "link_" + std::to_string(l.id) + " has no visual named '*-" +
                                  std::to_string(p.id) + "' for part '" + p.name + "' (" +
                                  std::to_string(p.id) + ") of mobility_v2.json");
    }
  }

  // labels and names on the links (a rotating slider's helper link carries its link's labels)
  art.name = (obj.category.empty() ? "object" : obj.category) + "_" + obj.model_id;
  for (const PartNetLink& l : obj.links) {
    const int i = obj.LinkIndex(l.id);
    for (int k : {i, l.rotates ? art.links[i].parent : -1}) {
      if (k < 0) continue;
      art.links[k].semantic_label = l.semantic_label;
      art.links[k].partnet_name = l.partnet_name;
    }
  }
  for (const SemanticsLine& s : semantics) {
    const int i = FindLink(art, s.link);
    if (i < 0) {
      notes.Warn(sem_file, "line " + std::to_string(s.line) + " names '" + s.link +
                               "', which mobility.urdf lacks");
    } else if (std::none_of(obj.links.begin(), obj.links.end(), [&](const PartNetLink& l) {
                 return "link_" + std::to_string(l.id) == s.link;
               })) {
      art.links[i].semantic_label = s.label;  // a link the JSON does not describe
    }
  }

  // bounds: bounding_box.json when present, else from the meshes
  if (present(bbox_file)) {
    json bbox = ReadJson(bbox_file);
    obj.bbox_min = Fields(bbox_file, "bounding box").Vec3(bbox, "min") * u.scale;
    obj.bbox_max = Fields(bbox_file, "bounding box").Vec3(bbox, "max") * u.scale;
  } else {
    ComputeBounds(&obj);
  }
  last_report_ = obj.report;
  return obj;
}

Articulation PartNetMobilityLoader::Load(const std::string& folder) {
  if (!scene_) throw Error("PartNetMobilityLoader::Load: the loader has no scene");
  return scene_->AddArticulation(Parse(folder).articulation);
}

namespace {

// A folder on the way down from a dataset's root: resolved, as reached, and whether it was
// reached through a symbolic link of its own.
struct SearchStep {
  fs::path resolved;
  fs::path reached;
  bool link = false;
};

// True when `folder` is `inside` or one of the folders above it (both resolved).
bool Holds(const fs::path& folder, const fs::path& inside) {
  auto f = folder.begin(), i = inside.begin();
  for (; f != folder.end(); ++f, ++i)
    if (i == inside.end() || *f != *i) return false;
  return true;
}

// One step of FindDatasetFolders: the folder at the end of `chain`, the folders from the root
// down to it, against which each link's target is checked for a loop.
void SearchDatasetFolder(std::vector<SearchStep>* chain,
                         const std::function<bool(const std::string&)>& is_object,
                         std::vector<std::string>* found,
                         std::vector<UnreadableFolder>* unreadable) {
  const fs::path dir = chain->back().reached;
  auto cannot_read = [&](const fs::path& what, const std::string& reason) {
    if (!unreadable) throw Error("'" + what.string() + "': " + reason);
    unreadable->push_back({what.string(), reason});
  };
  if (is_object(dir.string())) {
    found->push_back(dir.string());
    return;  // an object's own subfolders (textured_objs/, images/) hold no objects
  }
  // the entries in path order, so that the search and its first error do not depend on the
  // order the file system lists them in
  std::error_code ec;
  fs::directory_iterator it(dir, ec), end;
  if (ec) return cannot_read(dir, "cannot read the folder: " + ec.message());
  std::vector<fs::path> entries;
  for (; it != end; it.increment(ec)) {
    if (ec) return cannot_read(dir, "cannot read the folder: " + ec.message());
    entries.push_back(it->path());
  }
  std::sort(entries.begin(), entries.end());
  for (const fs::path& entry : entries) {
    std::error_code kind;
    const bool link = fs::is_symlink(fs::symlink_status(entry, kind));
    if (!link && !fs::is_directory(fs::symlink_status(entry, kind))) continue;
    if (link) {
      // a link: followed when it leads to a folder
      const fs::file_status target = fs::status(entry, kind);
      if (kind.value() == ELOOP) {
        cannot_read(entry, "symbolic link in a loop of links (" + kind.message() + ")");
        continue;
      }
      if (kind || !fs::exists(target)) {
        cannot_read(entry, "symbolic link to '" + fs::read_symlink(entry, kind).string() +
                               "', which does not exist");
        continue;
      }
      if (!fs::is_directory(target)) continue;
    }
    const fs::path resolved = fs::canonical(entry, kind);
    if (kind) {
      cannot_read(entry, "cannot resolve the folder: " + kind.message());
      continue;
    }
    // a folder on the way down from the root, or one that holds such a folder: the search
    // would come back to where it is, again and again; the link to blame is the last one on
    // the way (this entry itself, but for a folder that is in two places)
    const bool loop = std::any_of(chain->begin(), chain->end(),
                                  [&](const SearchStep& s) { return Holds(resolved, s.resolved); });
    if (loop) {
      std::string through;
      if (!link)
        for (auto s = chain->rbegin(); s != chain->rend(); ++s)
          if (s->link) {
            through = " through the symbolic link '" + s->reached.string() + "'";
            break;
          }
      cannot_read(entry, std::string(link ? "symbolic link" : "folder") + " to '" +
                             resolved.string() + "'" + through +
                             ", a folder that holds it (a loop of links)");
      continue;
    }
    chain->push_back({resolved, entry, link});
    SearchDatasetFolder(chain, is_object, found, unreadable);
    chain->pop_back();
  }
}

}  // namespace

std::vector<std::string> FindDatasetFolders(
    const std::string& root, const std::function<bool(const std::string& folder)>& is_object,
    std::vector<UnreadableFolder>* unreadable) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw Error("dataset folder '" + root + "' is not a folder");
  std::vector<SearchStep> chain = {{fs::canonical(root, ec), root, false}};
  if (ec) throw Error("dataset folder '" + root + "': " + ec.message());
  std::vector<std::string> found;
  SearchDatasetFolder(&chain, is_object, &found, unreadable);
  std::sort(found.begin(), found.end());
  return found;
}

std::vector<std::string> FindPartNetMobilityFolders(const std::string& root,
                                                    std::vector<UnreadableFolder>* unreadable) {
  return FindDatasetFolders(
      root,
      [](const std::string& folder) {
        std::error_code ec;
        return fs::is_regular_file(fs::path(folder) / "mobility.urdf", ec);
      },
      unreadable);
}

std::vector<PartNetBatchEntry> ParsePartNetMobilityBatch(const std::string& root,
                                                         const PartNetMobilityLoader& loader) {
  const std::vector<std::string> folders = FindPartNetMobilityFolders(root);
  std::vector<PartNetBatchEntry> out;
  for (const std::string& f : folders) {
    PartNetBatchEntry entry;
    entry.folder = f;
    try {
      entry.object = loader.Parse(f);
      entry.ok = true;
    } catch (const Error& e) {
      entry.error = e.what();
    }
    out.push_back(std::move(entry));
  }
  return out;
}

}  // namespace partsim
