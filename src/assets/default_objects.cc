#include "partsim/assets/default_objects.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/number_text.h"
#include "partsim/core/check.h"
#include "partsim/core/constants.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

/// One primitive of a link: a box (full sizes) or a cylinder along its local z axis (URDF).
struct Part {
  std::string name;
  bool cylinder = false;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();   ///< origin in the link frame (m)
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();   ///< URDF roll, pitch, yaw (rad)
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  ///< box full sizes (m)
  double radius = 0.0;                             ///< cylinder (m)
  double length = 0.0;                             ///< cylinder, along local z (m)
  double density = 0.0;                            ///< kg/m^3
  std::string material;                            ///< "wood", "wood_light" or "metal"
};

/// Mass properties of a link about its centre of mass, in the link frame.
struct MassProps {
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

// numbers in the URDF text read back bit-exact
using internal::Num;
using internal::Vec;

Eigen::Matrix3d RotationFromRpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

MassProps ComputeMassProps(const std::vector<Part>& parts) {
  MassProps out;
  // masses and centres of the parts
  std::vector<double> masses;
  std::vector<Eigen::Matrix3d> inertias;  // about each part's centre, in the link frame
  for (const Part& part : parts) {
    double m = 0.0;
    Eigen::Vector3d diag;
    if (part.cylinder) {
      m = part.density * kPi * part.radius * part.radius * part.length;
      double ixx = m * (3 * part.radius * part.radius + part.length * part.length) / 12.0;
      diag = Eigen::Vector3d(ixx, ixx, m * part.radius * part.radius / 2.0);
    } else {
      const Eigen::Vector3d& s = part.size;
      m = part.density * s.x() * s.y() * s.z();
      diag = Eigen::Vector3d(s.y() * s.y() + s.z() * s.z(), s.x() * s.x() + s.z() * s.z(),
                             s.x() * s.x() + s.y() * s.y()) *
             (m / 12.0);
    }
    Eigen::Matrix3d r = RotationFromRpy(part.rpy);
    masses.push_back(m);
    inertias.push_back(r * diag.asDiagonal() * r.transpose());
    out.mass += m;
    out.com += m * part.xyz;
  }
  out.com /= out.mass;
  // parallel axis theorem about the link's centre of mass
  for (size_t i = 0; i < parts.size(); ++i) {
    Eigen::Vector3d d = parts[i].xyz - out.com;
    out.inertia += inertias[i] +
                   masses[i] * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  return out;
}

std::string MaterialXml(const std::string& name) {
  const char* rgba = "0.8 0.8 0.8 1";
  if (name == "wood") rgba = "0.55 0.38 0.24 1";
  if (name == "wood_light") rgba = "0.72 0.55 0.38 1";
  if (name == "metal") rgba = "0.7 0.72 0.75 1";
  return "<material name=\"" + name + "\"><color rgba=\"" + rgba + "\"/></material>";
}

std::string GeometryXml(const Part& part) {
  if (part.cylinder) {
    return "<geometry><cylinder radius=\"" + Num(part.radius) + "\" length=\"" + Num(part.length) +
           "\"/></geometry>";
  }
  return "<geometry><box size=\"" + Vec(part.size) + "\"/></geometry>";
}

void WriteLink(std::ostringstream& out, const std::string& name, const std::vector<Part>& parts) {
  MassProps mp = ComputeMassProps(parts);
  const Eigen::Matrix3d& i = mp.inertia;
  out << "  <link name=\"" << name << "\">\n";
  out << "    <inertial>\n      <origin xyz=\"" << Vec(mp.com) << "\" rpy=\"0 0 0\"/>\n"
      << "      <mass value=\"" << Num(mp.mass) << "\"/>\n"
      << "      <inertia ixx=\"" << Num(i(0, 0)) << "\" ixy=\"" << Num(i(0, 1)) << "\" ixz=\""
      << Num(i(0, 2)) << "\" iyy=\"" << Num(i(1, 1)) << "\" iyz=\"" << Num(i(1, 2)) << "\" izz=\""
      << Num(i(2, 2)) << "\"/>\n    </inertial>\n";
  for (const Part& part : parts) {
    std::string origin = "<origin xyz=\"" + Vec(part.xyz) + "\" rpy=\"" + Vec(part.rpy) + "\"/>";
    out << "    <visual name=\"" << part.name << "\">" << origin << GeometryXml(part)
        << MaterialXml(part.material) << "</visual>\n";
    out << "    <collision name=\"" << part.name << "\">" << origin << GeometryXml(part)
        << "</collision>\n";
  }
  out << "  </link>\n";
}

void Require(bool ok, const std::string& option, const std::string& rule, double value) {
  if (!ok) {
    throw Error("MakeCabinetUrdf: CabinetOptions." + option + " must be " + rule + " (got " +
                FormatNumber(value) + ")");
  }
}

/// A handle: a bar of length `bar_length` along `bar_axis` (y or z of the link), at distance
/// `offset` in front of the face x = `face_x`, held by two posts along x.
void AddHandle(std::vector<Part>* parts, const std::string& name, double face_x,
               const Eigen::Vector3d& centre_yz, bool vertical, const CabinetOptions& o) {
  double post_radius = 0.7 * o.handle_radius;
  Part bar;
  bar.name = name;
  bar.cylinder = true;
  bar.xyz = Eigen::Vector3d(face_x + o.handle_offset, centre_yz.y(), centre_yz.z());
  // a URDF cylinder lies along z: roll by pi/2 to lay it along y
  bar.rpy = vertical ? Eigen::Vector3d::Zero() : Eigen::Vector3d(kPi / 2, 0, 0);
  bar.radius = o.handle_radius;
  bar.length = o.handle_length + 2 * o.handle_radius + 2 * post_radius;
  bar.density = o.handle_density;
  bar.material = "metal";
  parts->push_back(bar);
  for (int side : {-1, 1}) {
    Part post;
    post.name = name;
    post.cylinder = true;
    Eigen::Vector3d along = vertical ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    post.xyz = Eigen::Vector3d(face_x + o.handle_offset / 2, centre_yz.y(), centre_yz.z()) +
               side * o.handle_length / 2 * along;
    post.rpy = Eigen::Vector3d(0, kPi / 2, 0);  // along x
    post.radius = post_radius;
    post.length = o.handle_offset;
    post.density = o.handle_density;
    post.material = "metal";
    parts->push_back(post);
  }
}

Part Box(const std::string& name, const Eigen::Vector3d& centre, const Eigen::Vector3d& size,
         double density, const std::string& material) {
  Part p;
  p.name = name;
  p.xyz = centre;
  p.size = size;
  p.density = density;
  p.material = material;
  return p;
}

}  // namespace

std::string MakeCabinetUrdf(const CabinetOptions& opts) {
  CabinetOptions o = opts;
  // a seed varies the proportions deterministically (std::uniform_real_distribution is not
  // portable, so the factors come straight from the engine's 32-bit output)
  if (o.seed != 0) {
    std::mt19937 gen(o.seed);
    auto factor = [&gen](double spread) {
      return 1.0 + spread * (2.0 * (static_cast<double>(gen()) / 4294967296.0) - 1.0);
    };
    o.height *= factor(0.15);
    o.width *= factor(0.15);
    double depth_factor = factor(0.15);
    o.depth *= depth_factor;
    o.drawer_travel *= depth_factor;  // a shallower cabinet has a shorter drawer
    o.drawer_fraction *= factor(0.15);
    o.door_hinge_left = (gen() & 1u) != 0;
  }

  // validate
  const double t = o.wall_thickness;
  Require(o.wall_thickness > 0 && o.wall_thickness < 0.1, "wall_thickness", "in (0, 0.1) m", t);
  Require(o.height > 10 * t, "height", "> 10 wall_thickness", o.height);
  Require(o.width > 10 * t, "width", "> 10 wall_thickness", o.width);
  Require(o.depth > 10 * t, "depth", "> 10 wall_thickness", o.depth);
  Require(o.drawer_fraction > 0.1 && o.drawer_fraction < 0.9, "drawer_fraction", "in (0.1, 0.9)",
          o.drawer_fraction);
  Require(o.door_limit > 0 && o.door_limit <= kPi, "door_limit", "in (0, pi] rad", o.door_limit);
  Require(o.handle_radius > 0 && o.handle_radius < 0.05, "handle_radius", "in (0, 0.05) m",
          o.handle_radius);
  Require(o.handle_length > 0 && o.handle_length < o.width - 4 * t, "handle_length",
          "in (0, width - 4 wall_thickness) m", o.handle_length);
  Require(o.handle_offset > 2 * o.handle_radius, "handle_offset", "> 2 handle_radius",
          o.handle_offset);
  Require(o.wood_density > 0, "wood_density", "> 0", o.wood_density);
  Require(o.handle_density > 0, "handle_density", "> 0", o.handle_density);
  Require(o.joint_friction >= 0, "joint_friction", ">= 0", o.joint_friction);
  Require(o.joint_damping >= 0, "joint_damping", ">= 0", o.joint_damping);

  const double h = o.height, w = o.width, d = o.depth, rho = o.wood_density;
  const double gap = 0.003;  // clearance around moving panels (m)

  // vertical layout: drawer compartment on top, door compartment below the divider
  const double inner_h = h - 2 * t;
  const double drawer_h = o.drawer_fraction * (inner_h - t);  // compartment height
  const double divider_z = h - t - drawer_h - t / 2;
  const double drawer_z = divider_z + t / 2 + drawer_h / 2;
  const double door_h = divider_z + t / 2 - 2 * gap;
  const double door_z = gap + door_h / 2;

  // drawer box: open top, fits behind its front panel with clearance
  const double box_w = w - 2 * t - 2 * gap - 0.01;
  const double box_d = d - 2 * t - 0.01;
  const double box_h = drawer_h - 0.02;
  const double box_z = -drawer_h / 2 + 0.005 + box_h / 2;
  Require(o.drawer_travel > 0 && o.drawer_travel <= box_d, "drawer_travel",
          "in (0, " + FormatNumber(box_d) + "] m (the drawer's depth)", o.drawer_travel);

  // body: back, sides, top, bottom and the shelf divider
  std::vector<Part> body;
  body.push_back(
      Box("back-body", {-d / 2 + t / 2, 0, h / 2}, {t, w - 2 * t, h - 2 * t}, rho, "wood"));
  body.push_back(Box("side_left-body", {0, w / 2 - t / 2, h / 2}, {d, t, h}, rho, "wood"));
  body.push_back(Box("side_right-body", {0, -w / 2 + t / 2, h / 2}, {d, t, h}, rho, "wood"));
  body.push_back(Box("top-body", {0, 0, h - t / 2}, {d, w - 2 * t, t}, rho, "wood"));
  body.push_back(Box("bottom-body", {0, 0, t / 2}, {d, w - 2 * t, t}, rho, "wood"));
  body.push_back(Box("divider-body", {t / 2, 0, divider_z}, {d - t, w - 2 * t, t}, rho, "wood"));

  // drawer, in the joint frame at the centre of its closed front face
  std::vector<Part> drawer;
  drawer.push_back(Box("front-drawer_0", {-t / 2, 0, 0},
                       {t, w - 2 * t - 2 * gap, drawer_h - 2 * gap}, rho, "wood_light"));
  const double box_x = -t - box_d / 2;
  drawer.push_back(Box("bottom-drawer_0", {box_x, 0, -drawer_h / 2 + 0.005 + t / 2},
                       {box_d, box_w, t}, rho, "wood_light"));
  drawer.push_back(Box("side_left-drawer_0", {box_x, box_w / 2 - t / 2, box_z}, {box_d, t, box_h},
                       rho, "wood_light"));
  drawer.push_back(Box("side_right-drawer_0", {box_x, -box_w / 2 + t / 2, box_z}, {box_d, t, box_h},
                       rho, "wood_light"));
  drawer.push_back(Box("back-drawer_0", {-t - box_d + t / 2, 0, box_z}, {t, box_w - 2 * t, box_h},
                       rho, "wood_light"));
  AddHandle(&drawer, "handle-drawer_0", 0.0, Eigen::Vector3d::Zero(), false, o);

  // door, in the joint frame on the hinge line; it extends away from the hinge side
  const double s = o.door_hinge_left ? 1.0 : -1.0;
  const double door_w = w - 2 * gap;
  std::vector<Part> door;
  door.push_back(
      Box("panel-door_0", {t / 2, -s * (gap + door_w / 2), 0}, {t, door_w, door_h}, rho, "wood"));
  const double handle_y = -s * (gap + door_w - 0.05);
  const double handle_z = std::max(0.0, door_h / 2 - o.handle_length / 2 - 0.08);
  AddHandle(&door, "handle-door_0", t, Eigen::Vector3d(0, handle_y, handle_z), true, o);

  // the URDF text
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n";
  out << "<!-- generated by partsim::MakeCabinetUrdf: " << Num(h) << " x " << Num(w) << " x "
      << Num(d) << " m, seed " << o.seed << " -->\n";
  out << "<robot name=\"" << o.name << "\">\n";
  WriteLink(out, "body", body);
  WriteLink(out, "drawer_0", drawer);
  WriteLink(out, "door_0", door);
  // the drawer slides out along +x
  out << "  <joint name=\"drawer_0_joint\" type=\"prismatic\">\n"
      << "    <parent link=\"body\"/>\n    <child link=\"drawer_0\"/>\n"
      << "    <origin xyz=\"" << Vec({d / 2, 0, drawer_z}) << "\" rpy=\"0 0 0\"/>\n"
      << "    <axis xyz=\"1 0 0\"/>\n"
      << "    <limit lower=\"0\" upper=\"" << Num(o.drawer_travel)
      << "\" effort=\"100\" velocity=\"1\"/>\n"
      << "    <dynamics damping=\"" << Num(o.joint_damping) << "\" friction=\""
      << Num(o.joint_friction) << "\"/>\n  </joint>\n";
  // the door turns outwards about a vertical axis on the front edge of the hinge side
  out << "  <joint name=\"door_0_joint\" type=\"revolute\">\n"
      << "    <parent link=\"body\"/>\n    <child link=\"door_0\"/>\n"
      << "    <origin xyz=\"" << Vec({d / 2, s * w / 2, door_z}) << "\" rpy=\"0 0 0\"/>\n"
      << "    <axis xyz=\"0 0 " << Num(s) << "\"/>\n"
      << "    <limit lower=\"0\" upper=\"" << Num(o.door_limit)
      << "\" effort=\"100\" velocity=\"2\"/>\n"
      << "    <dynamics damping=\"" << Num(o.joint_damping) << "\" friction=\""
      << Num(o.joint_friction) << "\"/>\n  </joint>\n";
  out << "</robot>\n";
  return out.str();
}

}  // namespace partsim
