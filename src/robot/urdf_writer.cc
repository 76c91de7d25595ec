// ArticulationDesc -> URDF text. Link frames stay those of the description except where a
// revolute joint's axis misses the child's origin (URDF puts every joint at its child's origin):
// there the URDF link frame moves to the joint frame's origin and the link's shapes move with
// it. Numbers are written with 17 significant digits, so a round trip is exact to rounding.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/number_text.h"
#include "partsim/core/error.h"
#include "partsim/robot/robots.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using internal::Num;
using internal::Vec;

// XML attribute text with the five special characters escaped.
std::string Escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// <origin> of a pose: fixed-axis roll, pitch, yaw with R = Rz(yaw) Ry(pitch) Rx(roll).
std::string Origin(const Pose& pose) {
  const Eigen::Matrix3d r = pose.q.normalized().toRotationMatrix();
  double roll, pitch, yaw;
  const double c = std::hypot(r(0, 0), r(1, 0));
  pitch = std::atan2(-r(2, 0), c);
  if (c > 1e-9) {
    yaw = std::atan2(r(1, 0), r(0, 0));
    roll = std::atan2(r(2, 1), r(2, 2));
  } else {
    // gimbal lock: only yaw - roll (or yaw + roll) is defined; put it all in yaw
    roll = 0;
    yaw = std::atan2(-r(0, 1), r(1, 1));
  }
  return "<origin xyz=\"" + Vec(pose.p) + "\" rpy=\"" + Num(roll) + " " + Num(pitch) + " " +
         Num(yaw) + "\"/>";
}

// URDF cylinders and capsules run along z, partsim's along x.
Pose ZAlongX() {
  return Pose(Eigen::Vector3d::Zero(),
              Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY())));
}

// Writes a mesh as a Wavefront OBJ file; throws naming the file.
void WriteObj(const MeshData& mesh, const fs::path& path) {
  std::ofstream out(path);
  if (!out) throw Error("WriteUrdf: cannot write mesh file " + path.string());
  out.precision(9);
  for (const Eigen::Vector3f& v : mesh.vertices)
    out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const Eigen::Vector3i& f : mesh.faces)
    out << "f " << f.x() + 1 << " " << f.y() + 1 << " " << f.z() + 1 << "\n";
  if (!out) throw Error("WriteUrdf: cannot write mesh file " + path.string());
}

class Writer {
 public:
  // `mesh_dir`: folder the OBJ files go to; `mesh_ref`: how the URDF names that folder
  Writer(const ArticulationDesc& art, std::string mesh_dir, std::string mesh_ref)
      : art_(art), mesh_dir_(std::move(mesh_dir)), mesh_ref_(std::move(mesh_ref)) {}

  std::string Run() {
    Validate(art_, "ArticulationToUrdf");
    const int n = static_cast<int>(art_.links.size());
    // URDF frame of each link in its description frame
    offset_.assign(n, Eigen::Vector3d::Zero());
    for (int i = 0; i < n; ++i) {
      const LinkDesc& l = art_.links[i];
      if (l.parent < 0) continue;
      const JointType t = l.joint.type;
      if (t == JointType::kScrew) {
        Fail("joint '" + l.joint.name + "' is a screw joint, which URDF cannot express");
      }
      if (t == JointType::kRevolute || t == JointType::kContinuous)
        offset_[i] = l.joint.pose_in_child.p;
    }

    out_ << "<?xml version=\"1.0\"?>\n";
    out_ << "<robot name=\"" << Escape(art_.name)
         << "\" xmlns:partsim=\"https://partsim.dev/urdf\">\n";
    // a world link carries the root pose and a free root
    const bool world =
        !art_.fix_root || !art_.root_pose.p.isZero(0) ||
        !art_.root_pose.q.coeffs().isApprox(Eigen::Quaterniond::Identity().coeffs(), 0);
    int root = 0;
    for (int i = 0; i < n; ++i)
      if (art_.links[i].parent < 0) root = i;
    if (world) {
      for (const LinkDesc& l : art_.links)
        if (l.name == "world")
          Fail("a link named 'world' cannot be written with a root pose or a free root");
      out_ << "  <link name=\"world\"/>\n";
      out_ << "  <joint name=\"world_joint\" type=\"" << (art_.fix_root ? "fixed" : "floating")
           << "\">\n";
      out_ << "    " << Origin(art_.root_pose) << "\n";
      out_ << "    <parent link=\"world\"/>\n    <child link=\"" << Escape(art_.links[root].name)
           << "\"/>\n  </joint>\n";
    }
    for (int i = 0; i < n; ++i) WriteLink(i);
    for (int i = 0; i < n; ++i)
      if (art_.links[i].parent >= 0) WriteJoint(i);
    out_ << "</robot>\n";
    return out_.str();
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw Error("ArticulationToUrdf '" + art_.name + "': " + what);
  }

  // X_UC: the description frame C of link i in its URDF frame U
  Pose UFromC(int i) const { return Pose(-offset_[i], Eigen::Quaterniond::Identity()); }

  template <typename Shape>
  void WriteGeometry(const Shape& s, const std::string& link, const std::string& file_stem,
                     const Pose& X_UC) {
    Pose pose = X_UC * s.pose;
    std::string geometry;
    switch (s.type) {
      case ShapeType::kBox:
        geometry = "<box size=\"" + Vec(2 * s.half_size) + "\"/>";
        break;
      case ShapeType::kSphere:
        geometry = "<sphere radius=\"" + Num(s.radius) + "\"/>";
        break;
      case ShapeType::kCapsule:
      case ShapeType::kCylinder:
        pose = pose * ZAlongX();
        geometry = std::string("<") + (s.type == ShapeType::kCapsule ? "capsule" : "cylinder") +
                   " radius=\"" + Num(s.radius) + "\" length=\"" + Num(2 * s.half_length) + "\"/>";
        break;
      case ShapeType::kConvexMesh: {
        if (!s.mesh) Fail("link '" + link + "' has a mesh shape without a mesh");
        if (mesh_dir_.empty()) {
          Fail("link '" + link + "' has a mesh; give a mesh folder to write it to");
        }
        std::error_code ec;
        fs::create_directories(mesh_dir_, ec);
        const std::string file = file_stem + ".obj";
        WriteObj(*s.mesh, fs::path(mesh_dir_) / file);
        geometry = "<mesh filename=\"" + Escape((fs::path(mesh_ref_) / file).string()) + "\"/>";
        break;
      }
      case ShapeType::kPlane:
        Fail("link '" + link + "' has a plane, which URDF cannot express");
    }
    out_ << "      " << Origin(pose) << "\n      <geometry>" << geometry << "</geometry>\n";
  }

  void WriteLink(int i) {
    const LinkDesc& l = art_.links[i];
    const Pose X_UC = UFromC(i);
    out_ << "  <link name=\"" << Escape(l.name) << "\">\n";
    if (l.inertial) {
      const Inertial& in = *l.inertial;
      out_ << "    <inertial>\n      " << Origin(X_UC * in.cmass_local_pose) << "\n";
      out_ << "      <mass value=\"" << Num(in.mass) << "\"/>\n";
      out_ << "      <inertia ixx=\"" << Num(in.inertia.x()) << "\" ixy=\"0\" ixz=\"0\" iyy=\""
           << Num(in.inertia.y()) << "\" iyz=\"0\" izz=\"" << Num(in.inertia.z()) << "\"/>\n";
      out_ << "    </inertial>\n";
    }
    const std::string stem = SafeName(art_.name + "_" + l.name);
    for (size_t k = 0; k < l.visuals.size(); ++k) {
      const VisualShape& v = l.visuals[k];
      out_ << "    <visual" << (v.name.empty() ? "" : " name=\"" + Escape(v.name) + "\"") << ">\n";
      WriteGeometry(v, l.name, stem + "_visual" + std::to_string(k), X_UC);
      const Eigen::Vector4f& c = v.material.base_color;
      out_ << "      <material name=\"" << Escape(l.name) << "_visual" << k << "\"><color rgba=\""
           << Num(c[0]) << " " << Num(c[1]) << " " << Num(c[2]) << " " << Num(c[3]) << "\"/>";
      if (!v.material.diffuse_texture.empty())
        out_ << "<texture filename=\"" << Escape(v.material.diffuse_texture) << "\"/>";
      out_ << "</material>\n    </visual>\n";
    }
    for (size_t k = 0; k < l.collisions.size(); ++k) {
      const CollisionShape& c = l.collisions[k];
      out_ << "    <collision" << (c.name.empty() ? "" : " name=\"" + Escape(c.name) + "\"")
           << ">\n";
      WriteGeometry(c, l.name, stem + "_collision" + std::to_string(k), X_UC);
      // density and contact material, which URDF lacks
      out_ << "      <partsim:collision density=\"" << Num(c.density) << "\"";
      if (c.material) {
        out_ << " static_friction=\"" << Num(c.material->static_friction)
             << "\" dynamic_friction=\"" << Num(c.material->dynamic_friction) << "\" restitution=\""
             << Num(c.material->restitution) << "\"";
      }
      out_ << "/>\n    </collision>\n";
    }
    out_ << "  </link>\n";
  }

  void WriteJoint(int i) {
    const LinkDesc& l = art_.links[i];
    const JointDesc& j = l.joint;
    const bool limited = std::isfinite(j.lower) && std::isfinite(j.upper);
    std::string type;
    switch (j.type) {
      case JointType::kFixed:
        type = "fixed";
        break;
      case JointType::kRevolute:
        type = limited ? "revolute" : "continuous";
        break;
      case JointType::kContinuous:
        type = "continuous";
        break;
      case JointType::kPrismatic:
        type = "prismatic";
        break;
      case JointType::kScrew:
        Fail("joint '" + j.name + "' is a screw joint");
    }
    // X_{U_parent U_child} at q = 0 and the axis in the child's URDF frame
    const Pose origin =
        UFromC(l.parent) * j.pose_in_parent * j.pose_in_child.Inverse() * UFromC(i).Inverse();
    out_ << "  <joint name=\"" << Escape(j.name) << "\" type=\"" << type << "\">\n";
    out_ << "    " << Origin(origin) << "\n";
    out_ << "    <parent link=\"" << Escape(art_.links[l.parent].name) << "\"/>\n";
    out_ << "    <child link=\"" << Escape(l.name) << "\"/>\n";
    if (j.type == JointType::kFixed) {
      out_ << "  </joint>\n";
      return;
    }
    out_ << "    <axis xyz=\"" << Vec(j.pose_in_child.q * Eigen::Vector3d::UnitX()) << "\"/>\n";
    // URDF requires limits on prismatic joints: an unlimited slide gets +-1e30
    const double effort = std::isfinite(j.effort_limit)        ? j.effort_limit
                          : std::isfinite(j.drive.force_limit) ? j.drive.force_limit
                                                               : 0.0;
    out_ << "    <limit";
    if (type != "continuous") {
      out_ << " lower=\"" << Num(std::isfinite(j.lower) ? j.lower : -1e30) << "\" upper=\""
           << Num(std::isfinite(j.upper) ? j.upper : 1e30) << "\"";
    }
    // the description holds no velocity limit: 0 stands for "not given"
    out_ << " effort=\"" << Num(effort) << "\" velocity=\"0\"/>\n";
    out_ << "    <dynamics damping=\"" << Num(j.damping) << "\" friction=\"" << Num(j.friction)
         << "\"/>\n";
    for (const JointCoupling& c : art_.couplings) {
      if (c.joint != j.name) continue;
      out_ << "    <mimic joint=\"" << Escape(c.source) << "\" multiplier=\"" << Num(c.multiplier)
           << "\" offset=\"" << Num(c.offset) << "\"/>\n";
    }
    const DriveDesc& d = j.drive;
    out_ << "    <partsim:drive stiffness=\"" << Num(d.stiffness) << "\" damping=\""
         << Num(d.damping) << "\"";
    if (std::isfinite(d.force_limit)) out_ << " force_limit=\"" << Num(d.force_limit) << "\"";
    out_ << " target=\"" << Num(d.target) << "\" velocity_target=\"" << Num(d.velocity_target)
         << "\" armature=\"" << Num(j.armature) << "\"/>\n";
    out_ << "  </joint>\n";
  }

  // a file name made of letters, digits, '_', '-' and '.'
  static std::string SafeName(const std::string& s) {
    std::string out;
    for (char c : s)
      out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.') ? c : '_';
    return out;
  }

  const ArticulationDesc& art_;
  std::string mesh_dir_, mesh_ref_;
  std::vector<Eigen::Vector3d> offset_;
  std::ostringstream out_;
};

}  // namespace

std::string ArticulationToUrdf(const ArticulationDesc& articulation, const std::string& mesh_dir) {
  std::error_code ec;
  const std::string ref = mesh_dir.empty() ? "" : fs::absolute(mesh_dir, ec).string();
  return Writer(articulation, mesh_dir, ref).Run();
}

void WriteUrdf(const ArticulationDesc& articulation, const std::string& path) {
  // meshes go to <stem>_meshes/ beside the file, named relative to it
  const fs::path file(path);
  const std::string folder = file.stem().string() + "_meshes";
  const fs::path parent = file.parent_path();
  const std::string text = Writer(articulation, (parent / folder).string(), folder).Run();
  std::ofstream out(path, std::ios::binary);
  if (!out) throw Error("WriteUrdf: cannot write " + path);
  out << text;
  out.close();
  if (!out) throw Error("WriteUrdf: cannot write " + path);
}

}  // namespace partsim
