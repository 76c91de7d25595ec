#include "partsim/robot/robots.h"

#include <cmath>

#include "partsim/core/error.h"

namespace partsim {
namespace {

using Eigen::AngleAxisd;
using Eigen::Quaterniond;
using Eigen::Vector3d;

// Rotations that take partsim's joint axis (x of the joint frame) onto y and z.
Quaterniond XToY() { return Quaterniond(AngleAxisd(M_PI / 2, Vector3d::UnitZ())); }
Quaterniond XToMinusY() { return Quaterniond(AngleAxisd(-M_PI / 2, Vector3d::UnitZ())); }
Quaterniond XToZ() { return Quaterniond(AngleAxisd(-M_PI / 2, Vector3d::UnitY())); }

// Inertia of a solid box with half sizes h (principal moments, kg m^2).
Vector3d BoxInertia(double mass, const Vector3d& h) {
  const Vector3d s = 2 * h;
  return mass / 12.0 *
         Vector3d(s.y() * s.y() + s.z() * s.z(), s.x() * s.x() + s.z() * s.z(),
                  s.x() * s.x() + s.y() * s.y());
}

// Inertia of a solid cylinder of radius r and half length l along x.
Vector3d CylinderInertia(double mass, double r, double l) {
  const double axial = 0.5 * mass * r * r;
  const double across = mass * (3 * r * r + 4 * l * l) / 12.0;
  return Vector3d(axial, across, across);
}

Inertial MakeInertial(double mass, const Vector3d& com, const Vector3d& inertia,
                      const Quaterniond& axes = Quaterniond::Identity()) {
  Inertial in;
  in.mass = mass;
  in.cmass_local_pose = Pose(com, axes);
  in.inertia = inertia;
  return in;
}

CollisionShape Box(const Pose& pose, const Vector3d& half_size,
                   const std::optional<PhysicalMaterial>& material = {}) {
  CollisionShape s;
  s.type = ShapeType::kBox;
  s.pose = pose;
  s.half_size = half_size;
  s.material = material;
  return s;
}

// A capsule along local x from point a to point b (in the link frame), radius r.
CollisionShape CapsuleBetween(const Vector3d& a, const Vector3d& b, double r) {
  CollisionShape s;
  s.type = ShapeType::kCapsule;
  s.radius = r;
  s.half_length = 0.5 * (b - a).norm();
  Quaterniond q = Quaterniond::FromTwoVectors(Vector3d::UnitX(), (b - a).normalized());
  if ((b - a).normalized().x() < -1 + 1e-12) q = Quaterniond(AngleAxisd(M_PI, Vector3d::UnitZ()));
  s.pose = Pose(0.5 * (a + b), q.normalized());
  return s;
}

VisualShape VisualOf(const CollisionShape& c, const Eigen::Vector4f& color) {
  VisualShape v;
  v.type = c.type;
  v.pose = c.pose;
  v.half_size = c.half_size;
  v.radius = c.radius;
  v.half_length = c.half_length;
  v.material.base_color = color;
  v.name = c.name;
  return v;
}

// Adds each collision shape of a link as a visual of the same geometry.
void AddVisuals(LinkDesc* link, const Eigen::Vector4f& color) {
  for (const CollisionShape& c : link->collisions) link->visuals.push_back(VisualOf(c, color));
}

DriveDesc Drive(double stiffness, double damping, double force_limit) {
  DriveDesc d;
  d.stiffness = stiffness;
  d.damping = damping;
  d.force_limit = force_limit;
  return d;
}

// A link attached to `parent` by a joint whose axis frame is `axis_rot` in both links (the two
// link frames coincide at q = 0, offset by `offset` in the parent).
LinkDesc ChildLink(const std::string& name, int parent, const std::string& joint, JointType type,
                   const Vector3d& offset, const Quaterniond& axis_rot) {
  LinkDesc l;
  l.name = name;
  l.parent = parent;
  l.joint.name = joint;
  l.joint.type = type;
  l.joint.pose_in_parent = Pose(offset, axis_rot);
  l.joint.pose_in_child = Pose(Vector3d::Zero(), axis_rot);
  return l;
}

}  // namespace

RobotModel BuildFlyingGripper(const FlyingGripperOptions& options) {
  const FlyingGripperOptions& o = options;
  if (!(o.workspace > 0) || !(o.finger_travel > 0) || !(o.finger_length > 0.03) ||
      !(o.finger_force > 0) || !(o.arm_force > 0) || !(o.arm_torque > 0)) {
    throw Error("BuildFlyingGripper '" + o.name +
                "': workspace, finger_travel, finger_force, arm_force and arm_torque must be "
                "> 0 and finger_length > 0.03 m");
  }
  RobotModel robot;
  ArticulationDesc& art = robot.articulation;
  art.name = o.name;
  art.fix_root = true;

  // root: a frame with a tiny mass, no shapes
  LinkDesc root;
  root.name = "root";
  root.inertial = MakeInertial(1e-3, Vector3d::Zero(), Vector3d::Constant(1e-6));
  art.links.push_back(root);

  // virtual links between the six arm joints: small masses, no shapes, all frames at the TCP
  struct ArmJoint {
    const char* joint;
    const char* link;
    JointType type;
    Quaterniond axis;
  };
  const ArmJoint arm[6] = {
      {"x", "x_link", JointType::kPrismatic, Quaterniond::Identity()},
      {"y", "y_link", JointType::kPrismatic, XToY()},
      {"z", "z_link", JointType::kPrismatic, XToZ()},
      {"yaw", "yaw_link", JointType::kRevolute, XToZ()},
      {"pitch", "pitch_link", JointType::kRevolute, XToY()},
      {"roll", "hand", JointType::kRevolute, Quaterniond::Identity()},
  };
  // drives: a ~1 kg hand on the slides, ~0.01 kg m^2 (plus armature) on the rotations, near
  // critical damping; the implicit integrator takes the damping
  const double slide_k = 5000, slide_d = 200, slide_armature = 0.05;
  const double rot_k = 300, rot_d = 8, rot_armature = 0.01;
  for (int i = 0; i < 6; ++i) {
    const ArmJoint& a = arm[i];
    LinkDesc l = ChildLink(a.link, i, a.joint, a.type, Vector3d::Zero(), a.axis);
    const bool slide = a.type == JointType::kPrismatic;
    if (slide) {
      l.joint.lower = -o.workspace;
      l.joint.upper = o.workspace;
      l.joint.armature = slide_armature;
      l.joint.drive = Drive(slide_k, slide_d, o.arm_force);
    } else {
      // pitch = +-pi/2 is the gimbal lock of the yaw-pitch-roll chain
      const double range = std::string(a.joint) == "pitch" ? M_PI : 2 * M_PI;
      l.joint.lower = -range;
      l.joint.upper = range;
      l.joint.armature = rot_armature;
      l.joint.drive = Drive(rot_k, rot_d, o.arm_torque);
    }
    if (i < 5) l.inertial = MakeInertial(0.05, Vector3d::Zero(), Vector3d::Constant(1e-5));
    art.links.push_back(l);
  }
  const int hand = 6;

  // the hand: the TCP (hand frame origin) lies between the fingertip pads' centres; the palm
  // sits behind the fingers along -z, the fingers open along +-y
  const double pad_half_len = 0.015;       // pad extent along z, each side of the TCP
  const double pad_half_thick = 0.003;     // pad extent along y
  const double finger_half_thick = 0.005;  // finger body along y
  const double finger_half_width = 0.01;   // finger and pad along x
  const double palm_z = -(o.finger_length - pad_half_len);  // palm face
  const Vector3d palm_half(0.03, o.finger_travel + 2 * (pad_half_thick + finger_half_thick) + 0.01,
                           0.02);
  const Eigen::Vector4f grey(0.3f, 0.3f, 0.32f, 1.0f), pad_color(0.1f, 0.1f, 0.1f, 1.0f);
  {
    LinkDesc& h = art.links[hand];
    h.collisions.push_back(Box(Pose(Vector3d(0, 0, palm_z - palm_half.z())), palm_half));
    AddVisuals(&h, grey);
    const double mass = 0.8;
    h.inertial =
        MakeInertial(mass, Vector3d(0, 0, palm_z - palm_half.z()), BoxInertia(mass, palm_half));
  }
  robot.ee_link = "hand";
  robot.tcp_in_ee = Pose();

  // fingers: joint frames at the hand origin, axis +y (left) and -y (right); at q = 0 the
  // pads' inner faces touch at y = 0
  PhysicalMaterial pad_material;
  pad_material.static_friction = 1.8;
  pad_material.dynamic_friction = 1.5;
  const double finger_k = 5000, finger_d = 70, finger_mass = 0.05, finger_armature = 0.2;
  for (int side = 0; side < 2; ++side) {
    const bool left = side == 0;
    LinkDesc f = ChildLink(left ? "left_finger" : "right_finger", hand,
                           left ? "left_finger_joint" : "right_finger_joint", JointType::kPrismatic,
                           Vector3d::Zero(), left ? XToY() : XToMinusY());
    const double s = left ? 1.0 : -1.0;
    // finger body from the palm face to the tip, pad on its inner face at the tip
    const double body_len = o.finger_length;  // palm face to tip
    const double body_centre_z = palm_z + body_len / 2;
    f.collisions.push_back(
        Box(Pose(Vector3d(0, s * (2 * pad_half_thick + finger_half_thick), body_centre_z)),
            Vector3d(finger_half_width, finger_half_thick, body_len / 2)));
    f.collisions.push_back(Box(Pose(Vector3d(0, s * pad_half_thick, 0)),
                               Vector3d(finger_half_width, pad_half_thick, pad_half_len),
                               pad_material));
    f.collisions.back().name = "pad";
    f.visuals.push_back(VisualOf(f.collisions[0], grey));
    f.visuals.push_back(VisualOf(f.collisions[1], pad_color));
    f.inertial = MakeInertial(
        finger_mass, Vector3d(0, s * (2 * pad_half_thick + finger_half_thick), body_centre_z),
        BoxInertia(finger_mass, Vector3d(finger_half_width, finger_half_thick, body_len / 2)));
    f.joint.lower = 0;
    f.joint.upper = o.finger_travel;
    f.joint.drive = Drive(finger_k, finger_d, o.finger_force);
    f.joint.armature = finger_armature;
    art.links.push_back(f);
  }

  robot.arm_joints = {"x", "y", "z", "yaw", "pitch", "roll"};
  robot.gripper_joints = {"left_finger_joint", "right_finger_joint"};
  robot.gripper_open = o.finger_travel;
  robot.gripper_closed = 0.0;
  robot.arm_velocity_limits = {1.0, 1.0, 1.0, M_PI, M_PI, M_PI};
  robot.arm_effort_limits = {o.arm_force,  o.arm_force,  o.arm_force,
                             o.arm_torque, o.arm_torque, o.arm_torque};
  robot.home = std::vector<double>(6, 0.0);
  Validate(art, "BuildFlyingGripper");
  return robot;
}

RobotModel BuildPanda(const std::string& name) {
  RobotModel robot;
  ArticulationDesc& art = robot.articulation;
  art.name = name;
  art.fix_root = true;

  // modified DH parameters (Craig): link i hangs from link i-1 by
  // RotX(alpha[i-1]) TransX(a[i-1]) RotZ(q_i) TransZ(d[i-1])
  const double a[7] = {0, 0, 0, 0.0825, -0.0825, 0, 0.088};
  const double d[7] = {0.333, 0, 0.316, 0, 0.384, 0, 0};
  const double alpha[7] = {0, -M_PI / 2, M_PI / 2, M_PI / 2, -M_PI / 2, M_PI / 2, M_PI / 2};
  const double lower[7] = {-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973};
  const double upper[7] = {2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973};
  const double velocity[7] = {2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61};
  const double torque[7] = {87, 87, 87, 87, 12, 12, 12};
  const double mass[8] = {4.0, 4.0, 4.0, 4.0, 3.0, 3.0, 1.5, 0.5};  // link0..link7
  // position-control drives (N m/rad, N m s/rad) and rotor inertia (kg m^2)
  const double stiffness[7] = {1500, 1500, 1500, 1500, 600, 600, 300};
  const double damping[7] = {150, 150, 150, 150, 60, 60, 30};
  const double armature[7] = {0.1, 0.1, 0.1, 0.1, 0.05, 0.05, 0.05};

  // capsules in each link frame (z = the link's joint axis), sized so that links that are not
  // neighbours stay apart at home (nor do link0, welded to the world, and link1 touch: MuJoCo
  // filters no contacts with the world's bodies); the first capsule carries the link's mass
  struct Segment {
    Vector3d from, to;
    double radius;
  };
  const std::vector<std::vector<Segment>> shapes = {
      {{{0, 0, 0.05}, {0, 0, 0.12}, 0.06}},                                         // link0 (base)
      {{{0, 0, -0.09}, {0, 0, -0.05}, 0.06}},                                       // link1
      {{{0, 0, -0.06}, {0, 0, 0.06}, 0.06}, {{0, -0.07, 0}, {0, -0.13, 0}, 0.05}},  // link2
      {{{0, 0, -0.17}, {0, 0, -0.04}, 0.05}},                                       // link3
      {{{0, 0, -0.04}, {0, 0, 0.04}, 0.055}, {{0, 0, 0}, {-0.0825, 0.17, 0}, 0.05}},  // link4
      {{{0, 0, -0.22}, {0, 0, -0.13}, 0.045}},                                        // link5
      {{{0, 0, -0.04}, {0, 0, 0.04}, 0.05}, {{0.02, 0, 0}, {0.088, 0, 0}, 0.04}},     // link6
      {{{0, 0, 0.0}, {0, 0, 0.06}, 0.04}},                                            // link7
  };
  const Eigen::Vector4f white(0.95f, 0.95f, 0.95f, 1.0f), dark(0.2f, 0.2f, 0.2f, 1.0f);
  for (int i = 0; i <= 7; ++i) {
    LinkDesc l;
    l.name = "panda_link" + std::to_string(i);
    for (const Segment& s : shapes[i])
      l.collisions.push_back(CapsuleBetween(s.from, s.to, s.radius));
    AddVisuals(&l, i % 2 ? white : dark);
    const CollisionShape& main = l.collisions[0];
    l.inertial = MakeInertial(mass[i], main.pose.p,
                              CylinderInertia(mass[i], main.radius, main.half_length + main.radius),
                              main.pose.q);
    if (i > 0) {
      const int k = i - 1;
      const Pose dh(Vector3d(a[k], -std::sin(alpha[k]) * d[k], std::cos(alpha[k]) * d[k]),
                    Quaterniond(AngleAxisd(alpha[k], Vector3d::UnitX())));
      l.parent = i - 1;
      l.joint.name = "panda_joint" + std::to_string(i);
      l.joint.type = JointType::kRevolute;
      // the DH z axis is partsim's joint axis x
      l.joint.pose_in_parent = dh * Pose(Vector3d::Zero(), XToZ());
      l.joint.pose_in_child = Pose(Vector3d::Zero(), XToZ());
      l.joint.lower = lower[k];
      l.joint.upper = upper[k];
      l.joint.armature = armature[k];
      l.joint.drive = Drive(stiffness[k], damping[k], torque[k]);
    }
    art.links.push_back(l);
  }

  // hand: 0.107 m along the flange z, turned -pi/4 about it; TCP 0.1034 m further along z
  LinkDesc hand;
  hand.name = "panda_hand";
  hand.parent = 7;
  hand.joint.name = "panda_hand_joint";
  hand.joint.type = JointType::kFixed;
  hand.joint.pose_in_parent =
      Pose(Vector3d(0, 0, 0.107), Quaterniond(AngleAxisd(-M_PI / 4, Vector3d::UnitZ())));
  const Vector3d hand_half(0.02, 0.1, 0.029);
  hand.collisions.push_back(Box(Pose(Vector3d(0, 0, 0.029)), hand_half));
  AddVisuals(&hand, white);
  hand.inertial = MakeInertial(0.7, Vector3d(0, 0, 0.029), BoxInertia(0.7, hand_half));
  art.links.push_back(hand);
  const int hand_index = 8;

  // fingers slide along +-y of the hand from z = 0.0584; 0 = closed (pads touch), 0.04 open.
  // Both fingers carry their own drive (no mimic coupling), so a grasp centres itself.
  PhysicalMaterial pad_material;
  pad_material.static_friction = 1.5;
  pad_material.dynamic_friction = 1.2;
  for (int side = 0; side < 2; ++side) {
    const bool left = side == 0;
    const double s = left ? 1.0 : -1.0;
    LinkDesc f =
        ChildLink(left ? "panda_leftfinger" : "panda_rightfinger", hand_index,
                  left ? "panda_finger_joint1" : "panda_finger_joint2", JointType::kPrismatic,
                  Vector3d(0, 0, 0.0584), left ? XToY() : XToMinusY());
    f.collisions.push_back(Box(Pose(Vector3d(0, s * 0.013, 0.027)), Vector3d(0.01, 0.009, 0.027)));
    f.collisions.push_back(
        Box(Pose(Vector3d(0, s * 0.004, 0.045)), Vector3d(0.01, 0.004, 0.01), pad_material));
    f.collisions.back().name = "pad";
    f.visuals.push_back(VisualOf(f.collisions[0], white));
    f.visuals.push_back(VisualOf(f.collisions[1], dark));
    f.inertial = MakeInertial(0.015, Vector3d(0, s * 0.01, 0.03), Vector3d::Constant(2e-6));
    f.joint.lower = 0;
    f.joint.upper = 0.04;
    f.joint.drive = Drive(1000, 20, 35);
    art.links.push_back(f);
  }

  robot.arm_joints.clear();
  for (int i = 1; i <= 7; ++i) robot.arm_joints.push_back("panda_joint" + std::to_string(i));
  robot.gripper_joints = {"panda_finger_joint1", "panda_finger_joint2"};
  robot.ee_link = "panda_hand";
  robot.tcp_in_ee = Pose(Vector3d(0, 0, 0.1034));
  robot.gripper_open = 0.04;
  robot.gripper_closed = 0.0;
  robot.arm_velocity_limits.assign(velocity, velocity + 7);
  robot.arm_effort_limits.assign(torque, torque + 7);
  robot.home = {0, -M_PI / 4, 0, -3 * M_PI / 4, 0, M_PI / 2, M_PI / 4};
  Validate(art, "BuildPanda");
  return robot;
}

}  // namespace partsim
