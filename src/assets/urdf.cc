#include "partsim/assets/urdf.h"

#include <tinyxml2.h>

#include <Eigen/Eigenvalues>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/file_read.h"
#include "partsim/assets/mesh.h"
#include "partsim/assets/srdf.h"
#include "partsim/core/check.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using tinyxml2::XMLElement;

// A URDF joint as read, before the tree is ordered.
struct RawJoint {
  std::string name;
  std::string type;
  std::string parent;
  std::string child;
  const XMLElement* element = nullptr;
};

// Rotation taking the x axis onto the unit vector `a` (a = -x gives a half turn about z).
Eigen::Quaterniond XToAxis(const Eigen::Vector3d& a) {
  if (a.x() < -1.0 + 1e-12)
    return Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), a).normalized();
}

// Shape pose offset that lays partsim's x-aligned cylinders and capsules along URDF's z.
Eigen::Quaterniond XToZ() {
  return Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()));
}

// Parses URDF text for one source; every error message starts with "URDF <source>: ".
class Parser {
 public:
  Parser(const UrdfLoader& loader, const std::string& base_dir, const std::string& source,
         LoadReport* report)
      : loader_(loader),
        base_dir_(base_dir.empty() ? "." : base_dir),
        source_(source),
        report_(report) {}

  ArticulationDesc Run(const std::string& text);

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw Error("URDF " + source_ + ": " + what);
  }
  // a defect partsim works around: a warning in the report, an error when the loader is strict
  void Warn(const std::string& what) const {
    if (loader_.strict) Fail(what + " (strict loading)");
    report_->Warn(source_, what);
  }

  // numbers
  std::vector<double> Numbers(const char* text, size_t count, const std::string& where) const;
  double Number(const XMLElement* e, const char* attr, std::optional<double> fallback,
                const std::string& where) const;
  Eigen::Vector3d Vector(const XMLElement* e, const char* attr, const Eigen::Vector3d& fallback,
                         const std::string& where) const;
  Pose Origin(const XMLElement* parent, const std::string& where, bool scaled = true) const;

  // elements
  void ReadMaterials(const XMLElement* robot);
  std::optional<RenderMaterial> ReadMaterial(const XMLElement* material,
                                             const std::string& where) const;
  LinkDesc ReadLink(const XMLElement* link, const std::string& name);
  void ReadCollision(const XMLElement* c, const std::string& link, LinkDesc* out);
  void ReadVisual(const XMLElement* v, const std::string& link, LinkDesc* out);
  // fills a CollisionShape or VisualShape from <geometry>; for a mesh, returns its file name
  // and scale instead
  template <typename Shape>
  std::optional<std::pair<std::string, Eigen::Vector3d>> ReadGeometry(const XMLElement* parent,
                                                                      const std::string& where,
                                                                      Shape* shape) const;
  std::optional<Inertial> ReadInertial(const XMLElement* e, const std::string& link) const;
  JointDesc ReadJoint(const RawJoint& raw, ArticulationDesc* desc);
  // a file named by the URDF, resolved; nullopt (and the file noted for the one error that
  // lists them all) when it is missing
  // `kind` names what the file should be ("mesh file") when the path is a device, a FIFO or a
  // symbolic link loop
  std::optional<std::string> ResolvePath(const std::string& uri, const std::string& where,
                                         const char* kind = "texture file") const;
  // ResolvePath for a mesh file, which must also not be empty (noted like a missing one)
  std::optional<std::string> ResolveMeshFile(const std::string& uri,
                                             const std::string& where) const;
  // notes a missing or unreadable file; Run fails listing every one of them
  void NoteBadFile(const std::string& where, const std::string& uri,
                   const std::string& problem) const;
  std::vector<std::shared_ptr<const MeshData>> CollisionMeshes(const std::string& path,
                                                               const Eigen::Vector3d& scale,
                                                               const std::string& where,
                                                               const std::string& uri);
  // the sub-meshes of a file as read (LoadMeshFile), once per parse
  const std::vector<LoadedMesh>& FileMeshes(const std::string& path, const Eigen::Vector3d& scale);

  const UrdfLoader& loader_;
  fs::path base_dir_;
  std::string source_;
  LoadReport* report_;
  std::map<std::string, RenderMaterial> materials_;
  // meshes read during this parse, by path and scale
  std::map<std::pair<std::string, std::string>, std::vector<std::shared_ptr<const MeshData>>>
      collision_cache_;
  // files that are missing or cannot be read: "where: 'uri' problem", in file order
  mutable std::vector<std::string> bad_files_;
  mutable std::set<std::string> bad_uris_;
  std::map<std::pair<std::string, std::string>, std::vector<LoadedMesh>> file_cache_;
};

std::vector<double> Parser::Numbers(const char* text, size_t count,
                                    const std::string& where) const {
  std::vector<double> out;
  std::istringstream tokens(text == nullptr ? "" : text);
  std::string tok;
  while (tokens >> tok) {
    const char* b = tok.data();
    const char* e = tok.data() + tok.size();
    if (b != e && *b == '+') ++b;
    double v = 0;
    auto [ptr, ec] = std::from_chars(b, e, v);
    if (ec != std::errc() || ptr != e) {
      Fail(where + ": '" + tok + "' is not a number");
    }
    if (!std::isfinite(v)) Fail(where + ": '" + tok + "' is not a finite number");
    out.push_back(v);
  }
  if (out.size() != count) {
    Fail(where + ": expected " + std::to_string(count) + " number" + (count > 1 ? "s" : "") +
         ", got " + std::to_string(out.size()) + " in '" + (text ? text : "") + "'");
  }
  return out;
}

double Parser::Number(const XMLElement* e, const char* attr, std::optional<double> fallback,
                      const std::string& where) const {
  const char* text = e->Attribute(attr);
  const std::string at = where + " <" + e->Name() + " " + attr + ">";
  if (text == nullptr) {
    if (!fallback) Fail(at + " is missing");
    return *fallback;
  }
  return Numbers(text, 1, at)[0];
}

Eigen::Vector3d Parser::Vector(const XMLElement* e, const char* attr,
                               const Eigen::Vector3d& fallback, const std::string& where) const {
  const char* text = e->Attribute(attr);
  if (text == nullptr) return fallback;
  std::vector<double> v = Numbers(text, 3, where + " <" + e->Name() + " " + attr + ">");
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

Pose Parser::Origin(const XMLElement* parent, const std::string& where, bool scaled) const {
  const XMLElement* o = parent->FirstChildElement("origin");
  if (o == nullptr) return Pose();
  Eigen::Vector3d xyz = Vector(o, "xyz", Eigen::Vector3d::Zero(), where);
  Eigen::Vector3d rpy = Vector(o, "rpy", Eigen::Vector3d::Zero(), where);
  // fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll)
  Eigen::Quaterniond q = Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX());
  Pose pose(scaled ? Eigen::Vector3d(xyz * loader_.scale) : xyz, q.normalized());
  if (!pose.IsValid()) Fail(where + " <origin> is not finite after scaling");
  return pose;
}

void Parser::ReadMaterials(const XMLElement* robot) {
  for (const XMLElement* m = robot->FirstChildElement("material"); m != nullptr;
       m = m->NextSiblingElement("material")) {
    const char* name = m->Attribute("name");
    if (name == nullptr)
      Fail("<material> at line " + std::to_string(m->GetLineNum()) + " has no name");
    std::optional<RenderMaterial> mat = ReadMaterial(m, std::string("material '") + name + "'");
    materials_[name] = mat.value_or(RenderMaterial());
  }
}

std::optional<RenderMaterial> Parser::ReadMaterial(const XMLElement* material,
                                                   const std::string& where) const {
  const XMLElement* color = material->FirstChildElement("color");
  const XMLElement* texture = material->FirstChildElement("texture");
  if (color == nullptr && texture == nullptr) return std::nullopt;
  RenderMaterial out;
  if (color != nullptr) {
    const char* rgba = color->Attribute("rgba");
    if (rgba != nullptr) {
      std::vector<double> c = Numbers(rgba, 4, where + " <color rgba>");
      out.base_color = Eigen::Vector4d(c[0], c[1], c[2], c[3]).cast<float>();
    }
  }
  if (texture != nullptr && texture->Attribute("filename") != nullptr) {
    // a missing texture is listed with the missing meshes
    out.diffuse_texture =
        ResolvePath(texture->Attribute("filename"), where + " <texture>").value_or("");
  }
  return out;
}

void Parser::NoteBadFile(const std::string& where, const std::string& uri,
                         const std::string& problem) const {
  bad_files_.push_back(where + ": '" + uri + "' " + problem);
  bad_uris_.insert(uri);
}

std::optional<std::string> Parser::ResolveMeshFile(const std::string& uri,
                                                   const std::string& where) const {
  std::optional<std::string> path = ResolvePath(uri, where, "mesh file");
  std::error_code ec;
  if (path && fs::file_size(*path, ec) == 0 && !ec) {
    NoteBadFile(where, uri, "is empty");
    return std::nullopt;
  }
  return path;
}

std::optional<std::string> Parser::ResolvePath(const std::string& uri, const std::string& where,
                                               const char* kind) const {
  std::vector<fs::path> tried;
  std::error_code ec;
  // the first candidate that exists but is no regular file (checked without opening it)
  std::string not_a_file;
  auto found = [&](const fs::path& p) {
    tried.push_back(p);
    if (fs::is_regular_file(p, ec)) return true;
    const std::string what = internal::NonRegularFileKind(p.string());
    if (not_a_file.empty() && !what.empty() && what != "a folder")
      not_a_file = "('" + p.string() + "') is " + what + ", not a " + kind;
    return false;
  };
  static const std::string kPackage = "package://";
  static const std::string kFile = "file://";
  if (uri.rfind(kPackage, 0) == 0) {
    // package://NAME/rest
    std::string rest = uri.substr(kPackage.size());
    size_t slash = rest.find('/');
    std::string name = rest.substr(0, slash);
    std::string rel = slash == std::string::npos ? "" : rest.substr(slash + 1);
    auto it = loader_.package_dirs.find(name);
    if (it != loader_.package_dirs.end() && found(fs::path(it->second) / rel)) {
      return (fs::path(it->second) / rel).lexically_normal().string();
    }
    // a folder NAME on the way up from the URDF's folder, or beside one of those folders
    fs::path dir = fs::absolute(base_dir_, ec).lexically_normal();
    for (int depth = 0; depth < 64 && !dir.empty(); ++depth) {
      if (dir.filename() == name && found(dir / rel)) return (dir / rel).string();
      if (found(dir / name / rel)) return (dir / name / rel).string();
      if (dir == dir.parent_path()) break;
      dir = dir.parent_path();
    }
    if (found(base_dir_ / rel)) return (base_dir_ / rel).lexically_normal().string();
  } else {
    std::string path = uri.rfind(kFile, 0) == 0 ? uri.substr(kFile.size()) : uri;
    fs::path p(path);
    if (p.is_relative()) p = base_dir_ / p;
    if (found(p)) return p.lexically_normal().string();
  }
  if (!not_a_file.empty()) {
    NoteBadFile(where, uri, not_a_file);
    return std::nullopt;
  }
  std::string msg = "not found (tried";
  for (const fs::path& p : tried) msg += " '" + p.string() + "'";
  NoteBadFile(where, uri, msg + ")");
  return std::nullopt;
}

std::vector<std::shared_ptr<const MeshData>> Parser::CollisionMeshes(const std::string& path,
                                                                     const Eigen::Vector3d& scale,
                                                                     const std::string& where,
                                                                     const std::string& uri) {
  std::ostringstream key;
  key.precision(17);
  key << scale.transpose();
  auto found = collision_cache_.find({path, key.str()});
  if (found != collision_cache_.end()) return found->second;

  // the file is read once per parse, for its visuals and collisions alike
  const std::vector<LoadedMesh>& parts = FileMeshes(path, scale);
  std::vector<std::shared_ptr<MeshData>> loaded;
  if (loader_.load_multiple_collisions_from_file) {
    loaded = ConnectedPieces(parts);
  } else {
    loaded = {MergeMeshes(parts, path)};
  }

  // MuJoCo collides each piece as its convex hull and refuses pieces without volume: flat,
  // line-like and tiny pieces are thickened or dropped; the file's first user hears of it, once
  std::vector<std::shared_ptr<const MeshData>> pieces;
  std::vector<std::string> repairs, simplified;
  int non_convex = 0;
  const bool several = loaded.size() > 1;
  for (size_t k = 0; k < loaded.size(); ++k) {
    ConvexPieceCheck check = CheckConvexPiece(loaded[k]);
    if (!check.repair.empty()) {
      repairs.push_back((several ? "piece " + std::to_string(k) + " " : std::string()) +
                        check.repair);
    }
    if (check.piece) pieces.push_back(check.piece);
    non_convex += check.non_convex;
    if (!check.simplified.empty()) {
      simplified.push_back((several ? "piece " + std::to_string(k) + " " : std::string()) +
                           check.simplified);
    }
  }
  const std::string file = "mesh '" + uri + "'";
  if (!repairs.empty()) {
    std::string list;
    for (size_t k = 0; k < repairs.size() && k < 4; ++k) list += (k ? "; " : "") + repairs[k];
    if (repairs.size() > 4) list += "; and " + std::to_string(repairs.size() - 4) + " more";
    Warn(where + " " + file + ": " +
         (several ? std::to_string(repairs.size()) + " of " + std::to_string(loaded.size()) +
                        " collision pieces are degenerate: "
                  : "collision piece ") +
         list);
  }
  // a hull of too many vertices, cut short, is no defect of the file either
  if (!simplified.empty()) {
    std::string list;
    for (size_t k = 0; k < simplified.size() && k < 4; ++k) list += (k ? "; " : "") + simplified[k];
    if (simplified.size() > 4) list += "; and " + std::to_string(simplified.size() - 4) + " more";
    report_->Warn(source_, where + " " + file + ": collision piece " + list);
  }
  // a non-convex mesh is no defect of the file, only a limit of hull collision: a warning even
  // when loading strictly
  if (non_convex > 0) {
    const std::string decompose = "`partsim assets decompose " + path + " --out DIR`";
    if (several) {
      report_->Warn(
          source_,
          where + " " + file + ": " + std::to_string(non_convex) + " of " +
              std::to_string(loaded.size()) +
              " connected pieces are not convex, and each collides as its convex hull; split the "
              "mesh into convex pieces with " +
              decompose);
    } else {
      report_->Warn(
          source_,
          where + " " + file +
              " is not convex, and collides as one convex hull; set "
              "load_multiple_collisions_from_file to make each connected part its own piece, or "
              "split it into convex pieces with " +
              decompose);
    }
  }
  collision_cache_[{path, key.str()}] = pieces;
  return pieces;
}

const std::vector<LoadedMesh>& Parser::FileMeshes(const std::string& path,
                                                  const Eigen::Vector3d& scale) {
  std::ostringstream key;
  key.precision(17);
  key << scale.transpose();
  auto& cached = file_cache_[{path, key.str()}];
  if (cached.empty()) cached = LoadMeshFile(path, scale);
  return cached;
}

template <typename Shape>
std::optional<std::pair<std::string, Eigen::Vector3d>> Parser::ReadGeometry(
    const XMLElement* parent, const std::string& where, Shape* shape) const {
  const double scale = loader_.scale;
  const XMLElement* g = parent->FirstChildElement("geometry");
  if (g == nullptr) Fail(where + " has no <geometry>");
  const XMLElement* e = g->FirstChildElement();
  if (e == nullptr) Fail(where + " <geometry> is empty");
  const std::string kind = e->Name();
  auto positive = [&](double v, const std::string& what) {
    if (!(v > 0) || !std::isfinite(v)) Fail(where + " <" + kind + "> " + what + " must be > 0");
    return v;
  };
  auto attr = [&](const char* name) -> const char* {
    const char* t = e->Attribute(name);
    if (t == nullptr) Fail(where + " <" + kind + "> has no '" + name + "'");
    return t;
  };
  if (kind == "box") {
    std::vector<double> s = Numbers(attr("size"), 3, where + " <box size>");
    shape->type = ShapeType::kBox;
    for (int i = 0; i < 3; ++i) shape->half_size[i] = positive(s[i] * scale / 2, "size");
  } else if (kind == "sphere") {
    shape->type = ShapeType::kSphere;
    shape->radius =
        positive(Numbers(attr("radius"), 1, where + " <sphere radius>")[0] * scale, "radius");
  } else if (kind == "cylinder" || kind == "capsule") {
    shape->type = kind == "cylinder" ? ShapeType::kCylinder : ShapeType::kCapsule;
    shape->radius =
        positive(Numbers(attr("radius"), 1, where + " <" + kind + " radius>")[0] * scale, "radius");
    shape->half_length = positive(
        Numbers(attr("length"), 1, where + " <" + kind + " length>")[0] * scale / 2, "length");
    // URDF cylinders run along z, partsim's along x
    shape->pose = shape->pose * Pose(Eigen::Vector3d::Zero(), XToZ());
  } else if (kind == "mesh") {
    shape->type = ShapeType::kConvexMesh;
    Eigen::Vector3d s = Eigen::Vector3d::Ones();
    if (const char* t = e->Attribute("scale")) {
      std::vector<double> v = Numbers(t, 3, where + " <mesh scale>");
      s = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    s *= scale;
    if (!s.allFinite() || (s.array() == 0).any())
      Fail(where + " <mesh scale> must be finite and non-zero");
    return std::make_pair(std::string(attr("filename")), s);
  } else {
    Fail(where + " <geometry> has unknown shape <" + kind + ">");
  }
  return std::nullopt;
}

void Parser::ReadCollision(const XMLElement* c, const std::string& link, LinkDesc* out) {
  const std::string where = "link '" + link + "' <collision>";
  CollisionShape shape;
  shape.pose = Origin(c, where);
  if (const char* n = c->Attribute("name")) shape.name = n;

  // density and material: per-link override, else the loader's defaults
  shape.density = loader_.density;
  shape.material = loader_.material;
  // partsim's density and contact material (written by WriteUrdf) replace the defaults
  if (const XMLElement* p = c->FirstChildElement("partsim:collision")) {
    const std::string at = where + " <partsim:collision>";
    shape.density = Number(p, "density", shape.density, where);
    if (!(shape.density > 0)) Fail(at + " density must be > 0");
    if (p->Attribute("static_friction") != nullptr) {
      PhysicalMaterial m;
      m.static_friction = Number(p, "static_friction", std::nullopt, where);
      m.dynamic_friction = Number(p, "dynamic_friction", m.static_friction, where);
      m.restitution = Number(p, "restitution", 0.0, where);
      if (m.static_friction < 0 || m.dynamic_friction < 0) Fail(at + " friction is negative");
      if (m.restitution < 0 || m.restitution > 1) Fail(at + " restitution is not in [0, 1]");
      shape.material = m;
    }
  }
  auto ov = loader_.link_overrides.find(link);
  if (ov != loader_.link_overrides.end()) {
    if (ov->second.density) shape.density = *ov->second.density;
    if (ov->second.material) shape.material = ov->second.material;
  }

  auto mesh = ReadGeometry(c, where, &shape);
  if (!mesh) {
    out->collisions.push_back(shape);
    return;
  }
  std::optional<std::string> path = ResolveMeshFile(mesh->first, where + " <mesh>");
  if (!path) return;
  std::vector<std::shared_ptr<const MeshData>> pieces;
  try {
    pieces = CollisionMeshes(*path, mesh->second, where, mesh->first);
  } catch (const Error& e) {
    NoteBadFile(where + " <mesh>", mesh->first, std::string("cannot be read: ") + e.what());
    return;
  }
  for (const auto& piece : pieces) {
    CollisionShape s = shape;
    s.mesh = piece;
    out->collisions.push_back(std::move(s));
  }
}

void Parser::ReadVisual(const XMLElement* v, const std::string& link, LinkDesc* out) {
  const std::string where = "link '" + link + "' <visual>";
  VisualShape shape;
  shape.pose = Origin(v, where);
  if (const char* n = v->Attribute("name")) shape.name = n;

  // material: inline colour or texture, else a robot-level material by name
  std::optional<RenderMaterial> material;
  if (const XMLElement* m = v->FirstChildElement("material")) {
    material = ReadMaterial(m, where + " <material>");
    const char* name = m->Attribute("name");
    if (!material && name != nullptr) {
      auto it = materials_.find(name);
      if (it != materials_.end()) material = it->second;
    }
  }
  if (material) shape.material = *material;

  auto mesh = ReadGeometry(v, where, &shape);
  if (!mesh) {
    out->visuals.push_back(shape);
    return;
  }
  std::optional<std::string> path = ResolveMeshFile(mesh->first, where + " <mesh>");
  if (!path) return;
  const std::vector<LoadedMesh>* parts = nullptr;
  try {
    parts = &FileMeshes(*path, mesh->second);
  } catch (const Error& e) {
    NoteBadFile(where + " <mesh>", mesh->first, std::string("cannot be read: ") + e.what());
    return;
  }
  // one visual per sub-mesh, with the file's material unless the URDF gives one
  for (const LoadedMesh& part : *parts) {
    VisualShape s = shape;
    s.mesh = part.mesh;
    if (!material) s.material = part.material;
    out->visuals.push_back(std::move(s));
  }
}

std::optional<Inertial> Parser::ReadInertial(const XMLElement* e, const std::string& link) const {
  const std::string where = "link '" + link + "' <inertial>";
  const XMLElement* mass_e = e->FirstChildElement("mass");
  if (mass_e == nullptr) Fail(where + " has no <mass>");
  const double s = loader_.scale;
  double mass = Number(mass_e, "value", std::nullopt, where);
  if (mass < 0) Fail(where + " has negative mass " + FormatNumber(mass));
  // a massless link (common for frames in ROS files): mass follows from its shapes, if any
  if (mass == 0) return std::nullopt;  // ReadLink warns when shapes then give it a mass

  // inertia tensor about the centre of mass in the <origin> frame; scaling at constant
  // density multiplies mass by s^3 and inertia by s^5
  Eigen::Matrix3d tensor = Eigen::Matrix3d::Zero();
  if (const XMLElement* in = e->FirstChildElement("inertia")) {
    const char* names[6] = {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"};
    double v[6];
    for (int i = 0; i < 6; ++i) v[i] = Number(in, names[i], 0.0, where);
    tensor << v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5];
  }
  mass *= s * s * s;
  tensor *= std::pow(s, 5);
  if (!std::isfinite(mass) || !tensor.allFinite()) Fail(where + " is not finite after scaling");
  // the bounds of the physics (physics/description.cc): at most 1e9 kg, and 1e9 kg at 1e6 m
  constexpr double kMaxMass = 1e9, kMaxInertia = 1e21;
  if (mass > kMaxMass)
    Fail(where + " <mass value> is " + FormatNumber(mass) + " kg" +
         (s != 1 ? " after scaling" : "") + ", beyond the 1e9 kg partsim simulates");
  if (tensor.cwiseAbs().maxCoeff() > kMaxInertia)
    Fail(where + " <inertia> has an entry of " + FormatNumber(tensor.cwiseAbs().maxCoeff()) +
         " kg m^2" + (s != 1 ? " after scaling" : "") +
         ", beyond the 1e21 kg m^2 partsim simulates");

  // principal axes; eigenvalues a hair below zero are rounding, clearly negative ones an error
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(tensor);
  Eigen::Vector3d moments = eig.eigenvalues();
  Eigen::Matrix3d axes = eig.eigenvectors();
  const double largest = std::max(moments.cwiseAbs().maxCoeff(), 0.0);
  if (moments.minCoeff() < -1e-9 - 1e-6 * largest) {
    Fail(where + " has an inertia tensor that is not positive semi-definite (principal moments " +
         FormatNumber(moments[0]) + ", " + FormatNumber(moments[1]) + ", " +
         FormatNumber(moments[2]) + ")");
  }
  if (largest <= 1e-12 * mass) {
    // no inertia at all (an <inertia> of zeros, or none): a link whose centre of mass lies on
    // its joint's axis would turn without resistance (one such joint spun to -283,062 rad in
    // 0.4 s). It gets the inertia of a solid sphere of its mass, 5 cm in radius (scaled).
    const double r = 0.05 * s;
    moments.setConstant(0.4 * mass * r * r);
    axes.setIdentity();
    Warn(where + " has no inertia tensor (all zero) for its mass of " + FormatNumber(mass) +
         " kg: set to that of a solid sphere 5 cm in radius, " + FormatNumber(moments[0]) +
         " kg m^2 about each axis");
  }
  const double floor = std::max(1e-9 * mass, 1e-6 * largest);
  moments = moments.cwiseMax(floor);

  // MuJoCo refuses principal moments that break the triangle inequality A + B >= C (exported
  // files often do): balanced as its compiler's balanceinertia does, all three set to their mean.
  // A breach within rounding (a thin disc's A + B = C) only moves C onto A + B. Moments ascend.
  const double breach = moments[2] - (moments[0] + moments[1]);
  if (breach > 1e-9 * moments[2]) {
    const Eigen::Vector3d before = moments;
    moments.setConstant(moments.sum() / 3.0);
    auto list = [](const Eigen::Vector3d& v) {
      std::ostringstream out;
      out.precision(6);
      out << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
      return out.str();
    };
    Warn(where + ": principal moments of inertia " + list(before) +
         " kg m^2 break the triangle inequality A + B >= C; set to their mean " + list(moments) +
         " as MuJoCo's balanceinertia does");
  } else if (breach > 0) {
    moments[2] = moments[0] + moments[1];
  }
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);

  Inertial out;
  out.mass = mass;
  out.inertia = moments;
  Pose origin = Origin(e, where);
  out.cmass_local_pose = Pose(origin.p, (origin.q * Eigen::Quaterniond(axes)).normalized());
  return out;
}

LinkDesc Parser::ReadLink(const XMLElement* link, const std::string& name) {
  LinkDesc out;
  out.name = name;
  for (const XMLElement* c = link->FirstChildElement("collision");
       c != nullptr && loader_.load_collisions; c = c->NextSiblingElement("collision")) {
    ReadCollision(c, name, &out);
  }
  for (const XMLElement* v = link->FirstChildElement("visual"); v != nullptr;
       v = v->NextSiblingElement("visual")) {
    ReadVisual(v, name, &out);
  }
  if (const XMLElement* in = link->FirstChildElement("inertial")) {
    out.inertial = ReadInertial(in, name);
    if (!out.inertial && !out.collisions.empty())
      Warn("link '" + name +
           "' <inertial> has mass 0: the link's mass and inertia follow "
           "from its collision shapes at the loader's density instead");
  }
  return out;
}

JointDesc Parser::ReadJoint(const RawJoint& raw, ArticulationDesc* desc) {
  const std::string where = "joint '" + raw.name + "'";
  const XMLElement* e = raw.element;
  JointDesc j;
  j.name = raw.name;
  const Pose origin = Origin(e, where);

  if (raw.type == "fixed") {
    j.type = JointType::kFixed;
  } else if (raw.type == "revolute") {
    j.type = JointType::kRevolute;
  } else if (raw.type == "continuous") {
    j.type = JointType::kContinuous;
  } else if (raw.type == "prismatic") {
    j.type = JointType::kPrismatic;
  } else {
    Fail(where + " has type '" + raw.type + "', which partsim does not support here");
  }

  // the joint frame: URDF origin, turned so that its x axis is the URDF axis
  Eigen::Quaterniond r = Eigen::Quaterniond::Identity();
  if (j.type != JointType::kFixed) {
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
    if (const XMLElement* a = e->FirstChildElement("axis")) {
      axis = Vector(a, "xyz", axis, where);
    }
    if (axis.norm() < 1e-9) Fail(where + " <axis> has zero length");
    r = XToAxis(axis.normalized());
  }
  j.pose_in_parent = origin * Pose(Eigen::Vector3d::Zero(), r);
  j.pose_in_child = Pose(Eigen::Vector3d::Zero(), r);

  // limits: required for revolute and prismatic joints; prismatic ones scale with the robot
  const XMLElement* limit = e->FirstChildElement("limit");
  if ((j.type == JointType::kRevolute || j.type == JointType::kPrismatic) && limit == nullptr) {
    Fail(where + " (" + raw.type + ") has no <limit>");
  }
  if (limit != nullptr && j.type != JointType::kFixed) {
    if (j.type != JointType::kContinuous && limit->Attribute("lower") == nullptr &&
        limit->Attribute("upper") == nullptr) {
      // a <limit> for effort and velocity alone (ANYmal's): URDF's defaults, 0 and 0, would
      // lock the joint, which is not what such files mean
      Warn(where + " <limit> gives neither lower nor upper: the joint is left unlimited");
    } else if (j.type != JointType::kContinuous) {
      const double s = j.type == JointType::kPrismatic ? loader_.scale : 1.0;
      j.lower = Number(limit, "lower", 0.0, where) * s;
      j.upper = Number(limit, "upper", 0.0, where) * s;
      if (j.lower > j.upper) {
        Fail(where + " <limit> has lower " + FormatNumber(j.lower) + " > upper " +
             FormatNumber(j.upper));
      }
    }
    double effort = Number(limit, "effort", 0.0, where);
    if (effort < 0) Fail(where + " <limit effort> is negative");
    if (effort > 0) j.drive.force_limit = j.effort_limit = effort;
    Number(limit, "velocity", 0.0, where);  // checked, not used
  }

  // damping and dry friction
  if (const XMLElement* d = e->FirstChildElement("dynamics")) {
    j.damping = Number(d, "damping", 0.0, where);
    j.friction = Number(d, "friction", 0.0, where);
    if (j.damping < 0) Fail(where + " <dynamics damping> is negative");
    if (j.friction < 0) Fail(where + " <dynamics friction> is negative");
  }

  // partsim's drive (written by WriteUrdf): gains, force limit, targets and rotor inertia;
  // prismatic targets scale with the robot
  if (const XMLElement* d = e->FirstChildElement("partsim:drive")) {
    if (j.type == JointType::kFixed) Fail(where + " is fixed and cannot have <partsim:drive>");
    const std::string at = where + " <partsim:drive>";
    j.drive.stiffness = Number(d, "stiffness", 0.0, where);
    j.drive.damping = Number(d, "damping", 0.0, where);
    j.drive.force_limit = Number(d, "force_limit", j.drive.force_limit, where);
    const double s = j.type == JointType::kPrismatic ? loader_.scale : 1.0;
    j.drive.target = Number(d, "target", 0.0, where) * s;
    j.drive.velocity_target = Number(d, "velocity_target", 0.0, where) * s;
    j.armature = Number(d, "armature", 0.0, where);
    if (j.drive.stiffness < 0) Fail(at + " stiffness is negative");
    if (j.drive.damping < 0) Fail(at + " damping is negative");
    if (!(j.drive.force_limit > 0)) Fail(at + " force_limit must be > 0");
    if (j.armature < 0) Fail(at + " armature is negative");
  }

  // mimic: a coupling; prismatic lengths scale with the robot. A fixed joint has nothing to
  // couple, so its <mimic> is ignored
  const XMLElement* m = e->FirstChildElement("mimic");
  if (m != nullptr && j.type == JointType::kFixed) {
    Warn(where + " is fixed: its <mimic> is ignored");
    m = nullptr;
  }
  if (m != nullptr) {
    const char* src = m->Attribute("joint");
    if (src == nullptr) Fail(where + " <mimic> has no 'joint'");
    JointCoupling c;
    c.joint = raw.name;
    c.source = src;
    c.multiplier = Number(m, "multiplier", 1.0, where);
    c.offset = Number(m, "offset", 0.0, where);
    if (j.type == JointType::kPrismatic) {
      c.multiplier *= loader_.scale;
      c.offset *= loader_.scale;
    }
    desc->couplings.push_back(c);
  }
  return j;
}

ArticulationDesc Parser::Run(const std::string& text) {
  // xml
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
    Fail("malformed XML at line " + std::to_string(doc.ErrorLineNum()) + ": " +
         (doc.ErrorStr() ? doc.ErrorStr() : "unknown error"));
  }
  const XMLElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) Fail("no <robot> element");
  if (!(loader_.scale > 0) || !std::isfinite(loader_.scale)) {
    Fail("scale " + FormatNumber(loader_.scale) + " must be positive and finite");
  }
  ArticulationDesc desc;
  if (const char* n = robot->Attribute("name")) desc.name = n;
  ReadMaterials(robot);

  // links by name, in file order
  std::vector<const XMLElement*> link_elements;
  std::unordered_map<std::string, int> link_index;
  std::vector<std::string> link_names;
  for (const XMLElement* l = robot->FirstChildElement("link"); l != nullptr;
       l = l->NextSiblingElement("link")) {
    const char* name = l->Attribute("name");
    if (name == nullptr || *name == '\0') {
      Fail("<link> at line " + std::to_string(l->GetLineNum()) + " has no name");
    }
    if (!link_index.emplace(name, static_cast<int>(link_names.size())).second) {
      Fail(std::string("link '") + name + "' is defined twice");
    }
    link_elements.push_back(l);
    link_names.push_back(name);
  }
  if (link_names.empty()) Fail("robot has no <link>");
  // before any link is read: MuJoCo's compile grows as the square of the bodies in a scene
  if (link_names.size() > static_cast<size_t>(kMaxUrdfLinks)) {
    Fail("robot has " + std::to_string(link_names.size()) + " links, more than the " +
         std::to_string(kMaxUrdfLinks) +
         " partsim loads as one articulation (its compile time and memory grow as the square "
         "of the joints); split it into several robots");
  }

  // joints: names unique, parent and child exist, one parent per link
  std::vector<RawJoint> joints;
  std::set<std::string> joint_names;
  std::vector<int> joint_of_child(link_names.size(), -1);
  std::vector<std::vector<int>> child_joints(link_names.size());
  for (const XMLElement* j = robot->FirstChildElement("joint"); j != nullptr;
       j = j->NextSiblingElement("joint")) {
    RawJoint raw;
    raw.element = j;
    const char* name = j->Attribute("name");
    if (name == nullptr || *name == '\0') {
      Fail("<joint> at line " + std::to_string(j->GetLineNum()) + " has no name");
    }
    raw.name = name;
    const std::string where = "joint '" + raw.name + "'";
    if (!joint_names.insert(raw.name).second) Fail(where + " is defined twice");
    const char* type = j->Attribute("type");
    if (type == nullptr) Fail(where + " has no type");
    raw.type = type;
    static const std::set<std::string> kKnown = {"fixed",     "revolute", "continuous",
                                                 "prismatic", "floating", "planar"};
    if (!kKnown.count(raw.type)) Fail(where + " has unknown type '" + raw.type + "'");
    if (raw.type == "planar") {
      Fail(where + " has type 'planar', which partsim does not support");
    }
    for (const char* role : {"parent", "child"}) {
      const XMLElement* e = j->FirstChildElement(role);
      const char* link = e ? e->Attribute("link") : nullptr;
      if (link == nullptr) Fail(where + " has no <" + role + " link=...>");
      if (!link_index.count(link)) {
        Fail(where + " has " + role + " '" + link + "', which does not exist");
      }
      (std::string(role) == "parent" ? raw.parent : raw.child) = link;
    }
    int child = link_index[raw.child];
    if (raw.parent == raw.child) Fail(where + " joins link '" + raw.child + "' to itself");
    if (joint_of_child[child] >= 0) {
      Fail("link '" + raw.child + "' has two parent joints, '" +
           joints[joint_of_child[child]].name + "' and '" + raw.name + "'");
    }
    joint_of_child[child] = static_cast<int>(joints.size());
    child_joints[link_index[raw.parent]].push_back(static_cast<int>(joints.size()));
    joints.push_back(raw);
  }

  // exactly one root
  std::vector<int> roots;
  for (size_t i = 0; i < link_names.size(); ++i) {
    if (joint_of_child[i] < 0) roots.push_back(static_cast<int>(i));
  }
  if (roots.empty()) Fail("no root link: the joints form a cycle");
  if (roots.size() > 1) {
    std::string list;
    for (size_t k = 0; k < roots.size() && k < 5; ++k) {
      list += (k ? ", '" : "'") + link_names[roots[k]] + "'";
    }
    Fail(std::to_string(roots.size()) + " root links (" + list + (roots.size() > 5 ? ", ..." : "") +
         "); a robot needs exactly one");
  }
  int root = roots[0];

  // links parents-first (breadth-first from the root); a link never reached sits on a cycle
  std::vector<int> order = {root};
  for (size_t k = 0; k < order.size(); ++k) {
    for (int j : child_joints[order[k]]) order.push_back(link_index[joints[j].child]);
  }
  if (order.size() != link_names.size()) {
    std::vector<bool> reached(link_names.size(), false);
    for (int i : order) reached[i] = true;
    for (size_t i = 0; i < link_names.size(); ++i) {
      if (!reached[i]) {
        Fail("link '" + link_names[i] + "' is on a cycle of joints (through joint '" +
             joints[joint_of_child[i]].name + "')");
      }
    }
  }

  // chains no deeper than MuJoCo compiles (it refuses bodies about 1023 below the world)
  {
    std::vector<int> depth(link_names.size(), 0);
    for (int i : order) {
      for (int j : child_joints[i]) {
        const int child = link_index[joints[j].child];
        depth[child] = depth[i] + 1;
        if (depth[child] > kMaxUrdfChainDepth) {
          Fail("link '" + joints[j].child + "' lies " + std::to_string(depth[child]) +
               " joints below the root link, deeper than the " +
               std::to_string(kMaxUrdfChainDepth) + " partsim loads");
        }
      }
    }
  }

  // floating joints may only join a "world" root to the robot
  const bool world_root = link_names[root] == "world" &&
                          link_elements[root]->FirstChildElement("collision") == nullptr &&
                          link_elements[root]->FirstChildElement("visual") == nullptr &&
                          link_elements[root]->FirstChildElement("inertial") == nullptr;
  int world_joint = -1;
  if (world_root && child_joints[root].size() == 1) {
    const RawJoint& wj = joints[child_joints[root][0]];
    if (wj.type == "fixed" || wj.type == "floating") world_joint = child_joints[root][0];
  }
  for (size_t j = 0; j < joints.size(); ++j) {
    if (joints[j].type == "floating" && static_cast<int>(j) != world_joint) {
      Fail("joint '" + joints[j].name +
           "' has type 'floating', which partsim supports only between a root link 'world' "
           "and the robot");
    }
  }

  // the root: a dropped world link turns its joint into the root pose
  desc.fix_root = loader_.fix_root_link;
  std::vector<int> kept = order;
  if (world_joint >= 0) {
    const RawJoint& wj = joints[world_joint];
    desc.fix_root = wj.type == "fixed";
    desc.root_pose = Origin(wj.element, "joint '" + wj.name + "'");
    kept.erase(kept.begin());
  } else if (world_root) {
    desc.fix_root = true;  // a world link moved by joints stays in the world
  }

  // links with their joints
  std::vector<int> desc_index(link_names.size(), -1);
  for (int i : kept) {
    desc_index[i] = static_cast<int>(desc.links.size());
    LinkDesc link = ReadLink(link_elements[i], link_names[i]);
    const int jid = joint_of_child[i];
    if (jid >= 0 && jid != world_joint) {
      link.parent = desc_index[link_index[joints[jid].parent]];
      link.joint = ReadJoint(joints[jid], &desc);
    } else {
      link.parent = -1;
      link.joint = JointDesc();
    }
    desc.links.push_back(std::move(link));
  }

  // every file that is missing or unreadable, in one error
  if (!bad_files_.empty()) {
    std::string list;
    for (const std::string& b : bad_files_) list += "\n  " + b;
    Fail(std::to_string(bad_uris_.size()) + " file" + (bad_uris_.size() > 1 ? "s" : "") +
         " named by the URDF " + (bad_uris_.size() > 1 ? "are" : "is") +
         " missing or unreadable:" + list);
  }

  // couplings name existing, moving joints other than themselves; a prismatic source turns
  // lengths into the scaled unit
  std::map<std::string, JointType> moving;
  for (const LinkDesc& l : desc.links) {
    if (l.parent >= 0) moving[l.joint.name] = l.joint.type;
  }
  for (JointCoupling& c : desc.couplings) {
    const std::string where = "joint '" + c.joint + "' <mimic>";
    auto it = moving.find(c.source);
    if (it == moving.end()) {
      Fail(where + " names joint '" + c.source + "', which does not exist");
    }
    if (c.source == c.joint) Fail(where + " names itself");
    if (it->second == JointType::kFixed) {
      Fail(where + " names joint '" + c.source + "', which is fixed");
    }
    if (it->second == JointType::kPrismatic) c.multiplier /= loader_.scale;
  }

  Validate(desc, "URDF " + source_);
  return desc;
}

}  // namespace

namespace {

// Adds the <disable_collisions> pairs of an SRDF to a parsed URDF. What the loader skips (a pair
// naming a link the URDF lacks, an entry without links) is a warning, an error when strict.
void ApplySrdf(const std::string& path, const std::string& urdf_source, bool strict,
               ArticulationDesc* desc, LoadReport* report) {
  LoadReport srdf_report;
  SrdfDesc srdf = ReadSrdfFile(path, &srdf_report);
  auto warn = [&](const std::string& what) {
    if (strict) throw Error("SRDF " + path + ": " + what + " (strict loading)");
    report->Warn(path, what);
  };
  for (const LoadWarning& w : srdf_report.warnings) warn(w.message);
  std::set<std::string> links;
  for (const LinkDesc& l : desc->links) links.insert(l.name);
  for (const SrdfDisabledCollision& p : srdf.disabled_collisions) {
    std::string missing = !links.count(p.link1) ? p.link1 : !links.count(p.link2) ? p.link2 : "";
    if (links.count(p.link1) && links.count(p.link2))
      desc->disabled_collisions.emplace_back(p.link1, p.link2);
    else
      warn("<disable_collisions> at line " + std::to_string(p.line) + " names link '" + missing +
           "', which URDF " + urdf_source + " lacks; pair ignored");
  }
}

}  // namespace

ArticulationDesc UrdfLoader::Parse(const std::string& text, const std::string& base_dir,
                                   const std::string& source) const {
  last_report_ = LoadReport();
  ArticulationDesc desc = Parser(*this, base_dir, source, &last_report_).Run(text);
  if (!srdf_file.empty()) ApplySrdf(srdf_file, source, strict, &desc, &last_report_);
  return desc;
}

ArticulationDesc UrdfLoader::ParseFile(const std::string& path) const {
  const std::string name = fs::path(path).filename().string();
  const std::string text = internal::ReadWholeFile(path, "URDF");
  std::error_code ec;
  fs::path dir = fs::absolute(fs::path(path), ec).parent_path();
  ArticulationDesc desc = Parse(text, dir.string(), name);
  // without an SRDF named, the one beside the file (same stem) applies
  fs::path beside = fs::path(path).replace_extension(".srdf");
  if (srdf_file.empty() && fs::is_regular_file(beside, ec))
    ApplySrdf(beside.string(), name, strict, &desc, &last_report_);
  return desc;
}

Articulation UrdfLoader::Load(const std::string& path) {
  if (scene_ == nullptr) throw Error("UrdfLoader::Load(" + path + "): the loader has no scene");
  return scene_->AddArticulation(ParseFile(path));
}

Articulation UrdfLoader::LoadFromString(const std::string& text, const std::string& base_dir) {
  if (scene_ == nullptr) throw Error("UrdfLoader::LoadFromString: the loader has no scene");
  return scene_->AddArticulation(Parse(text, base_dir));
}

}  // namespace partsim
