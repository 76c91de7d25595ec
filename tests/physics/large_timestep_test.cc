// Scenes that SAPIEN users step at large timesteps (0.01 s): PD drives must stay stable on light
// links, as PhysX's backward-Euler drives do.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <memory>
#include <string>

#include "partsim/physics/scene.h"

namespace partsim {
namespace {

const Eigen::Quaterniond kXToZ(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()));
const Eigen::Quaterniond kXToY(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));

// SAPIEN's articulation tutorial car (density 1, about 0.3 kg): a body, a steering shaft in front
// (revolute about z, +-15 degrees) and a fixed one at the back, each carrying a pair of wheels
// below it: a capsule along the axle, unlimited revolute about it. The wheel centres lie 0.325 m
// below the body's: at z = 0.49 the wheels hang 1.5 cm above the ground.
Articulation AddToyCar(Scene& scene) {
  const double tire_radius = 0.15, density = 1.0;
  const Eigen::Vector3d body_half(0.5, 0.25, 0.125);
  const Eigen::Vector3d shaft_half(0.1 * tire_radius, 0.1 * tire_radius, 0.2 * body_half.z());
  const double axle_half = 2.0 * body_half.y();
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.SetName("car").SetInitialPose(Pose(Eigen::Vector3d(0, 0, 0.49)));
  LinkBuilder* body = b.CreateLinkBuilder();
  body->SetName("body").AddBoxCollision(Pose(), body_half, {}, density);
  const char* names[2] = {"front", "back"};
  for (int i = 0; i < 2; ++i) {
    const double x = (i == 0 ? 1 : -1) * (body_half.x() - tire_radius);
    LinkBuilder* shaft = b.CreateLinkBuilder(body);
    shaft->SetName(std::string(names[i]) + "_shaft")
        .SetJointName(std::string(names[i]) + "_shaft_joint")
        .SetJointProperties(i == 0 ? JointType::kRevolute : JointType::kFixed,
                            Eigen::Vector2d(-M_PI / 12, M_PI / 12),
                            Pose(Eigen::Vector3d(x, 0, -body_half.z()), kXToZ),
                            Pose(Eigen::Vector3d(0, 0, shaft_half.z()), kXToZ))
        .AddBoxCollision(Pose(), shaft_half, {}, density);
    LinkBuilder* wheels = b.CreateLinkBuilder(shaft);
    wheels->SetName(std::string(names[i]) + "_wheels")
        .SetJointName(std::string(names[i]) + "_gear")
        .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-kInf, kInf),
                            Pose(Eigen::Vector3d(0, 0, -(shaft_half.z() + tire_radius)), kXToY),
                            Pose())
        .AddCapsuleCollision(Pose(), tire_radius, axle_half, {}, density);
  }
  return b.Build();
}

SceneConfig TutorialConfig(double dt) {
  SceneConfig config;
  config.timestep = dt;
  config.default_material = PhysicalMaterial{1.0, 1.0, 0.0};
  return config;
}

// The tutorial's drives: a stiff position drive on the steering, velocity drives on the gears.
void SetUpDrives(Articulation& car) {
  car.FindJointByName("front_shaft_joint").SetDriveProperty(1000, 0);
  for (const char* gear : {"front_gear", "back_gear"})
    car.FindJointByName(gear).SetDriveProperty(0, 1000);
}

// Steps with the wheels at `speed` (rad/s) and the steering at `steer` (rad); every step the
// state must be finite and the body ride on its wheels, 0.475 m up (it bobs up 2.5 cm when the
// wheels bite).
::testing::AssertionResult Drive(Scene& scene, Articulation& car, double speed, double steer,
                                 int steps) {
  car.FindJointByName("front_shaft_joint").SetDriveTarget(steer);
  for (const char* gear : {"front_gear", "back_gear"})
    car.FindJointByName(gear).SetDriveVelocityTarget(speed);
  for (int i = 0; i < steps; ++i) {
    scene.Step();
    const Pose pose = car.GetRootPose();
    if (!pose.p.allFinite() || !car.GetQvel().allFinite())
      return ::testing::AssertionFailure() << "not finite at step " << i;
    if (std::abs(pose.p.z() - 0.475) > 0.03)
      return ::testing::AssertionFailure() << "body at z = " << pose.p.z() << " at step " << i;
  }
  return ::testing::AssertionSuccess();
}

double Yaw(const Pose& pose) { return 2 * std::atan2(pose.q.z(), pose.q.w()); }

// Before backward-Euler drives, at dt = 0.01: the steering spring (1000 N m/rad on about
// 0.004 kg m^2, dt sqrt(k / I) = 5) diverged, and the gears' damping (1000 N m s/rad on about
// 1e-3 kg m^2), integrated implicitly only after the contacts were solved against its explicit
// pull, threw the car up as soon as the wheels started on the ground.
TEST(LargeTimestepTest, ToyCarDrivesStraightAtTenMilliseconds) {
  Scene scene(TutorialConfig(0.01));
  scene.AddGround(0.0);
  Articulation car = AddToyCar(scene);
  SetUpDrives(car);
  // lands on its wheels and rests
  for (int i = 0; i < 50; ++i) {
    scene.Step();
    ASSERT_TRUE(car.GetRootPose().p.allFinite()) << "step " << i;
  }
  EXPECT_NEAR(car.GetRootPose().p.z(), 0.475, 0.005);
  const Eigen::Vector3d start = car.GetRootPose().p;
  ASSERT_TRUE(Drive(scene, car, 10.0, 0.0, 200));
  EXPECT_TRUE(scene.GetWarnings().empty());
  // 10 rad/s on 0.15 m tires: 1.5 m/s straight ahead, 3 m in 2 s less the spin-up
  const Pose pose = car.GetRootPose();
  EXPECT_GT(pose.p.x() - start.x(), 2.7);
  EXPECT_LT(pose.p.x() - start.x(), 3.0);
  EXPECT_NEAR(pose.p.y(), start.y(), 0.02);
  EXPECT_NEAR(std::abs(car.FindJointByName("front_shaft_joint").GetQpos()), 0.0, 0.01);
  EXPECT_NEAR(car.FindJointByName("back_gear").GetQvel(), 10.0, 0.1);
  EXPECT_GT(std::abs(pose.q.w()), 0.999);  // upright, heading along x
}

// Steering, with a damped steering drive: the tutorial's undamped one snaps the 1.3 m roller
// round within a step at any dt, and MuJoCo's soft friction cone turns the scrub into a normal
// push that throws the light car up (0.6 m at dt = 0.001 too). Over a second of a steady turn
// (0.16 rad/s at dt = 0.001, 0.17 at 0.002, 0.19 at 0.01) the car circles left on the ground.
TEST(LargeTimestepTest, ToyCarSteersLeftAtTenMilliseconds) {
  Scene scene(TutorialConfig(0.01));
  scene.AddGround(0.0);
  Articulation car = AddToyCar(scene);
  SetUpDrives(car);
  car.FindJointByName("front_shaft_joint").SetDriveProperty(1000, 60);
  scene.Step(50);
  ASSERT_TRUE(Drive(scene, car, 10.0, 0.0, 100));
  ASSERT_TRUE(Drive(scene, car, 10.0, 0.2, 50));
  const double yaw = Yaw(car.GetRootPose());
  ASSERT_TRUE(Drive(scene, car, 10.0, 0.2, 50));
  EXPECT_TRUE(scene.GetWarnings().empty());
  EXPECT_NEAR(car.FindJointByName("front_shaft_joint").GetQpos(), 0.2, 0.01);
  const double rate = (Yaw(car.GetRootPose()) - yaw) / 0.5;  // rad/s
  EXPECT_GT(rate, 0.12);
  EXPECT_LT(rate, 0.25);
}

// One light link (I = 1e-4 kg m^2) on a hinge about its centre of mass, no gravity.
struct LightLink {
  std::unique_ptr<Scene> scene;
  Articulation art;
  Joint joint;
};

constexpr double kLightInertia = 1e-4;

LightLink MakeLightLink(double dt, Integrator integrator = Integrator::kImplicit) {
  SceneConfig config;
  config.timestep = dt;
  config.gravity = Eigen::Vector3d::Zero();
  config.integrator = integrator;
  LightLink w{std::make_unique<Scene>(config), {}, {}};
  ArticulationBuilder b = w.scene->CreateArticulationBuilder();
  LinkBuilder* base = b.CreateLinkBuilder();
  base->SetName("base");
  LinkBuilder* arm = b.CreateLinkBuilder(base);
  arm->SetName("arm")
      .SetJointName("hinge")
      .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-kInf, kInf), Pose(), Pose())
      .SetMassAndInertia(0.01, Pose(), Eigen::Vector3d::Constant(kLightInertia));
  w.art = b.Build(/*fix_root_link=*/true);
  w.joint = w.art.FindJointByName("hinge");
  return w;
}

// The MuJoCo dof and actuator of the hinge and its drive.
int HingeDof(const LightLink& w) {
  const std::string name = "r" + std::to_string(w.art.GetId()) + "_j1";
  const mjModel* m = w.scene->GetMjModel();
  const int joint = mj_name2id(m, mjOBJ_JOINT, name.c_str());
  return joint < 0 ? -1 : m->jnt_dofadr[joint];
}
int DriveActuator(const LightLink& w) {
  const std::string name = "r" + std::to_string(w.art.GetId()) + "_d1";
  return mj_name2id(w.scene->GetMjModel(), mjOBJ_ACTUATOR, name.c_str());
}

// Backward Euler, PhysX's drive: I (v' - v) / dt = k (x* - x - dt v') + d (v* - v').
double BackwardEulerVelocity(double x, double v, double k, double d, double target,
                             double velocity_target, double dt) {
  return (kLightInertia * v + dt * (k * (target - x) + d * velocity_target)) /
         (kLightInertia + dt * d + dt * dt * k);
}

// dt sqrt(k / I) = 32: an explicit spring diverges at once.
TEST(LargeTimestepTest, StiffPositionDriveOnLightLinkSettlesAtTarget) {
  LightLink w = MakeLightLink(0.01);
  w.joint.SetDriveProperty(1000, 0);
  w.joint.SetDriveTarget(0.5);
  w.scene->Step(100);
  EXPECT_TRUE(w.scene->GetWarnings().empty());
  EXPECT_NEAR(w.joint.GetQpos(), 0.5, 1e-6);
  EXPECT_NEAR(w.joint.GetQvel(), 0.0, 1e-6);
}

TEST(LargeTimestepTest, DriveStepIsBackwardEuler) {
  const double k = 1000, d = 2, target = 0.5, velocity_target = 3;
  for (double dt : {0.002, 0.01}) {
    LightLink w = MakeLightLink(dt);
    w.joint.SetDriveProperty(k, d);
    w.joint.SetDriveTarget(target);
    w.joint.SetDriveVelocityTarget(velocity_target);
    double x = 0, v = 0;
    for (int i = 0; i < 5; ++i) {
      v = BackwardEulerVelocity(x, v, k, d, target, velocity_target, dt);
      x += dt * v;
      w.scene->Step();
      EXPECT_NEAR(w.joint.GetQvel(), v, 1e-9 * (1 + std::abs(v))) << "dt " << dt << " step " << i;
      EXPECT_NEAR(w.joint.GetQpos(), x, 1e-9) << "dt " << dt << " step " << i;
    }
  }
}

TEST(LargeTimestepTest, SetTimestepKeepsDrivesBackwardEuler) {
  const double k = 1000, d = 2, target = 0.5;
  LightLink w = MakeLightLink(0.002);
  w.joint.SetDriveProperty(k, d);
  w.joint.SetDriveTarget(target);
  w.scene->Step(3);
  double x = w.joint.GetQpos(), v = w.joint.GetQvel();
  const double dt = 0.01;
  w.scene->SetTimestep(dt);  // recompiled: the drive's velocity gain and inertia follow the step
  const int dof = HingeDof(w);
  ASSERT_GE(dof, 0);
  EXPECT_DOUBLE_EQ(w.scene->GetMjModel()->dof_armature[dof], dt * (d + k * dt));
  for (int i = 0; i < 3; ++i) {
    v = BackwardEulerVelocity(x, v, k, d, target, 0.0, dt);
    x += dt * v;
    w.scene->Step();
    EXPECT_NEAR(w.joint.GetQvel(), v, 1e-9 * (1 + std::abs(v))) << "step " << i;
    EXPECT_NEAR(w.joint.GetQpos(), x, 1e-9) << "step " << i;
  }
  // gains and armature set after the change use the new step too
  w.joint.SetDriveProperty(2 * k, d);
  EXPECT_DOUBLE_EQ(w.scene->GetMjModel()->dof_armature[dof], dt * (d + 2 * k * dt));
  w.joint.SetArmature(0.5);
  EXPECT_DOUBLE_EQ(w.scene->GetMjModel()->dof_armature[dof], 0.5 + dt * (d + 2 * k * dt));
  EXPECT_DOUBLE_EQ(w.joint.GetArmature(), 0.5);
}

// The inertia a drive lends its joint is the integrator's business: the mass matrix and the
// dynamics queries see the link and the joint's own armature only.
TEST(LargeTimestepTest, DriveInertiaStaysOutOfTheDynamicsQueries) {
  LightLink w = MakeLightLink(0.01);
  w.joint.SetDriveProperty(1000, 100);
  w.joint.SetArmature(2e-4);
  EXPECT_NEAR(w.art.ComputeManipulatorInertiaMatrix()(0, 0), kLightInertia + 2e-4, 1e-12);
  EXPECT_NEAR(w.art.ComputeForwardDynamics(Eigen::VectorXd::Constant(1, 3e-4))[0], 1.0, 1e-9);
  EXPECT_NEAR(w.art.ComputeInverseDynamics(Eigen::VectorXd::Constant(1, 1.0))[0], 3e-4, 1e-12);
}

TEST(LargeTimestepTest, ExplicitIntegratorsKeepThePlainDriveGains) {
  for (Integrator integrator : {Integrator::kEuler, Integrator::kRK4}) {
    LightLink w = MakeLightLink(0.001, integrator);
    w.joint.SetDriveProperty(1000, 2);
    const mjModel* m = w.scene->GetMjModel();
    const int act = DriveActuator(w), dof = HingeDof(w);
    ASSERT_GE(act, 0);
    ASSERT_GE(dof, 0);
    EXPECT_DOUBLE_EQ(m->actuator_biasprm[act * mjNBIAS + 1], -1000.0);
    EXPECT_DOUBLE_EQ(m->actuator_biasprm[act * mjNBIAS + 2], -2.0);
    EXPECT_DOUBLE_EQ(m->dof_armature[dof], 0.0);
  }
}

}  // namespace
}  // namespace partsim
