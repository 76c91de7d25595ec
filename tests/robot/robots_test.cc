// Robot models: the flying gripper's closed-form kinematics and pose tracking under gravity, a
// grasp, the Panda's forward kinematics against an independent DH product, and URDF round trips.
#include "partsim/robot/robots.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "partsim/assets/urdf.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

using Eigen::AngleAxisd;
using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;
using Eigen::VectorXd;

// Angle of the rotation between two orientations (rad).
double AngleBetween(const Quaterniond& a, const Quaterniond& b) {
  return Eigen::AngleAxisd(a.inverse() * b).angle();
}

// Steps with gravity compensation, the way controllers drive the robots.
void StepCompensated(Scene* scene, Articulation* art, int steps) {
  for (int i = 0; i < steps; ++i) {
    art->SetQf(art->ComputePassiveForce());
    scene->Step();
  }
}

// Dof index of a joint by name.
int Dof(const Articulation& art, const std::string& joint) {
  return art.FindJointByName(joint).GetDofIndex();
}

// Arm joints of the flying gripper for a TCP pose in the root frame: x, y, z, then Z-Y-X Euler
// angles of the rotation.
std::vector<double> FlyingGripperIk(const Pose& X_RT) {
  const Matrix3d r = X_RT.q.toRotationMatrix();
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  const double pitch = std::asin(-r(2, 0));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  return {X_RT.p.x(), X_RT.p.y(), X_RT.p.z(), yaw, pitch, roll};
}

Pose TcpPose(const Articulation& art, const RobotModel& robot) {
  return art.FindLinkByName(robot.ee_link).GetPose() * robot.tcp_in_ee;
}

// ---------------------------------------------------------------- flying gripper

TEST(RobotsFlyingGripperTest, JointsAndLinksFollowTheBrief) {
  RobotModel robot = BuildFlyingGripper();
  EXPECT_EQ(robot.arm_joints, (std::vector<std::string>{"x", "y", "z", "yaw", "pitch", "roll"}));
  EXPECT_EQ(robot.gripper_joints,
            (std::vector<std::string>{"left_finger_joint", "right_finger_joint"}));
  EXPECT_EQ(robot.ee_link, "hand");
  EXPECT_EQ(robot.home.size(), 6u);
  EXPECT_EQ(robot.arm_velocity_limits.size(), 6u);
  EXPECT_EQ(robot.arm_effort_limits.size(), 6u);
  EXPECT_DOUBLE_EQ(robot.gripper_open, 0.05);
  Scene scene;
  Articulation art = scene.AddArticulation(robot.articulation);
  EXPECT_EQ(art.Dof(), 8);
  EXPECT_EQ(art.GetLink(0).GetName(), "root");
  // the hand weighs ~1 kg with its fingers
  double moving = 0;
  for (const Link& l : art.GetLinks())
    if (l.GetIndex() > 0) moving += l.GetMass();
  EXPECT_GT(moving, 0.8);
  EXPECT_LT(moving, 1.5);

  FlyingGripperOptions bad;
  bad.finger_travel = -1;
  EXPECT_THROW(BuildFlyingGripper(bad), Error);
}

TEST(RobotsFlyingGripperTest, TcpPoseIsTheClosedFormProduct) {
  RobotModel robot = BuildFlyingGripper();
  robot.articulation.root_pose =
      Pose(Vector3d(0.1, -0.2, 0.7), Quaterniond(AngleAxisd(0.4, Vector3d(1, 2, 3).normalized())));
  Scene scene;
  Articulation art = scene.AddArticulation(robot.articulation);
  // at q = 0 the TCP is the root frame
  Pose tcp0 = TcpPose(art, robot);
  EXPECT_LT((tcp0.p - robot.articulation.root_pose.p).norm(), 1e-12);
  EXPECT_LT(AngleBetween(tcp0.q, robot.articulation.root_pose.q), 1e-9);

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  for (int trial = 0; trial < 10; ++trial) {
    VectorXd q = VectorXd::Zero(art.Dof());
    for (int k = 0; k < 6; ++k) q[Dof(art, robot.arm_joints[k])] = u(rng);
    art.SetQpos(q);
    const double x = q[Dof(art, "x")], y = q[Dof(art, "y")], z = q[Dof(art, "z")];
    const double yaw = q[Dof(art, "yaw")], pitch = q[Dof(art, "pitch")], roll = q[Dof(art, "roll")];
    Pose expected = robot.articulation.root_pose *
                    Pose(Vector3d(x, y, z), AngleAxisd(yaw, Vector3d::UnitZ()) *
                                                AngleAxisd(pitch, Vector3d::UnitY()) *
                                                AngleAxisd(roll, Vector3d::UnitX()));
    Pose tcp = TcpPose(art, robot);
    EXPECT_LT((tcp.p - expected.p).norm(), 1e-9);
    EXPECT_LT(AngleBetween(tcp.q, expected.q), 1e-9);
    // and the closed-form inverse gives the joints back
    std::vector<double> ik = FlyingGripperIk(robot.articulation.root_pose.Inverse() * tcp);
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(ik[k], q[Dof(art, robot.arm_joints[k])], 1e-9);
  }
}

TEST(RobotsFlyingGripperTest, TracksAPoseTargetUnderGravityAndMovesItsFingers) {
  RobotModel robot = BuildFlyingGripper();
  robot.articulation.root_pose = Pose(Vector3d(0, 0, 1));
  Scene scene;
  Articulation art = scene.AddArticulation(robot.articulation);
  const Pose target_in_root(
      Vector3d(0.3, -0.2, 0.15),
      Quaterniond(AngleAxisd(0.7, Vector3d::UnitZ()) * AngleAxisd(-0.4, Vector3d::UnitY()) *
                  AngleAxisd(1.1, Vector3d::UnitX())));
  std::vector<double> arm = FlyingGripperIk(target_in_root);
  VectorXd target = VectorXd::Zero(art.Dof());
  for (int k = 0; k < 6; ++k) target[Dof(art, robot.arm_joints[k])] = arm[k];
  target[Dof(art, "left_finger_joint")] = 0.04;
  target[Dof(art, "right_finger_joint")] = 0.04;
  art.SetDriveTarget(target);
  StepCompensated(&scene, &art, 1000);  // 2 s

  const Pose target_world = robot.articulation.root_pose * target_in_root;
  Pose tcp = TcpPose(art, robot);
  const double position_error = (tcp.p - target_world.p).norm();
  const double rotation_error = AngleBetween(tcp.q, target_world.q);
  EXPECT_LT(position_error, 0.002);
  EXPECT_LT(rotation_error, M_PI / 180);
  EXPECT_NEAR(art.GetQpos()[Dof(art, "left_finger_joint")], 0.04, 1e-3);
  EXPECT_NEAR(art.GetQpos()[Dof(art, "right_finger_joint")], 0.04, 1e-3);
  RecordProperty("position_error_m", testing::PrintToString(position_error));
  RecordProperty("rotation_error_rad", testing::PrintToString(rotation_error));

  // the fingers close until they touch in the middle
  target[Dof(art, "left_finger_joint")] = 0.0;
  target[Dof(art, "right_finger_joint")] = 0.0;
  art.SetDriveTarget(target);
  StepCompensated(&scene, &art, 500);
  EXPECT_NEAR(art.GetQpos()[Dof(art, "left_finger_joint")], 0.0, 1e-3);
  EXPECT_NEAR(art.GetQpos()[Dof(art, "right_finger_joint")], 0.0, 1e-3);
  tcp = TcpPose(art, robot);
  EXPECT_LT((tcp.p - target_world.p).norm(), 0.002);
  EXPECT_LT(AngleBetween(tcp.q, target_world.q), M_PI / 180);
}

TEST(RobotsFlyingGripperTest, GraspsAndLiftsABox) {
  // the root looks down from 0.5 m: at q = 0 the hand approaches along -z of the world
  RobotModel robot = BuildFlyingGripper();
  robot.articulation.root_pose =
      Pose(Vector3d(0, 0, 0.5), Quaterniond(AngleAxisd(M_PI, Vector3d::UnitX())));
  Scene scene;
  scene.AddGround(0.0);
  Articulation art = scene.AddArticulation(robot.articulation);
  ActorDesc box;
  box.name = "box";
  CollisionShape shape;
  shape.type = ShapeType::kBox;
  shape.half_size = Vector3d(0.02, 0.02, 0.03);
  box.collisions.push_back(shape);
  box.inertial = Inertial();
  box.inertial->mass = 0.2;
  box.inertial->inertia = Vector3d::Constant(1e-4);
  box.pose = Pose(Vector3d(0, 0, 0.03));
  Actor cube = scene.AddActor(box);

  // open above the box, then come down until the TCP is at the box centre
  const int z = Dof(art, "z"), left = Dof(art, "left_finger_joint"),
            right = Dof(art, "right_finger_joint");
  VectorXd q = VectorXd::Zero(art.Dof());
  q[z] = 0.3;
  q[left] = q[right] = 0.045;
  art.SetQpos(q);
  art.SetDriveTarget(q);
  StepCompensated(&scene, &art, 100);
  VectorXd target = q;
  for (int i = 1; i <= 500; ++i) {
    target[z] = 0.3 + (0.47 - 0.3) * i / 500.0;
    art.SetDriveTarget(target);
    StepCompensated(&scene, &art, 1);
  }
  StepCompensated(&scene, &art, 200);
  EXPECT_NEAR(TcpPose(art, robot).p.z(), 0.03, 0.003);
  EXPECT_NEAR(cube.GetPose().p.z(), 0.03, 0.002);

  // close on the box, then lift by 0.1 m
  target[left] = target[right] = 0.0;
  art.SetDriveTarget(target);
  StepCompensated(&scene, &art, 300);
  // the fingers stop at the box's faces (0.02), into which MuJoCo's soft contacts let the pads
  // sink a few millimetres
  for (int f : {left, right}) {
    EXPECT_GT(art.GetQpos()[f], 0.013);
    EXPECT_LT(art.GetQpos()[f], 0.0205);
  }
  for (int i = 1; i <= 500; ++i) {
    target[z] = 0.47 - 0.1 * i / 500.0;
    art.SetDriveTarget(target);
    StepCompensated(&scene, &art, 1);
  }
  StepCompensated(&scene, &art, 500);
  const Pose tcp = TcpPose(art, robot);
  EXPECT_NEAR(tcp.p.z(), 0.13, 0.003);
  EXPECT_NEAR(cube.GetPose().p.z(), 0.13, 0.01);
  EXPECT_LT((cube.GetPose().p - tcp.p).head<2>().norm(), 0.005);
  RecordProperty("box_lift_m", testing::PrintToString(cube.GetPose().p.z() - 0.03));
}

// ---------------------------------------------------------------- Panda

// Craig's modified DH transform: RotX(alpha) TransX(a) RotZ(theta) TransZ(d), as a 4x4 matrix.
Eigen::Matrix4d Dh(double a, double d, double alpha, double theta) {
  auto rot_x = [](double t) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.block<3, 3>(0, 0) = AngleAxisd(t, Vector3d::UnitX()).toRotationMatrix();
    return m;
  };
  auto rot_z = [](double t) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.block<3, 3>(0, 0) = AngleAxisd(t, Vector3d::UnitZ()).toRotationMatrix();
    return m;
  };
  auto trans = [](double x, double y, double z) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.block<3, 1>(0, 3) = Vector3d(x, y, z);
    return m;
  };
  return rot_x(alpha) * trans(a, 0, 0) * rot_z(theta) * trans(0, 0, d);
}

// Frames of panda_link1..7, the flange and the TCP in the base frame, by the DH product.
std::vector<Eigen::Matrix4d> PandaDhFrames(const VectorXd& q) {
  const double a[7] = {0, 0, 0, 0.0825, -0.0825, 0, 0.088};
  const double d[7] = {0.333, 0, 0.316, 0, 0.384, 0, 0};
  const double alpha[7] = {0, -M_PI / 2, M_PI / 2, M_PI / 2, -M_PI / 2, M_PI / 2, M_PI / 2};
  std::vector<Eigen::Matrix4d> frames;
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  for (int i = 0; i < 7; ++i) {
    t = t * Dh(a[i], d[i], alpha[i], q[i]);
    frames.push_back(t);
  }
  const Eigen::Matrix4d flange = t * Dh(0, 0.107, 0, 0);
  frames.push_back(flange);
  frames.push_back(flange * Dh(0, 0.1034, 0, -M_PI / 4));
  return frames;
}

// Largest position and rotation differences between a pose and a 4x4 frame.
void ExpectPoseNear(const Pose& pose, const Eigen::Matrix4d& frame, double tol,
                    const std::string& what) {
  const Pose expected = Pose::FromMatrix(frame);
  EXPECT_LT((pose.p - expected.p).norm(), tol) << what;
  EXPECT_LT(AngleBetween(pose.q, expected.q), tol) << what;
}

TEST(RobotsPandaTest, ForwardKinematicsIsTheDhProduct) {
  RobotModel robot = BuildPanda();
  EXPECT_EQ(robot.arm_joints.size(), 7u);
  EXPECT_EQ(robot.gripper_joints.size(), 2u);
  EXPECT_EQ(robot.ee_link, "panda_hand");
  robot.articulation.root_pose =
      Pose(Vector3d(0.3, -0.1, 0.2), Quaterniond(AngleAxisd(0.5, Vector3d::UnitZ())));
  Scene scene;
  Articulation art = scene.AddArticulation(robot.articulation);
  ASSERT_EQ(art.Dof(), 9);
  const Pose base = robot.articulation.root_pose;

  // the flange at q = 0 is at (0.088, 0, 0.926) in the base, the TCP 0.1034 m below it
  art.SetQpos(VectorXd::Zero(9));
  const Pose hand0 = base.Inverse() * art.FindLinkByName("panda_hand").GetPose();
  EXPECT_LT((hand0.p - Vector3d(0.088, 0, 0.926)).norm(), 1e-12);
  const Pose tcp0 = hand0 * robot.tcp_in_ee;
  EXPECT_LT((tcp0.p - Vector3d(0.088, 0, 0.926 - 0.1034)).norm(), 1e-12);

  std::mt19937 rng(7);
  std::vector<VectorXd> configs = {VectorXd::Zero(7),
                                   Eigen::Map<const VectorXd>(robot.home.data(), 7)};
  const Eigen::MatrixX2d limits = art.GetQlimits();
  for (int k = 0; k < 5; ++k) {
    VectorXd q(7);
    for (int i = 0; i < 7; ++i)
      q[i] = std::uniform_real_distribution<double>(limits(i, 0), limits(i, 1))(rng);
    configs.push_back(q);
  }
  for (const VectorXd& q7 : configs) {
    VectorXd q = VectorXd::Zero(9);
    for (int i = 0; i < 7; ++i) q[Dof(art, robot.arm_joints[i])] = q7[i];
    art.SetQpos(q);
    std::vector<Eigen::Matrix4d> dh = PandaDhFrames(q7);
    for (int i = 0; i < 7; ++i) {
      const std::string link = "panda_link" + std::to_string(i + 1);
      ExpectPoseNear(base.Inverse() * art.FindLinkByName(link).GetPose(), dh[i], 1e-9, link);
    }
    const Pose hand = base.Inverse() * art.FindLinkByName("panda_hand").GetPose();
    ExpectPoseNear(
        hand * Pose(Vector3d::Zero(), Quaterniond(AngleAxisd(M_PI / 4, Vector3d::UnitZ()))), dh[7],
        1e-9, "flange");
    ExpectPoseNear(hand * robot.tcp_in_ee, dh[8], 1e-9, "tcp");
  }
}

TEST(RobotsPandaTest, HoldsHomeUnderGravityAndMovesItsFingers) {
  RobotModel robot = BuildPanda();
  Scene scene;
  scene.AddGround(0.0);
  Articulation art = scene.AddArticulation(robot.articulation);
  VectorXd home = VectorXd::Zero(9);
  for (int i = 0; i < 7; ++i) home[Dof(art, robot.arm_joints[i])] = robot.home[i];
  home[Dof(art, "panda_finger_joint1")] = home[Dof(art, "panda_finger_joint2")] = 0.04;
  art.SetQpos(home);
  const Pose tcp0 = TcpPose(art, robot);
  // start 0.1 rad away on every arm joint, drive back to home
  VectorXd start = home;
  for (int i = 0; i < 7; ++i) start[Dof(art, robot.arm_joints[i])] += i % 2 ? 0.1 : -0.1;
  art.SetQpos(start);
  art.SetDriveTarget(home);
  StepCompensated(&scene, &art, 1000);  // 2 s
  // no link touches another at home
  for (const Contact& c : scene.GetContacts()) {
    EXPECT_FALSE(c.body0.kind == ContactBody::Kind::kLink &&
                 c.body1.kind == ContactBody::Kind::kLink)
        << c.body0.name << " touches " << c.body1.name;
  }
  const VectorXd q = art.GetQpos();
  EXPECT_LT((q - home).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_LT((TcpPose(art, robot).p - tcp0.p).norm(), 1e-3);
  RecordProperty("home_error_rad", testing::PrintToString((q - home).cwiseAbs().maxCoeff()));

  // the fingers close
  VectorXd target = home;
  target[Dof(art, "panda_finger_joint1")] = target[Dof(art, "panda_finger_joint2")] = 0.0;
  art.SetDriveTarget(target);
  StepCompensated(&scene, &art, 500);
  EXPECT_NEAR(art.GetQpos()[Dof(art, "panda_finger_joint1")], 0.0, 1e-3);
  EXPECT_NEAR(art.GetQpos()[Dof(art, "panda_finger_joint2")], 0.0, 1e-3);
}

// ---------------------------------------------------------------- URDF writing

// A fresh folder under the system's temporary folder, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("partsim_robots_test_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string operator/(const std::string& file) const { return (path_ / file).string(); }

 private:
  std::filesystem::path path_;
};

// Compares an articulation read back from URDF with the one written: joints (types, limits,
// damping, friction, armature, drives), couplings, link masses and link poses at random q.
void ExpectSameArticulation(Scene* scene, const Articulation& original,
                            const Articulation& loaded) {
  ASSERT_EQ(original.Dof(), loaded.Dof());
  ASSERT_EQ(original.GetLinks().size(), loaded.GetLinks().size());
  EXPECT_EQ(original.HasFixedRoot(), loaded.HasFixedRoot());
  for (const Link& l : original.GetLinks()) {
    const Link m = loaded.FindLinkByName(l.GetName());
    EXPECT_NEAR(m.GetMass(), l.GetMass(), 1e-6 * l.GetMass()) << l.GetName();
  }
  std::vector<Joint> a = original.GetActiveJoints(), b = loaded.GetActiveJoints();
  for (size_t k = 0; k < a.size(); ++k) {
    const std::string& name = a[k].GetName();
    EXPECT_EQ(b[k].GetName(), name);
    EXPECT_EQ(b[k].GetType(), a[k].GetType()) << name;
    EXPECT_EQ(b[k].GetLimits(), a[k].GetLimits()) << name;
    EXPECT_EQ(b[k].GetDamping(), a[k].GetDamping()) << name;
    EXPECT_EQ(b[k].GetFriction(), a[k].GetFriction()) << name;
    EXPECT_EQ(b[k].GetArmature(), a[k].GetArmature()) << name;
    EXPECT_EQ(b[k].GetDriveStiffness(), a[k].GetDriveStiffness()) << name;
    EXPECT_EQ(b[k].GetDriveDamping(), a[k].GetDriveDamping()) << name;
    EXPECT_EQ(b[k].GetDriveForceLimit(), a[k].GetDriveForceLimit()) << name;
  }
  EXPECT_EQ(loaded.GetDesc().couplings.size(), original.GetDesc().couplings.size());
  std::mt19937 rng(11);
  const Eigen::MatrixX2d limits = original.GetQlimits();
  double worst = 0;
  for (int trial = 0; trial < 5; ++trial) {
    VectorXd q(original.Dof());
    for (int i = 0; i < q.size(); ++i) {
      const double lo = std::max(limits(i, 0), -3.0), hi = std::min(limits(i, 1), 3.0);
      q[i] = std::uniform_real_distribution<double>(lo, hi)(rng);
    }
    Articulation o = original, m = loaded;
    o.SetQpos(q);
    m.SetQpos(q);
    for (const Link& l : original.GetLinks()) {
      const Pose x = l.GetPose(), y = loaded.FindLinkByName(l.GetName()).GetPose();
      EXPECT_LT((x.p - y.p).norm(), 1e-9) << l.GetName();
      EXPECT_LT(AngleBetween(x.q, y.q), 1e-9) << l.GetName();
      worst = std::max({worst, (x.p - y.p).norm(), AngleBetween(x.q, y.q)});
    }
  }
  testing::Test::RecordProperty("worst_pose_difference_" + original.GetName(),
                                testing::PrintToString(worst));
}

TEST(RobotsUrdfTest, RoundTripKeepsKinematicsMassesLimitsAndDrives) {
  TempDir dir("roundtrip");
  RobotModel gripper = BuildFlyingGripper();
  gripper.articulation.root_pose =
      Pose(Vector3d(0.1, 0.2, 0.5), Quaterniond(AngleAxisd(0.3, Vector3d(1, 1, 0).normalized())));
  for (const RobotModel& robot : {BuildPanda(), gripper}) {
    const std::string path = dir / (robot.articulation.name + ".urdf");
    WriteUrdf(robot.articulation, path);
    Scene scene;
    Articulation original = scene.AddArticulation(robot.articulation);
    Articulation loaded = CreateUrdfLoader(scene).Load(path);
    EXPECT_EQ(loaded.GetName(), robot.articulation.name);
    ExpectSameArticulation(&scene, original, loaded);
    // the pads keep their friction
    const LinkDesc& finger = loaded.FindLinkByName(robot.articulation.links.back().name).GetDesc();
    ASSERT_TRUE(finger.collisions.back().material.has_value());
    EXPECT_EQ(finger.collisions.back().material->static_friction,
              robot.articulation.links.back().collisions.back().material->static_friction);
  }
}

TEST(RobotsUrdfTest, FlyingGripperFromUrdfReachesAPoseTarget) {
  TempDir dir("gripper");
  RobotModel robot = BuildFlyingGripper();
  WriteUrdf(robot.articulation, dir / "gripper.urdf");
  Scene scene;
  Articulation art = CreateUrdfLoader(scene).Load(dir / "gripper.urdf");
  const Pose target(Vector3d(-0.2, 0.1, 0.3), Quaterniond(AngleAxisd(-0.5, Vector3d::UnitZ()) *
                                                          AngleAxisd(0.3, Vector3d::UnitY()) *
                                                          AngleAxisd(-0.8, Vector3d::UnitX())));
  std::vector<double> arm = FlyingGripperIk(target);
  VectorXd q = VectorXd::Zero(art.Dof());
  for (int k = 0; k < 6; ++k) q[Dof(art, robot.arm_joints[k])] = arm[k];
  art.SetDriveTarget(q);
  StepCompensated(&scene, &art, 1000);
  const Pose tcp = TcpPose(art, robot);
  EXPECT_LT((tcp.p - target.p).norm(), 0.002);
  EXPECT_LT(AngleBetween(tcp.q, target.q), M_PI / 180);
}

TEST(RobotsUrdfTest, MeshesOffsetJointsAndFreeRootsRoundTrip) {
  // a free root with a convex mesh, a revolute joint whose axis misses the child's origin, and
  // a coupled prismatic joint
  auto mesh = std::make_shared<MeshData>();
  mesh->vertices = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}, {0, 0, 0.1f}};
  mesh->faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  ArticulationDesc art;
  art.name = "odd";
  art.fix_root = false;
  art.root_pose = Pose(Vector3d(0, 0, 1));
  LinkDesc base;
  base.name = "base";
  CollisionShape hull;
  hull.type = ShapeType::kConvexMesh;
  hull.mesh = mesh;
  base.collisions.push_back(hull);
  base.inertial = Inertial();
  art.links.push_back(base);
  LinkDesc arm;
  arm.name = "arm";
  arm.parent = 0;
  arm.joint.name = "hinge";
  arm.joint.type = JointType::kRevolute;
  arm.joint.lower = -1;
  arm.joint.upper = 2;
  arm.joint.pose_in_parent =
      Pose(Vector3d(0.2, 0, 0), Quaterniond(AngleAxisd(0.4, Vector3d(0, 1, 1).normalized())));
  arm.joint.pose_in_child =
      Pose(Vector3d(-0.1, 0.05, 0.02), Quaterniond(AngleAxisd(1.0, Vector3d::UnitZ())));
  arm.joint.damping = 0.3;
  arm.joint.friction = 0.1;
  CollisionShape rod;
  rod.type = ShapeType::kCylinder;
  rod.radius = 0.02;
  rod.half_length = 0.1;
  rod.pose = Pose(Vector3d(0.1, 0, 0));
  arm.collisions.push_back(rod);
  art.links.push_back(arm);
  for (const char* name : {"slide_a", "slide_b"}) {
    LinkDesc s;
    s.name = std::string(name) + "_link";
    s.parent = 1;
    s.joint.name = name;
    s.joint.type = JointType::kPrismatic;
    s.joint.lower = 0;
    s.joint.upper = 0.1;
    s.joint.pose_in_parent = Pose(Vector3d(0.1, 0, 0));
    CollisionShape ball;
    ball.type = ShapeType::kSphere;
    ball.radius = 0.01;
    s.collisions.push_back(ball);
    art.links.push_back(s);
  }
  art.couplings.push_back({"slide_b", "slide_a", -1.0, 0.05});

  TempDir dir("odd");
  WriteUrdf(art, dir / "odd.urdf");
  EXPECT_TRUE(std::filesystem::exists(dir / "odd_meshes"));
  Scene scene;
  scene.SetGravity(Vector3d::Zero());
  Articulation original = scene.AddArticulation(art);
  Articulation loaded = CreateUrdfLoader(scene).Load(dir / "odd.urdf");
  EXPECT_FALSE(loaded.HasFixedRoot());
  const LinkDesc& b = loaded.FindLinkByName("base").GetDesc();
  ASSERT_EQ(b.collisions.size(), 1u);
  EXPECT_EQ(b.collisions[0].type, ShapeType::kConvexMesh);
  // the same points (the OBJ reader may repeat a vertex per face)
  for (const Eigen::Vector3f& v : b.collisions[0].mesh->vertices) {
    double nearest = 1;
    for (const Eigen::Vector3f& w : mesh->vertices)
      nearest = std::min(nearest, double((v - w).norm()));
    EXPECT_LT(nearest, 1e-7);
  }
  for (const Eigen::Vector3f& w : mesh->vertices) {
    double nearest = 1;
    for (const Eigen::Vector3f& v : b.collisions[0].mesh->vertices)
      nearest = std::min(nearest, double((v - w).norm()));
    EXPECT_LT(nearest, 1e-7);
  }
  // the coupled slide keeps a dof of its own
  EXPECT_EQ(loaded.Dof(), 3);
  // the hinge's URDF link frame sits on the joint axis: compare the arm's joint frame, and the
  // links whose frames did not move
  Articulation o = original, m = loaded;
  for (double angle : {0.0, 0.7, -0.9}) {
    VectorXd q(3);
    q << angle, 0.03, 0.0;
    o.SetQpos(q);
    m.SetQpos(q);
    for (const char* link : {"base", "slide_a_link", "slide_b_link"}) {
      const Pose x = original.FindLinkByName(link).GetPose(),
                 y = loaded.FindLinkByName(link).GetPose();
      EXPECT_LT((x.p - y.p).norm(), 1e-9) << link;
      EXPECT_LT(AngleBetween(x.q, y.q), 1e-9) << link;
    }
    const Pose x = original.FindJointByName("hinge").GetGlobalPose();
    const Pose y = loaded.FindJointByName("hinge").GetGlobalPose();
    EXPECT_LT((x.p - y.p).norm(), 1e-9);
    EXPECT_LT((x.q * Vector3d::UnitX() - y.q * Vector3d::UnitX()).norm(), 1e-9);
  }
}

TEST(RobotsUrdfTest, ErrorsNameTheFileOrElement) {
  RobotModel robot = BuildFlyingGripper();
  try {
    WriteUrdf(robot.articulation, "/nonexistent_folder/sub/gripper.urdf");
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent_folder/sub/gripper.urdf"), std::string::npos)
        << e.what();
  }
  // a mesh needs a folder to go to
  ArticulationDesc art;
  art.name = "m";
  LinkDesc l;
  l.name = "only";
  CollisionShape hull;
  hull.type = ShapeType::kConvexMesh;
  auto mesh = std::make_shared<MeshData>();
  mesh->vertices = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}, {0, 0, 0.1f}};
  mesh->faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  hull.mesh = mesh;
  l.collisions.push_back(hull);
  art.links.push_back(l);
  EXPECT_THROW(ArticulationToUrdf(art), Error);
}

// The loader reads <partsim:drive> on joints and <partsim:collision> on collisions.
TEST(RobotsUrdfTest, LoaderReadsPartsimDriveAndCollisionElements) {
  const std::string urdf = R"(<?xml version="1.0"?>
<robot name="r" xmlns:partsim="https://partsim.dev/urdf">
  <link name="a"><collision><geometry><box size="0.1 0.1 0.1"/></geometry>
    <partsim:collision density="500" static_friction="1.7" dynamic_friction="1.1" restitution="0.2"/>
  </collision></link>
  <link name="b"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>
  <joint name="j" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.2" effort="30" velocity="1"/>
    <partsim:drive stiffness="800" damping="40" force_limit="25" target="0.1" armature="0.02"/>
  </joint>
</robot>)";
  UrdfLoader loader;
  ArticulationDesc desc = loader.Parse(urdf, ".", "drive.urdf");
  const JointDesc& j = desc.links[1].joint;
  EXPECT_EQ(j.drive.stiffness, 800);
  EXPECT_EQ(j.drive.damping, 40);
  EXPECT_EQ(j.drive.force_limit, 25);
  EXPECT_EQ(j.drive.target, 0.1);
  EXPECT_EQ(j.armature, 0.02);
  const CollisionShape& c = desc.links[0].collisions[0];
  EXPECT_EQ(c.density, 500);
  ASSERT_TRUE(c.material.has_value());
  EXPECT_EQ(c.material->static_friction, 1.7);
  EXPECT_EQ(c.material->dynamic_friction, 1.1);
  EXPECT_EQ(c.material->restitution, 0.2);
  // without the element: the loader's defaults, the effort limit as force limit
  std::string plain = urdf;
  plain.erase(plain.find("<partsim:drive"),
              plain.find("/>", plain.find("<partsim:drive")) + 2 - plain.find("<partsim:drive"));
  EXPECT_EQ(loader.Parse(plain, ".").links[1].joint.drive.force_limit, 30);
  EXPECT_EQ(loader.Parse(plain, ".").links[1].joint.drive.stiffness, 0);

  std::string bad = urdf;
  bad.replace(bad.find("stiffness=\"800\""), 15, "stiffness=\"-1\"");
  try {
    loader.Parse(bad, ".", "drive.urdf");
    FAIL() << "no exception";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("drive.urdf"), std::string::npos) << msg;
    EXPECT_NE(msg.find("joint 'j'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("stiffness"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace partsim
