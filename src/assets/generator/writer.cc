// Writes a GeneratedObject as a PartNet-Mobility folder with the real dataset's structure
// (docs/partnet_mobility_format.md). Numbers have fixed formats so that the same object always
// gives the same bytes.
#include "assets/generator/writer.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "assets/generator/mesh_builder.h"
#include "core/atomic_file.h"
#include "core/file_read.h"
#include "partsim/assets/generator.h"
#include "partsim/core/constants.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

using internal::gen::ComputeVolumeProps;
using internal::gen::M3;
using internal::gen::Mesh;
using internal::gen::V3;
using internal::gen::VolumeProps;

/// Appends printf-formatted text to a string.
void Append(std::string* s, const char* fmt, double x, bool fixed = true) {
  char buf[64];
  if (fixed && std::abs(x) < 5e-10) x = 0.0;  // no "-0.000000"
  int n = std::snprintf(buf, sizeof(buf), fmt, x);
  // a value that rounds to zero prints without its sign
  std::string t(buf, static_cast<size_t>(n));
  if (t[0] == '-' && t.find_first_not_of("-0.") == std::string::npos) t.erase(0, 1);
  s->append(t);
}

std::string F6(double x) {
  std::string s;
  Append(&s, "%.6f", x);
  return s;
}
std::string F9(double x) {
  std::string s;
  Append(&s, "%.9f", x);
  return s;
}
std::string G9(double x) {
  std::string s;
  Append(&s, "%.9g", x, false);
  return s;
}
std::string Vec6(const V3& v) { return F6(v.x()) + " " + F6(v.y()) + " " + F6(v.z()); }
std::string Json3(const V3& v) {
  return "[" + F6(v.x()) + ", " + F6(v.y()) + ", " + F6(v.z()) + "]";
}

void WriteFile(const std::filesystem::path& path, const std::string& text) {
  std::FILE* f = std::fopen(path.string().c_str(), "wb");
  if (!f) throw Error("WriteObject: cannot write '" + path.string() + "'");
  bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) throw Error("WriteObject: failed writing '" + path.string() + "'");
}

/// Frame origin of each link in the file frame: the joint axis origin for moving links, the
/// parent's origin for fixed ones; rounded to the micrometre the files print, so that joint
/// offsets (differences of origins) and visual offsets add up exactly down a chain.
std::vector<V3> LinkOrigins(const GeneratedObject& o) {
  std::vector<V3> origin(o.links.size(), V3::Zero());
  for (const GeneratedLink& l : o.links) {
    bool moving = l.joint == "hinge" || l.joint == "slider";
    V3 p = moving ? l.axis_origin : (l.parent >= 0 ? origin[l.parent] : V3::Zero());
    for (int k = 0; k < 3; ++k) p[k] = std::round(p[k] * 1e6) / 1e6;
    origin[l.id] = p;
  }
  return origin;
}

std::string ObjText(const GeneratedPiece& p, const std::string& name) {
  std::string s;
  s.reserve(p.vertices.size() * 40 + p.triangles.size() * 24 + 64);
  s += "# partsim generator\nmtllib " + name + ".mtl\n";
  for (const V3& v : p.vertices) {
    s += "v ";
    Append(&s, "%.9f", v.x());
    s += ' ';
    Append(&s, "%.9f", v.y());
    s += ' ';
    Append(&s, "%.9f", v.z());
    s += '\n';
  }
  s += "usemtl " + p.material + "\n";
  char buf[64];
  for (const auto& t : p.triangles) {
    int n = std::snprintf(buf, sizeof(buf), "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
    s.append(buf, static_cast<size_t>(n));
  }
  return s;
}

std::string MtlText(const GeneratedPiece& p) {
  bool glass = p.material == "glass";
  std::string s = "newmtl " + p.material + "\n";
  s += "Ka 0.000000 0.000000 0.000000\n";
  s += "Kd " + Vec6(p.color) + "\n";
  s += glass ? "Ks 0.500000 0.500000 0.500000\nNs 200.000000\n"
             : "Ks 0.100000 0.100000 0.100000\nNs 20.000000\n";
  s += glass ? "d 0.350000\n" : "d 1.000000\n";
  s += "illum 2\n";
  return s;
}

std::string JointTypeUrdf(const GeneratedLink& l) {
  if (l.joint == "hinge") return l.no_limit ? "continuous" : "revolute";
  if (l.joint == "slider") return "prismatic";
  return "fixed";
}

/// <inertial> of a link from its pieces, about its centre of mass, in the link frame.
std::string InertialXml(const GeneratedLink& l, const V3& origin) {
  double mass = 0.0;
  V3 first = V3::Zero();
  M3 second = M3::Zero();
  for (const GeneratedPart& part : l.parts) {
    for (const GeneratedPiece& piece : part.pieces) {
      Mesh m;
      m.v = piece.vertices;
      m.f = piece.triangles;
      VolumeProps vp = ComputeVolumeProps(m);
      mass += piece.density * vp.volume;
      first += piece.density * vp.first;
      second += piece.density * vp.second;
    }
  }
  V3 com = origin;
  M3 inertia = M3::Identity() * 1e-9;
  if (mass > 1e-9) {
    com = first / mass;
    M3 s = second - mass * com * com.transpose();
    inertia = s.trace() * M3::Identity() - s;
  } else {
    mass = 1e-4;  // a helper link: small but non-zero for the physics engine
  }
  V3 c = com - origin;
  std::string x = "    <inertial>\n      <origin xyz=\"" + Vec6(c) + "\" rpy=\"0 0 0\"/>\n";
  x += "      <mass value=\"" + G9(mass) + "\"/>\n";
  x += "      <inertia ixx=\"" + G9(inertia(0, 0)) + "\" ixy=\"" + G9(inertia(0, 1)) + "\" ixz=\"" +
       G9(inertia(0, 2)) + "\" iyy=\"" + G9(inertia(1, 1)) + "\" iyz=\"" + G9(inertia(1, 2)) +
       "\" izz=\"" + G9(inertia(2, 2)) + "\"/>\n    </inertial>\n";
  return x;
}

std::string LimitXml(const GeneratedLink& l, bool rotation) {
  if (rotation || l.joint == "hinge") {
    double a = rotation ? 0.0 : l.limit_a, b = rotation ? l.rotation_limit : l.limit_b;
    return "    <limit lower=\"" + F9(a * kPi / 180.0) + "\" upper=\"" + F9(b * kPi / 180.0) +
           "\"/>\n";
  }
  return "    <limit lower=\"" + F6(l.limit_a) + "\" upper=\"" + F6(l.limit_b) + "\"/>\n";
}

std::string DynamicsXml(double damping, double friction) {
  return "    <dynamics damping=\"" + G9(damping) + "\" friction=\"" + G9(friction) + "\"/>\n";
}

// The rotation of the joint from "base" to the body, as the dataset writes it: it turns the raw
// mesh frame F (y up, front +z) z-up, with the front facing -x.
constexpr char kRootRpy[] = "1.570796326794897 0 -1.570796326794897";

/// R_BF of kRootRpy: URDF rpy is R = Rz(yaw) Ry(pitch) Rx(roll).
M3 RootRotation() {
  const double h = kPi / 2;
  M3 rx, rz;
  rx << 1, 0, 0, 0, std::cos(h), -std::sin(h), 0, std::sin(h), std::cos(h);
  rz << std::cos(-h), -std::sin(-h), 0, std::sin(-h), std::cos(-h), 0, 0, 0, 1;
  return rz * rx;
}

bool Moving(const GeneratedLink& l) { return l.joint == "hinge" || l.joint == "slider"; }

std::string LinkName(int id) { return "link_" + std::to_string(id); }

/// Joint element: name, type, origin (xyz in the parent link's frame; rpy only at the root),
/// parent, child and the rest (axis, limit, dynamics), already formatted.
std::string JointXml(const std::string& name, const std::string& type, const V3& xyz,
                     const char* rpy, const std::string& parent, const std::string& child,
                     const std::string& rest) {
  std::string s = "  <joint name=\"" + name + "\" type=\"" + type + "\">\n";
  s += std::string("    <origin xyz=\"") + Vec6(xyz) + "\"" +
       (rpy ? std::string(" rpy=\"") + rpy + "\"" : std::string()) + "/>\n";
  s += "    <parent link=\"" + parent + "\"/>\n    <child link=\"" + child + "\"/>\n";
  return s + rest + "  </joint>\n";
}

/// mobility.urdf as the dataset writes it: "base" (empty) joined to the body by a fixed joint
/// that turns F z-up; below it everything in F, each moving link's frame at its axis origin
/// (joint origins relative to the parent link's frame, visuals and collisions offset back); a
/// slider that also turns hangs from link_N_helper. Joint joint_N has child link_N; the helpers'
/// prismatic joints are numbered after the last link. partsim adds <inertial> and <dynamics>,
/// which the dataset's files lack.
std::string UrdfText(const GeneratedObject& o, const std::vector<std::vector<std::string>>& files) {
  std::vector<V3> origin = LinkOrigins(o);
  std::string s = "<?xml version=\"1.0\"?>\n<robot name=\"partnet_" + o.model_id + "\">\n";
  s += "  <link name=\"base\"/>\n";
  for (const GeneratedLink& l : o.links) {
    // visuals: one per piece, named after its part; then the same files as collisions
    std::string org = "      <origin xyz=\"" + Vec6(-origin[l.id]) + "\"/>\n";
    std::string visuals, collisions;
    size_t k = 0;
    for (const GeneratedPart& part : l.parts) {
      for (size_t i = 0; i < part.pieces.size(); ++i, ++k) {
        std::string geo = "      <geometry>\n        <mesh filename=\"textured_objs/" +
                          files[l.id][k] + ".obj\"/>\n      </geometry>\n";
        visuals += "    <visual name=\"" + part.name + "-" + std::to_string(part.id) + "\">\n" +
                   org + geo + "    </visual>\n";
        collisions += "    <collision>\n" + org + geo + "    </collision>\n";
      }
    }
    s += "  <link name=\"" + LinkName(l.id) + "\">\n" + InertialXml(l, origin[l.id]) + visuals +
         collisions + "  </link>\n";
    if (l.rotates) {
      s += "  <link name=\"" + LinkName(l.id) + "_helper\">\n" +
           InertialXml(GeneratedLink(), origin[l.id]) + "  </link>\n";
    }
  }
  const M3 R_BF = RootRotation();
  int helper_joint = static_cast<int>(o.links.size());
  for (const GeneratedLink& l : o.links) {
    const std::string name = LinkName(l.id);
    const std::string parent = l.parent < 0 ? "base" : LinkName(l.parent);
    // the joint frame in the parent link: at the root, turned z-up
    const V3 xyz = l.parent < 0 ? V3(R_BF * origin[l.id]) : V3(origin[l.id] - origin[l.parent]);
    const char* rpy = l.parent < 0 ? kRootRpy : nullptr;
    const std::string joint = "joint_" + std::to_string(l.id);
    if (!Moving(l)) {
      s += JointXml(joint, "fixed", xyz, rpy, parent, name, "");
      continue;
    }
    const std::string axis = "    <axis xyz=\"" + Vec6(l.axis_direction) + "\"/>\n";
    std::string motion =
        axis + (l.no_limit ? "" : LimitXml(l, false)) + DynamicsXml(l.damping, l.friction);
    if (!l.rotates) {
      s += JointXml(joint, JointTypeUrdf(l), xyz, rpy, parent, name, motion);
      continue;
    }
    // a slider that also turns: the slide to the helper, then the turn about the same axis
    s += JointXml(joint, l.no_rotation_limit ? "continuous" : "revolute", V3::Zero(), nullptr,
                  name + "_helper", name,
                  axis + (l.no_rotation_limit ? "" : LimitXml(l, true)) +
                      DynamicsXml(l.rotation_damping, l.rotation_friction));
    s += JointXml("joint_" + std::to_string(helper_joint++), "prismatic", xyz, rpy, parent,
                  name + "_helper", motion);
  }
  s += "</robot>\n";
  return s;
}

std::string Bool(bool b) { return b ? "true" : "false"; }

std::string MobilityText(const GeneratedObject& o) {
  std::string s = "[\n";
  for (size_t i = 0; i < o.links.size(); ++i) {
    const GeneratedLink& l = o.links[i];
    s += "  {\n    \"id\": " + std::to_string(l.id) +
         ",\n    \"parent\": " + std::to_string(l.parent) + ",\n    \"joint\": \"" + l.joint +
         "\",\n    \"name\": \"" + l.partnet_name + "\",\n    \"parts\": [";
    for (size_t p = 0; p < l.parts.size(); ++p) {
      s += (p ? ", " : "") + std::string("{\"id\": ") + std::to_string(l.parts[p].id) +
           ", \"name\": \"" + l.parts[p].name + "\", \"children\": []}";
    }
    s += "],\n    \"jointData\": ";
    if (l.joint == "hinge" || l.joint == "slider") {
      s += "{\n      \"axis\": {\"origin\": " + Json3(l.axis_origin) +
           ", \"direction\": " + Json3(l.axis_direction) + "},\n";
      s += "      \"limit\": {\"a\": " + F6(l.limit_a) + ", \"b\": " + F6(l.limit_b) +
           ", \"noLimit\": " + Bool(l.no_limit);
      if (l.joint == "slider") {
        s += ", \"rotates\": " + Bool(l.rotates) +
             ", \"noRotationLimit\": " + Bool(l.no_rotation_limit) +
             ", \"rotationLimit\": " + F6(l.rotation_limit);
      }
      s += "}\n    }\n";
    } else {
      s += "{}\n";
    }
    s += i + 1 < o.links.size() ? "  },\n" : "  }\n";
  }
  s += "]\n";
  return s;
}

/// "StorageFurniture" -> "storage_furniture" (PartNet's object names); "USB" -> "usb".
std::string SnakeCase(const std::string& category) {
  std::string out;
  for (size_t i = 0; i < category.size(); ++i) {
    char c = category[i];
    bool upper = c >= 'A' && c <= 'Z';
    bool after_lower = i > 0 && category[i - 1] >= 'a' && category[i - 1] <= 'z';
    if (upper && after_lower) out += '_';
    out += upper ? static_cast<char>(c - 'A' + 'a') : c;
  }
  return out;
}

/// "drawer_front" -> "Drawer Front", "storage_furniture" -> "Storage Furniture" (PartNet's
/// display texts).
std::string TitleText(const std::string& name) {
  std::string out;
  bool start = true;
  for (char c : name) {
    if (c == '_') {
      out += ' ';
      start = true;
      continue;
    }
    out += start && c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c;
    start = false;
  }
  return out;
}

std::string Quoted(const std::string& s) { return "\"" + s + "\""; }

std::string ObjList(const std::vector<std::string>& files) {
  std::string s = "[";
  for (size_t i = 0; i < files.size(); ++i) s += (i ? ", " : "") + Quoted(files[i]);
  return s + "]";
}

/// One node of the part hierarchy: the object, a link with several parts, or a part.
struct Node {
  int id = 0;
  std::string name;
  std::vector<std::string> files;  ///< OBJ names of the node and all below it
  std::vector<Node> children;
};

/// The PartNet part hierarchy of the object (ids as NumberPartNodes gave them).
Node PartTree(const GeneratedObject& o, const std::vector<std::vector<std::string>>& files) {
  Node root;
  root.name = SnakeCase(o.category);
  for (const GeneratedLink& l : o.links) {
    if (l.parts.empty()) continue;
    std::vector<Node> leaves;
    size_t k = 0;
    for (const GeneratedPart& part : l.parts) {
      Node leaf;
      leaf.id = part.id;
      leaf.name = part.name;
      for (size_t i = 0; i < part.pieces.size(); ++i) leaf.files.push_back(files[l.id][k++]);
      leaves.push_back(leaf);
    }
    if (leaves.size() == 1) {
      root.children.push_back(leaves[0]);
      continue;
    }
    Node group;
    group.id = leaves[0].id - 1;
    group.name = l.partnet_name;
    group.files = files[l.id];
    group.children = leaves;
    root.children.push_back(group);
  }
  for (const Node& c : root.children)
    root.files.insert(root.files.end(), c.files.begin(), c.files.end());
  return root;
}

/// result.json's node: internal nodes {text, children, id, name}, leaves {text, objs, id, name}.
std::string ResultJson(const Node& n, const std::string& text) {
  std::string s = "{\"text\": " + Quoted(text) + ", ";
  if (n.children.empty()) {
    s += "\"objs\": " + ObjList(n.files) + ", ";
  } else {
    s += "\"children\": [";
    for (size_t i = 0; i < n.children.size(); ++i)
      s += (i ? ", " : "") + ResultJson(n.children[i], TitleText(n.children[i].name));
    s += "], ";
  }
  return s + "\"id\": " + std::to_string(n.id) + ", \"name\": " + Quoted(n.name) + "}";
}

/// result_after_merging.json's node: every node lists the OBJ files below it, "ori_id" is its id
/// in result.json and "id" its pre-order index here.
std::string MergedJson(const Node& n, int* next) {
  const int id = (*next)++;
  std::string s = "{\"objs\": " + ObjList(n.files) + ", ";
  if (n.children.empty()) {
    s += "\"ori_id\": " + std::to_string(n.id) + ", \"text\": " + Quoted(n.name) +
         ", \"name\": " + Quoted(n.name);
  } else {
    s += "\"name\": " + Quoted(n.name) + ", \"ori_id\": " + std::to_string(n.id) +
         ", \"text\": " + Quoted(n.name) + ", \"children\": [";
    for (size_t i = 0; i < n.children.size(); ++i)
      s += (i ? ", " : "") + MergedJson(n.children[i], next);
    s += "]";
  }
  return s + ", \"id\": " + std::to_string(id) + "}";
}

/// The semantics.txt joint kind: the JSON motion, "slider+" for a slider that also turns.
std::string SemanticsKind(const GeneratedLink& l) {
  return l.joint == "slider" && l.rotates ? "slider+" : l.joint;
}

}  // namespace

bool IsGeneratedObjectFolder(const std::string& folder) {
  std::string text;
  try {  // a user's folder: meta.json may be anything, a link to a device included
    text = internal::ReadWholeFile((std::filesystem::path(folder) / "meta.json").string(),
                                   "meta.json");
  } catch (const Error&) {
    return false;
  }
  return text.find("\"generator\": \"partsim assets generate\"") != std::string::npos;
}

bool IsPartialObjectFolder(const std::string& folder) {
  const std::string name = std::filesystem::path(folder).filename().string();
  const std::string suffix = kPartialSuffix;
  return name.size() > suffix.size() &&
         name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

namespace internal {

void WriteObjectFolder(const GeneratedObject& object, const std::string& dir,
                       const ObjectFolderOptions& options) {
  namespace fs = std::filesystem;
  // everything goes to a staging folder, renamed into place at the end (removed on an error)
  const fs::path target(dir);
  std::error_code ec;
  if (fs::exists(target, ec) &&
      !(fs::is_directory(target, ec) &&
        (fs::is_empty(target, ec) || options.replaceable(target.string()))))
    throw Error("WriteObject: '" + dir + "' exists and holds something " + options.writer +
                " did not write: not replaced");
  internal::StagedPath staged(dir, dir + kPartialSuffix);
  const fs::path root(staged.Temporary());
  fs::remove_all(root, ec);
  fs::create_directories(root / "textured_objs", ec);
  if (ec) throw Error("WriteObject: cannot create '" + (root / "textured_objs").string() + "'");

  // one OBJ per piece, named by the piece or numbered in link, part, piece order
  std::vector<std::vector<std::string>> files(object.links.size());
  int k = 0;
  V3 lo = V3::Constant(1e30), hi = V3::Constant(-1e30);
  for (const GeneratedLink& l : object.links) {
    for (const GeneratedPart& part : l.parts) {
      for (const GeneratedPiece& piece : part.pieces) {
        const std::string name = piece.file.empty() ? "original-" + std::to_string(k) : piece.file;
        files[l.id].push_back(name);
        WriteFile(root / "textured_objs" / (name + ".obj"), ObjText(piece, name));
        WriteFile(root / "textured_objs" / (name + ".mtl"), MtlText(piece));
        for (const V3& v : piece.vertices) {
          lo = lo.cwiseMin(v);
          hi = hi.cwiseMax(v);
        }
        ++k;
      }
    }
  }
  if (k == 0) lo = hi = V3::Zero();
  if (options.mobility) {
    WriteFile(root / "mobility.urdf", UrdfText(object, files));
    WriteFile(root / "mobility_v2.json", MobilityText(object));
    std::string sem;
    for (const GeneratedLink& l : object.links) {
      sem += "link_" + std::to_string(l.id) + " " + SemanticsKind(l) + " " + l.name + "\n";
    }
    WriteFile(root / "semantics.txt", sem);
  }
  // the dataset's keys (string values), then partsim's provenance
  WriteFile(root / "meta.json",
            !options.meta_json.empty()
                ? options.meta_json
                : "{\"model_id\": " + Quoted(object.model_id) +
                      ", \"anno_id\": " + Quoted(object.anno_id) +
                      ", \"user_id\": \"partsim\", \"time_in_sec\": \"0\", \"version\": \"3\", "
                      "\"model_cat\": " +
                      Quoted(object.category) +
                      ", \"generator\": \"partsim assets generate\", \"seed\": " +
                      std::to_string(object.seed) + ", \"index\": " + std::to_string(object.index) +
                      "}\n");
  WriteFile(root / "bounding_box.json",
            "{\"min\": " + Json3(lo) + ", \"max\": " + Json3(hi) + "}\n");
  if (!options.result_json.empty()) {
    WriteFile(root / "result.json", options.result_json);
  } else {
    const Node tree = PartTree(object, files);
    WriteFile(root / "result.json", "[" + ResultJson(tree, object.category) + "]\n");
    int next = 0;
    WriteFile(root / "result_after_merging.json", "[" + MergedJson(tree, &next) + "]\n");
  }
  // complete: into place
  fs::remove_all(target, ec);
  try {
    staged.Commit();
  } catch (const Error& e) {
    throw Error(std::string("WriteObject: ") + e.what());
  }
}

}  // namespace internal

void WriteObject(const GeneratedObject& object, const std::string& dir) {
  internal::WriteObjectFolder(object, dir, internal::ObjectFolderOptions());
}

void WriteUnannotatedObject(const GeneratedObject& object, const std::string& dir) {
  internal::ObjectFolderOptions options;
  options.mobility = false;
  internal::WriteObjectFolder(object, dir, options);
}

}  // namespace partsim
