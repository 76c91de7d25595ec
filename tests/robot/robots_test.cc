// Robot models: the flying gripper's closed-form kinematics and pose tracking under gravity, a
// grasp, the Panda's forward kinematics against an independent DH product, and URDF round trips.
#include "partsim/robot/robots.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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

}  // namespace
}  // namespace partsim
