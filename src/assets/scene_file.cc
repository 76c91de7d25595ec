// Scene files and the loading of a URDF, a PartNet-Mobility folder or a scene file into a scene.
#include "partsim/assets/scene_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "core/ascii.h"
#include "core/file_read.h"
#include "core/json_parse.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/assets/urdf.h"
#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "partsim/physics/description.h"
#include "partsim/physics/mjcf.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kUnitTolerance = 1e-3;  // |norm - 1| allowed for quaternions, as Pose::IsValid

// What a path names.
enum class PathKind { kUrdf, kPartNetFolder, kSceneFile, kMjcf };

// Tells what `path` is; throws naming the path when it is none of the three.
PathKind Classify(const fs::path& path, const std::string& where) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(where + ": does not exist");
  if (fs::is_directory(path, ec)) {
    if (fs::exists(path / "mobility.urdf", ec) || fs::exists(path / "mobility_v2.json", ec))
      return PathKind::kPartNetFolder;
    throw Error(where +
                ": folder holds neither mobility.urdf nor mobility_v2.json (not a "
                "PartNet-Mobility object)");
  }
  const std::string ext = internal::AsciiLower(path.extension().string());
  if (ext == ".urdf") return PathKind::kUrdf;
  if (ext == ".json") return PathKind::kSceneFile;
  if (IsMjcfFile(path.string())) return PathKind::kMjcf;
  throw Error(where + ": unknown extension '" + ext +
              "' (expected a .urdf file, a PartNet-Mobility folder, an MJCF .xml file or a .json "
              "scene file)");
}

// Reads the fields of one JSON object; errors name the scene file and the field's JSON path
// (e.g. "objects[1].pose").
class Fields {
 public:
  Fields(const std::string& file, const std::string& where) : file_(file), where_(where) {}

  // The fields of member `name` of this object.
  Fields Sub(const std::string& name) const { return Fields(file_, where_ + "." + name); }

  [[noreturn]] void Fail(const std::string& field, const std::string& what) const {
    throw Error("scene file " + file_ + ": " + where_ + (field.empty() ? "" : "." + field) + ": " +
                what);
  }

  // The object itself must be a JSON object holding only `allowed` keys.
  void CheckObject(const json& j, const std::vector<std::string>& allowed) const {
    if (!j.is_object()) Fail("", std::string("must be an object, not ") + j.type_name());
    for (const auto& item : j.items()) {
      if (std::find(allowed.begin(), allowed.end(), item.key()) != allowed.end()) continue;
      std::string list;
      for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
      Fail(item.key(), "unknown field (expected one of " + list + ")");
    }
  }

  double Finite(const json& v, const std::string& field) const {
    if (!v.is_number()) Fail(field, std::string("must be a number, not ") + v.type_name());
    double x = v.get<double>();
    if (!std::isfinite(x)) Fail(field, "must be finite, not " + FormatNumber(x));
    return x;
  }

  // A list of exactly n finite numbers.
  Eigen::VectorXd Numbers(const json& j, const std::string& field, int n) const {
    const json& v = j.at(field);
    if (!v.is_array() || static_cast<int>(v.size()) != n)
      Fail(field, "must be a list of " + std::to_string(n) + " numbers, not " + v.dump());
    Eigen::VectorXd out(n);
    for (int i = 0; i < n; ++i) out[i] = Finite(v[i], field + "[" + std::to_string(i) + "]");
    return out;
  }

  std::string String(const json& j, const std::string& field) const {
    const json& v = j.at(field);
    if (!v.is_string()) Fail(field, std::string("must be a string, not ") + v.type_name());
    return v.get<std::string>();
  }

  bool Bool(const json& j, const std::string& field) const {
    const json& v = j.at(field);
    if (!v.is_boolean()) Fail(field, "must be true or false, not " + v.dump());
    return v.get<bool>();
  }

 private:
  std::string file_;
  std::string where_;
};

// X_WO from {"position": [x,y,z], "orientation": [w,x,y,z]} or {..., "rpy": [r,p,y]}.
Pose ReadPose(const json& j, const Fields& f) {
  f.CheckObject(j, {"position", "orientation", "rpy"});
  Pose pose;
  if (j.contains("position")) pose.p = f.Numbers(j, "position", 3);
  if (j.contains("orientation") && j.contains("rpy"))
    f.Fail("rpy", "give either orientation or rpy, not both");
  if (j.contains("orientation")) {
    Eigen::Vector4d wxyz = f.Numbers(j, "orientation", 4);
    double norm = wxyz.norm();
    if (norm == 0.0) f.Fail("orientation", "quaternion [w, x, y, z] is zero (must have norm 1)");
    if (std::abs(norm - 1.0) > kUnitTolerance)
      f.Fail("orientation",
             "quaternion [w, x, y, z] has norm " + FormatNumber(norm) + " (must be 1)");
    pose.q = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized();
  } else if (j.contains("rpy")) {
    Eigen::Vector3d rpy = f.Numbers(j, "rpy", 3);
    pose.q = Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
             Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
             Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX());
  }
  return pose;
}

// One entry of "objects"; relative paths resolve against `base_dir`.
SceneObjectSpec ReadEntry(const json& j, const Fields& f, const fs::path& base_dir) {
  f.CheckObject(j, {"path", "name", "pose", "fix_root", "scale"});
  SceneObjectSpec spec;
  if (!j.contains("path")) f.Fail("path", "is missing");
  const std::string raw = f.String(j, "path");
  if (raw.empty()) f.Fail("path", "is empty");
  fs::path p(raw);
  spec.path = (p.is_absolute() ? p : base_dir / p).lexically_normal().string();
  if (internal::AsciiLower(p.extension().string()) == ".json")
    f.Fail("path", "'" + raw + "' is a scene file; scene files cannot be nested");
  if (j.contains("name")) {
    spec.name = f.String(j, "name");
    if (spec.name.empty()) f.Fail("name", "is empty");
  }
  if (j.contains("pose")) spec.pose = ReadPose(j.at("pose"), f.Sub("pose"));
  if (j.contains("fix_root")) spec.fix_root = f.Bool(j, "fix_root");
  if (j.contains("scale")) {
    spec.scale = f.Finite(j.at("scale"), "scale");
    if (spec.scale <= 0.0) f.Fail("scale", "must be > 0, not " + FormatNumber(spec.scale));
  }
  return spec;
}

// An object read and placed, not yet in the scene.
struct Prepared {
  ArticulationDesc desc;
  std::string where;   // "scene file S: objects[i]" or the lone path, for error messages
  bool named = false;  // desc.name was given by the scene file
};

// Reads a URDF or a PartNet-Mobility folder into a description placed at X_WO = `pose`.
Prepared Prepare(const std::string& path, const Pose& pose, bool fix_root, double scale,
                 const std::string& where) {
  Prepared out;
  out.where = where;
  const PathKind kind = Classify(path, where);
  if (kind == PathKind::kSceneFile)
    throw Error(where + ": is a scene file; scene files cannot be nested");
  if (kind == PathKind::kMjcf)
    throw Error(where +
                ": is an MJCF file; scene files list URDF files and PartNet-Mobility "
                "folders (load an MJCF file on its own)");
  try {
    if (kind == PathKind::kUrdf) {
      UrdfLoader loader;
      loader.fix_root_link = fix_root;
      loader.scale = scale;
      out.desc = loader.ParseFile(path);
    } else {
      PartNetMobilityLoader loader;
      loader.urdf.fix_root_link = fix_root;
      loader.urdf.scale = scale;
      out.desc = loader.Parse(path).articulation;
    }
    if (out.desc.name.empty()) out.desc.name = fs::path(path).stem().string();
    if (out.desc.name.empty()) out.desc.name = fs::path(path).parent_path().filename().string();
    // the pose places the object's frame; a URDF's world joint offset stays below it
    out.desc.root_pose = pose * out.desc.root_pose;
    out.desc.root_pose.q.normalize();
    Validate(out.desc);
  } catch (const Error& e) {
    throw Error(where + ": " + e.what());
  }
  return out;
}

// `base`, or base_2, base_3, ... : the first not in `taken`.
std::string UniqueName(const std::string& base, const std::set<std::string>& taken) {
  if (!taken.count(base)) return base;
  for (int k = 2;; ++k) {
    std::string name = base + "_" + std::to_string(k);
    if (!taken.count(name)) return name;
  }
}

}  // namespace

SceneFileSpec ReadSceneFile(const std::string& path) {
  SceneFileSpec spec;
  spec.path = path;
  const std::string where = "scene file " + path;
  const std::string text = internal::ReadWholeFile(path, "scene file");

  // the JSON
  json root;
  try {
    root = internal::ParseJsonBounded(text);
  } catch (const json::exception& e) {
    throw Error(where + ": bad JSON: " + e.what());
  }
  const Fields top(path, "(top level)");
  top.CheckObject(root, {"objects"});
  if (!root.contains("objects")) top.Fail("objects", "is missing");
  const json& objects = root.at("objects");
  if (!objects.is_array())
    Fields(path, "objects").Fail("", std::string("must be a list, not ") + objects.type_name());
  if (objects.empty()) Fields(path, "objects").Fail("", "is empty (no object to load)");

  // the entries, with names unique within the file
  std::error_code ec;
  const fs::path base_dir = fs::absolute(fs::path(path), ec).parent_path();
  std::set<std::string> names;
  for (size_t i = 0; i < objects.size(); ++i) {
    const Fields f(path, "objects[" + std::to_string(i) + "]");
    SceneObjectSpec entry = ReadEntry(objects[i], f, base_dir);
    if (!entry.name.empty() && !names.insert(entry.name).second)
      f.Fail("name", "'" + entry.name + "' is used by an earlier entry");
    spec.objects.push_back(std::move(entry));
  }
  return spec;
}

std::vector<Articulation> AddSceneObjects(Scene* scene, const std::string& path,
                                          const Pose& default_pose, bool fix_root) {
  if (scene == nullptr) throw Error("AddSceneObjects(" + path + "): scene is null");
  CheckPose("AddSceneObjects(" + path + "): default_pose", default_pose);

  // an MJCF model: loaded whole (LoadMjcf leaves the scene as it was on an error)
  if (Classify(path, path) == PathKind::kMjcf)
    return LoadMjcf(*scene, path, default_pose).GetArticulations();

  // read every object before touching the scene
  std::vector<Prepared> prepared;
  if (Classify(path, path) == PathKind::kSceneFile) {
    SceneFileSpec spec = ReadSceneFile(path);
    for (size_t i = 0; i < spec.objects.size(); ++i) {
      const SceneObjectSpec& o = spec.objects[i];
      const std::string where = "scene file " + path + ": objects[" + std::to_string(i) + "]";
      prepared.push_back(Prepare(o.path, o.pose, o.fix_root.value_or(fix_root), o.scale,
                                 where + " (path '" + o.path + "')"));
      if (!o.name.empty()) {
        prepared.back().desc.name = o.name;
        prepared.back().named = true;
      }
    }
  } else {
    prepared.push_back(Prepare(path, default_pose, fix_root, 1.0, path));
  }

  // names: given ones must be free in the scene, the others are made unique
  std::set<std::string> taken;
  for (const Articulation& a : scene->GetArticulations()) taken.insert(a.GetName());
  for (const Prepared& p : prepared) {
    if (!p.named) continue;
    if (taken.count(p.desc.name))
      throw Error(p.where + ": name '" + p.desc.name +
                  "' is taken by an articulation already in the scene");
    taken.insert(p.desc.name);
  }
  for (Prepared& p : prepared) {
    if (p.named) continue;
    p.desc.name = UniqueName(p.desc.name, taken);
    taken.insert(p.desc.name);
  }

  // add them all, or none: on a failure the ones added by this call are removed
  std::vector<Articulation> added;
  for (const Prepared& p : prepared) {
    try {
      added.push_back(scene->AddArticulation(p.desc));
    } catch (const Error& e) {
      for (auto it = added.rbegin(); it != added.rend(); ++it) scene->RemoveArticulation(*it);
      throw Error(p.where + ": " + e.what());
    }
  }
  return added;
}

}  // namespace partsim
