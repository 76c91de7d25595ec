// Reads a PartNet-Mobility folder and cross-checks its files (docs/partnet_mobility_format.md).
#include "partsim/assets/partnet_mobility.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "partsim/core/error.h"

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
  std::ifstream in(file);
  if (!in) Fail(file, "cannot be read");
  try {
    return json::parse(in);
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
  l.semantic_label = g.String(e, "name");
  if (e.contains("parts")) {
    const json& parts = e.at("parts");
    if (!parts.is_array()) Fail(file, "link_" + std::to_string(l.id) + ": 'parts' must be a list");
    for (const json& p : parts) {
      if (p.is_null()) continue;  // the dataset leaves holes in some part lists
      l.parts.push_back({g.Int(p, "id"), g.String(p, "name")});
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

// Forward kinematics at q = 0 of a description, in the file's frame: X_FL per link.
std::vector<Pose> RestPoses(const ArticulationDesc& desc) {
  std::vector<Pose> X(desc.links.size());
  for (size_t i = 0; i < desc.links.size(); ++i) {
    const LinkDesc& l = desc.links[i];
    X[i] = l.parent < 0 ? desc.root_pose
                        : X[l.parent] * l.joint.pose_in_parent * l.joint.pose_in_child.Inverse();
  }
  return X;
}

int FindLink(const ArticulationDesc& desc, const std::string& name) {
  for (size_t i = 0; i < desc.links.size(); ++i)
    if (desc.links[i].name == name) return static_cast<int>(i);
  return -1;
}

// Checks one link's URDF joint(s) against its mobility_v2.json entry. `scale` is the loader's:
// the URDF was read scaled, mobility_v2.json's lengths are not.
void CheckLink(const PartNetLink& e, const ArticulationDesc& desc, const std::vector<Pose>& X,
               const fs::path& folder, double scale) {
  const fs::path urdf = folder / "mobility.urdf";
  std::string link_name = "link_" + std::to_string(e.id);
  std::string where = "link_" + std::to_string(e.id) + " ('" + e.semantic_label + "')";
  int li = FindLink(desc, link_name);
  if (li < 0) Fail(urdf, "has no link '" + link_name + "', which mobility_v2.json describes");
  // a rotating slider hangs from a helper link: the slide is the helper's joint
  int motion = li;
  if (e.rotates) {
    motion = desc.links[li].parent;
    if (motion < 0 || desc.links[motion].name != link_name + "_helper")
      Fail(urdf, where + " is a rotating slider but its parent is not '" + link_name + "_helper'");
  }
  const LinkDesc& m = desc.links[motion];
  // parent
  std::string parent_name = e.parent < 0 ? "base" : "link_" + std::to_string(e.parent);
  if (m.parent < 0 || desc.links[m.parent].name != parent_name)
    Fail(urdf, where + ": parent is '" +
                   (m.parent < 0 ? std::string("(none)") : desc.links[m.parent].name) +
                   "', mobility_v2.json says '" + parent_name + "'");
  // type
  JointType expect = PartNetMobilityObject::MotionJointType(e);
  if (m.joint.type != expect)
    Fail(urdf, where + ": joint '" + m.joint.name + "' is " + JointTypeName(m.joint.type) +
                   ", mobility_v2.json says " + e.joint + (e.no_limit ? " without limit" : "") +
                   " (" + JointTypeName(expect) + ")");
  if (!e.has_axis) return;
  // axis: the joint frame's x axis in the file frame
  Pose X_FJ = X[m.parent] * m.joint.pose_in_parent;
  Eigen::Vector3d d = X_FJ.q * Eigen::Vector3d::UnitX();
  double dot = d.dot(e.axis_direction);
  if ((d.cross(e.axis_direction)).norm() > kAxisTolerance)
    Fail(urdf, where + ": joint axis differs from mobility_v2.json's direction");
  if (e.joint == "hinge" &&
      (e.axis_origin * scale - X_FJ.p).cross(d).norm() > kAxisTolerance * scale)
    Fail(urdf, where + ": mobility_v2.json's axis origin is not on the joint's axis");
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
      s << where << ": limits [" << m.joint.lower << ", " << m.joint.upper
        << "] differ from mobility_v2.json's [" << lo << ", " << hi << "]"
        << (e.joint == "hinge" ? " (radians)" : " (metres)");
      Fail(urdf, s.str());
    }
  }
  if (e.rotates) {
    const JointDesc& r = desc.links[li].joint;
    JointType rot = e.no_rotation_limit ? JointType::kContinuous : JointType::kRevolute;
    if (r.type != rot)
      Fail(urdf, where + ": rotation joint '" + r.name + "' is " + JointTypeName(r.type) +
                     ", expected " + JointTypeName(rot));
    if (!e.no_rotation_limit && (std::abs(r.lower) > kLimitTolerance ||
                                 std::abs(r.upper - Radians(e.rotation_limit)) > kLimitTolerance))
      Fail(urdf, where + ": rotation limits differ from mobility_v2.json's rotationLimit");
  }
}

std::vector<std::pair<std::string, std::pair<std::string, std::string>>> ReadSemantics(
    const fs::path& file) {
  std::ifstream in(file);
  if (!in) Fail(file, "cannot be read");
  std::vector<std::pair<std::string, std::pair<std::string, std::string>>> out;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    std::istringstream s(line);
    std::string link, joint, label, extra;
    if (!(s >> link)) continue;  // blank line
    if (!(s >> joint >> label) || (s >> extra))
      Fail(file, "line " + std::to_string(n) + ": expected '<link> <joint type> <label>', got '" +
                     line + "'");
    out.push_back({link, {joint, label}});
  }
  return out;
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
    std::string suffix = "-" + std::to_string(p.id);
    for (size_t v = 0; v < link.visuals.size(); ++v) {
      const std::string& n = link.visuals[v].name;
      if (n.size() >= suffix.size() &&
          n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0)
        out.push_back(static_cast<int>(v));
    }
  }
  return out;
}

PartNetMobilityObject PartNetMobilityLoader::Parse(const std::string& folder_in) const {
  fs::path folder(folder_in);
  if (!fs::is_directory(folder)) Fail(folder, "is not a folder");
  fs::path urdf_file = Require(folder, "mobility.urdf");
  fs::path json_file = Require(folder, "mobility_v2.json");
  fs::path sem_file = Require(folder, "semantics.txt");
  fs::path meta_file = Require(folder, "meta.json");
  fs::path bbox_file = Require(folder, "bounding_box.json");

  PartNetMobilityObject obj;
  obj.folder = folder.string();
  // meta.json and bounding_box.json
  json meta = ReadJson(meta_file);
  obj.category = Fields(meta_file, "meta").String(meta, "model_cat");
  obj.model_id = meta.contains("model_id") && meta["model_id"].is_string()
                     ? meta["model_id"].get<std::string>()
                     : folder.filename().string();
  json bbox = ReadJson(bbox_file);
  obj.bbox_min = Fields(bbox_file, "bounding box").Vec3(bbox, "min");
  obj.bbox_max = Fields(bbox_file, "bounding box").Vec3(bbox, "max");

  // mobility_v2.json
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
      Fail(json_file, "link_" + std::to_string(l.id) + " has parent " + std::to_string(l.parent) +
                          ", which is not in the file");

  // semantics.txt agrees with the JSON
  auto semantics = ReadSemantics(sem_file);
  for (const PartNetLink& l : obj.links) {
    std::string name = "link_" + std::to_string(l.id);
    auto it = std::find_if(semantics.begin(), semantics.end(),
                           [&](const auto& s) { return s.first == name; });
    if (it == semantics.end()) Fail(sem_file, "has no line for " + name);
    if (it->second.first != l.joint || it->second.second != l.semantic_label)
      Fail(sem_file, name + " is '" + it->second.first + " " + it->second.second +
                         "', mobility_v2.json says '" + l.joint + " " + l.semantic_label + "'");
  }

  // mobility.urdf, cross-checked in the file's frame
  UrdfLoader u = urdf;
  u.fix_root_link = urdf.fix_root_link;
  obj.articulation = u.ParseFile(urdf_file.string());
  std::vector<Pose> X = RestPoses(obj.articulation);
  for (const PartNetLink& l : obj.links) CheckLink(l, obj.articulation, X, folder, u.scale);
  for (const PartNetLink& l : obj.links)
    for (const PartNetPart& p : l.parts)
      if (obj.PartVisuals(l.id, p.name).empty())
        Fail(urdf_file, "link_" + std::to_string(l.id) + " has no visual named '*-" +
                            std::to_string(p.id) + "' for part '" + p.name + "' (" +
                            std::to_string(p.id) + ") of mobility_v2.json");

  // labels, names, and the file's y-up frame turned z-up at the root
  ArticulationDesc& art = obj.articulation;
  art.name = obj.category + "_" + obj.model_id;
  for (const PartNetLink& l : obj.links) {
    int i = FindLink(art, "link_" + std::to_string(l.id));
    art.links[i].semantic_label = l.semantic_label;
    if (l.rotates) art.links[art.links[i].parent].semantic_label = l.semantic_label;
  }
  const Eigen::Quaterniond y_up_to_z_up(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  for (LinkDesc& l : art.links)
    if (l.parent >= 0 && art.links[l.parent].parent < 0)
      l.joint.pose_in_parent = Pose(Eigen::Vector3d::Zero(), y_up_to_z_up) * l.joint.pose_in_parent;
  return obj;
}

Articulation PartNetMobilityLoader::Load(const std::string& folder) {
  if (!scene_) throw Error("PartNetMobilityLoader::Load: the loader has no scene");
  return scene_->AddArticulation(Parse(folder).articulation);
}

std::vector<PartNetBatchEntry> ParsePartNetMobilityBatch(const std::string& root,
                                                         const PartNetMobilityLoader& loader) {
  std::vector<std::string> folders;
  if (!fs::is_directory(root))
    throw Error("PartNet-Mobility batch: '" + root + "' is not a folder");
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file() && e.path().filename() == "mobility_v2.json")
      folders.push_back(e.path().parent_path().string());
  std::sort(folders.begin(), folders.end());
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
