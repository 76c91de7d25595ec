// Writes a GeneratedObject as a PartNet-Mobility folder (docs/partnet_mobility_format.md).
// Numbers have fixed formats so that the same object always gives the same bytes.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "assets/generator/mesh_builder.h"
#include "partsim/assets/generator.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

using internal::gen::ComputeVolumeProps;
using internal::gen::M3;
using internal::gen::Mesh;
using internal::gen::V3;
using internal::gen::VolumeProps;

constexpr double kPi = 3.14159265358979323846;

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
/// parent's origin for fixed ones.
std::vector<V3> LinkOrigins(const GeneratedObject& o) {
  std::vector<V3> origin(o.links.size(), V3::Zero());
  for (const GeneratedLink& l : o.links) {
    bool moving = l.joint == "hinge" || l.joint == "slider";
    origin[l.id] = moving ? l.axis_origin : (l.parent >= 0 ? origin[l.parent] : V3::Zero());
  }
  return origin;
}

std::string ObjText(const GeneratedPiece& p, int k) {
  std::string s;
  s.reserve(p.vertices.size() * 40 + p.triangles.size() * 24 + 64);
  s += "# partsim generator\nmtllib original-" + std::to_string(k) + ".mtl\n";
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

std::string UrdfText(const GeneratedObject& o, const std::vector<std::vector<int>>& files) {
  std::vector<V3> origin = LinkOrigins(o);
  std::string s = "<?xml version=\"1.0\"?>\n<robot name=\"" + o.model_id + "\">\n";
  s += "  <link name=\"base\"/>\n";
  for (const GeneratedLink& l : o.links) {
    const std::string name = "link_" + std::to_string(l.id);
    // a rotating slider gets a helper link for its translation
    if (l.rotates) {
      s += "  <link name=\"" + name + "_helper\">\n" + InertialXml(GeneratedLink(), origin[l.id]) +
           "  </link>\n";
    }
    s += "  <link name=\"" + name + "\">\n";
    s += InertialXml(l, origin[l.id]);
    size_t k = 0;
    for (const GeneratedPart& part : l.parts) {
      for (size_t i = 0; i < part.pieces.size(); ++i, ++k) {
        std::string file = "textured_objs/original-" + std::to_string(files[l.id][k]) + ".obj";
        std::string org = "      <origin xyz=\"" + Vec6(-origin[l.id]) + "\" rpy=\"0 0 0\"/>\n";
        std::string geo =
            "      <geometry>\n        <mesh filename=\"" + file + "\"/>\n      </geometry>\n";
        s += "    <visual name=\"" + part.name + "-" + std::to_string(part.id) + "\">\n" + org +
             geo + "    </visual>\n";
        s += "    <collision>\n" + org + geo + "    </collision>\n";
      }
    }
    s += "  </link>\n";
  }
  for (const GeneratedLink& l : o.links) {
    const std::string name = "link_" + std::to_string(l.id);
    const std::string parent = l.parent < 0 ? "base" : "link_" + std::to_string(l.parent);
    V3 parent_origin = l.parent < 0 ? V3::Zero() : origin[l.parent];
    V3 xyz = origin[l.id] - parent_origin;
    const std::string axis = "    <axis xyz=\"" + Vec6(l.axis_direction) + "\"/>\n";
    s +=
        "  <joint name=\"joint_" + std::to_string(l.id) + "\" type=\"" + JointTypeUrdf(l) + "\">\n";
    s += "    <origin xyz=\"" + Vec6(xyz) + "\" rpy=\"0 0 0\"/>\n";
    s += "    <parent link=\"" + parent + "\"/>\n";
    s += "    <child link=\"" + name + (l.rotates ? "_helper" : "") + "\"/>\n";
    if (l.joint == "hinge" || l.joint == "slider") {
      s += axis;
      if (!l.no_limit) s += LimitXml(l, false);
      s += DynamicsXml(l.damping, l.friction);
    }
    s += "  </joint>\n";
    if (l.rotates) {
      s += "  <joint name=\"joint_" + std::to_string(l.id) + "_rot\" type=\"" +
           std::string(l.no_rotation_limit ? "continuous" : "revolute") + "\">\n";
      s += "    <origin xyz=\"0.000000 0.000000 0.000000\" rpy=\"0 0 0\"/>\n";
      s += "    <parent link=\"" + name + "_helper\"/>\n    <child link=\"" + name + "\"/>\n";
      s += axis;
      if (!l.no_rotation_limit) s += LimitXml(l, true);
      s += DynamicsXml(l.rotation_damping, l.rotation_friction);
      s += "  </joint>\n";
    }
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
         "\",\n    \"name\": \"" + l.name + "\",\n    \"parts\": [";
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

}  // namespace

void WriteObject(const GeneratedObject& object, const std::string& dir) {
  namespace fs = std::filesystem;
  fs::path root(dir);
  std::error_code ec;
  fs::create_directories(root / "textured_objs", ec);
  if (ec) throw Error("WriteObject: cannot create '" + (root / "textured_objs").string() + "'");

  // one OBJ per piece, numbered in link, part, piece order
  std::vector<std::vector<int>> files(object.links.size());
  int k = 0;
  V3 lo = V3::Constant(1e30), hi = V3::Constant(-1e30);
  for (const GeneratedLink& l : object.links) {
    for (const GeneratedPart& part : l.parts) {
      for (const GeneratedPiece& piece : part.pieces) {
        files[l.id].push_back(k);
        WriteFile(root / "textured_objs" / ("original-" + std::to_string(k) + ".obj"),
                  ObjText(piece, k));
        WriteFile(root / "textured_objs" / ("original-" + std::to_string(k) + ".mtl"),
                  MtlText(piece));
        for (const V3& v : piece.vertices) {
          lo = lo.cwiseMin(v);
          hi = hi.cwiseMax(v);
        }
        ++k;
      }
    }
  }
  if (k == 0) lo = hi = V3::Zero();
  WriteFile(root / "mobility.urdf", UrdfText(object, files));
  WriteFile(root / "mobility_v2.json", MobilityText(object));
  std::string sem;
  for (const GeneratedLink& l : object.links) {
    sem += "link_" + std::to_string(l.id) + " " + l.joint + " " + l.name + "\n";
  }
  WriteFile(root / "semantics.txt", sem);
  WriteFile(root / "meta.json",
            "{\n  \"model_cat\": \"" + object.category + "\",\n  \"model_id\": \"" +
                object.model_id + "\",\n  \"anno_id\": \"" + object.anno_id +
                "\",\n  \"generator\": \"partsim assets generate\",\n  \"seed\": " +
                std::to_string(object.seed) + ",\n  \"index\": " + std::to_string(object.index) +
                "\n}\n");
  WriteFile(root / "bounding_box.json",
            "{\"min\": " + Json3(lo) + ", \"max\": " + Json3(hi) + "}\n");
}

}  // namespace partsim
