// Drawer-pulling benchmark: a flying parallel gripper grasps the bar handle of a cabinet drawer
// and pulls it open. The same scene runs twice in this program: (a) through partsim's API
// (ArticulationBuilder, drives) and (b) directly against MuJoCo's C API with a hand-written MJCF
// of identical physical content. A third, diagnostic run steps a copy of partsim's own compiled
// model with raw mj_step, which isolates the cost of partsim's API. It prints the simulation
// speed of each (steps per second, median over repetitions, the runs interleaved episode by
// episode), their ratios, and the drawer opening each reached. Exit code 1 when (a) or (b) fails
// to open the drawer by 0.33 m or when the two compiled models differ; see README.md.
//
// Usage: partsim_drawer_bench [--reps N] [--episodes N] [--print-mjcf] [--raw-only] [--cpu-time]
//   --reps N       repetitions (default 5); the medians are taken over them
//   --episodes N   episodes per repetition and per run (default 10)
//   --print-mjcf   print the MJCF that partsim generated
//   --raw-only     run only the hand-written MuJoCo scene
//   --cpu-time     time with the thread's CPU clock instead of the wall clock
#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "partsim/physics/scene.h"

namespace {

// ---------------------------------------------------------------------------------------------
// Scene parameters. The raw MJCF below writes the same numbers out by hand.

constexpr double kTimestep = 1.0 / 500.0;  // s
constexpr int kSolverIterations = 50;
constexpr double kCloseTime = 0.2;      // s with the fingers closing before the pull
constexpr double kCloseRamp = 0.15;     // s over which the finger targets move to closed
constexpr double kPullTime = 2.0;       // s over which the pull target moves
constexpr double kPullDistance = 0.35;  // m
constexpr double kMinOpening = 0.33;    // m the drawer must reach
const int kSteps = static_cast<int>(std::lround((kCloseTime + kPullTime) / kTimestep));  // 1100

// cabinet: 0.8 m tall, 0.6 m wide, 0.5 m deep, 2 cm walls of wood (600 kg/m^3); its origin is at
// the centre of its bottom face, x out of the front
constexpr double kWood = 600.0;             // kg/m^3
constexpr double kAluminium = 2700.0;       // kg/m^3, handle
constexpr double kGripperDensity = 2000.0;  // kg/m^3, palm and fingers
constexpr double kGripFriction = 1.0;       // fingers and handle (rubber pads on metal)
constexpr double kDrawerZ = 0.67;           // drawer joint height (m)
constexpr double kDrawerTravel = 0.4;       // m
constexpr double kDrawerDamping = 0.5;      // N s/m
constexpr double kDrawerFriction = 0.1;     // N
constexpr double kHandleX = 0.29;           // bar axis in the world (m): 4 cm before the front

// gripper: root 5.5 cm in front of the bar, so that the bar sits between the finger pads
const Eigen::Vector3d kGripperStart(kHandleX + 0.055, 0.0, kDrawerZ);
constexpr double kLinkMass = 0.1;        // kg, each of the 5 intermediate links of the base
constexpr double kLinkInertia = 1e-4;    // kg m^2
constexpr double kFingerTravel = 0.045;  // m, finger joint upper limit (closed target)

// drives: base translation, base rotation, fingers
constexpr double kKpLinear = 20000.0, kKdLinear = 400.0;  // N/m, N s/m
constexpr double kKpAngular = 100.0, kKdAngular = 5.0;    // N m/rad, N m s/rad
constexpr double kKpFinger = 2000.0, kKdFinger = 100.0;   // N/m, N s/m
constexpr double kFingerForceLimit = 30.0;                // N

// Drive targets at time t: base x, y, z, roll, pitch, yaw, finger 1, finger 2.
void Targets(double t, std::array<double, 8>* q) {
  q->fill(0.0);
  double s = std::clamp((t - kCloseTime) / kPullTime, 0.0, 1.0);
  (*q)[0] = kPullDistance * s;
  double c = std::clamp(t / kCloseRamp, 0.0, 1.0);
  (*q)[6] = kFingerTravel * c;
  (*q)[7] = kFingerTravel * c;
}

// Drives are stepped by backward Euler, as partsim does with the implicit integrator (see
// partsim::DriveVelocityGain): over a step dt the force is kp (target - q) - c qdot with the
// velocity gain c = kd + kp dt, of which the actuator holds only the stiffness (a velocity gain
// there would be integrated implicitly a second time); the control written before each step
// carries kp target - c qdot, and the joint gets dt c of armature.
struct DriveGains {
  double kp = 0.0;  // stiffness: N/m or N m/rad
  double kd = 0.0;  // damping: N s/m or N m s/rad
};
// in joint order: x, y, z, roll, pitch, yaw, finger 1, finger 2
constexpr std::array<DriveGains, 8> kDrives{{{kKpLinear, kKdLinear},
                                             {kKpLinear, kKdLinear},
                                             {kKpLinear, kKdLinear},
                                             {kKpAngular, kKdAngular},
                                             {kKpAngular, kKdAngular},
                                             {kKpAngular, kKdAngular},
                                             {kKpFinger, kKdFinger},
                                             {kKpFinger, kKdFinger}}};

/// Velocity gain of a backward-Euler drive over a step dt: c = kd + kp dt.
double VelocityGain(const DriveGains& g) { return g.kd + g.kp * kTimestep; }

// ---------------------------------------------------------------------------------------------
// (b) raw MuJoCo: the same scene, hand-written. The driven joints' armature is dt c: 0.88 kg on
// the base slides (c = 440 N s/m), 0.0104 kg m^2 on the base hinges (c = 5.2 N m s/rad) and
// 0.208 kg on the fingers (c = 104 N s/m).

const char* kRawMjcf = R"(
<mujoco model="drawer_raw">
  <compiler angle="radian" inertiafromgeom="auto" boundmass="1e-6" boundinertia="1e-9"/>
  <option timestep="0.002" gravity="0 0 -9.81" iterations="50" integrator="implicitfast"/>
  <default>
    <geom friction="0.5 0.005 0.0001" solref="0.02 1" density="600" conaffinity="-1"
          margin="5e-8" solimp="0.999 0.999 0.001 0.5 2"/>
  </default>
  <worldbody>
    <body name="cabinet">
      <geom type="box" pos="-0.24 0 0.4" size="0.01 0.28 0.38"/>
      <geom type="box" pos="0 0.29 0.4" size="0.25 0.01 0.4"/>
      <geom type="box" pos="0 -0.29 0.4" size="0.25 0.01 0.4"/>
      <geom type="box" pos="0 0 0.79" size="0.25 0.28 0.01"/>
      <geom type="box" pos="0 0 0.01" size="0.25 0.28 0.01"/>
      <geom type="box" pos="0.01 0 0.55" size="0.24 0.28 0.01"/>
      <body name="drawer" pos="0.25 0 0.67">
        <joint name="drawer" type="slide" axis="1 0 0" limited="true" range="0 0.4"
               solreflimit="0.004 1" solimplimit="0.99 0.999 0.001 0.5 2"
               damping="0.5" frictionloss="0.1"/>
        <geom type="box" pos="-0.01 0 0" size="0.01 0.277 0.107"/>
        <geom type="box" pos="-0.245 0 -0.095" size="0.225 0.272 0.01"/>
        <geom type="box" pos="-0.245 0.262 -0.005" size="0.225 0.01 0.1"/>
        <geom type="box" pos="-0.245 -0.262 -0.005" size="0.225 0.01 0.1"/>
        <geom type="box" pos="-0.46 0 -0.005" size="0.01 0.252 0.1"/>
        <geom type="cylinder" pos="0.04 0 0" zaxis="0 1 0" size="0.01 0.1" density="2700"
              friction="1 0.005 0.0001"/>
        <geom type="cylinder" pos="0.02 0.08 0" zaxis="1 0 0" size="0.007 0.02" density="2700"/>
        <geom type="cylinder" pos="0.02 -0.08 0" zaxis="1 0 0" size="0.007 0.02" density="2700"/>
      </body>
    </body>
    <body name="gripper" pos="0.345 0 0.67">
      <body name="base_x">
        <joint name="x" type="slide" axis="1 0 0" limited="false" armature="0.88"/>
        <inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/>
        <body name="base_y">
          <joint name="y" type="slide" axis="0 1 0" limited="false" armature="0.88"/>
          <inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/>
          <body name="base_z">
            <joint name="z" type="slide" axis="0 0 1" limited="false" armature="0.88"/>
            <inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/>
            <body name="base_roll">
              <joint name="roll" type="hinge" axis="1 0 0" limited="false" armature="0.0104"/>
              <inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/>
              <body name="base_pitch">
                <joint name="pitch" type="hinge" axis="0 1 0" limited="false" armature="0.0104"/>
                <inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/>
                <body name="palm">
                  <joint name="yaw" type="hinge" axis="0 0 1" limited="false" armature="0.0104"/>
                  <geom type="box" size="0.015 0.04 0.07" density="2000"/>
                  <body name="finger_1">
                    <joint name="finger_1" type="slide" axis="0 0 -1" limited="true"
                           range="0 0.045" solreflimit="0.004 1"
                           solimplimit="0.99 0.999 0.001 0.5 2" armature="0.208"/>
                    <geom type="box" pos="-0.045 0 0.05" size="0.03 0.015 0.01" density="2000"
                          friction="1 0.005 0.0001"/>
                  </body>
                  <body name="finger_2">
                    <joint name="finger_2" type="slide" axis="0 0 1" limited="true"
                           range="0 0.045" solreflimit="0.004 1"
                           solimplimit="0.99 0.999 0.001 0.5 2" armature="0.208"/>
                    <geom type="box" pos="-0.045 0 -0.05" size="0.03 0.015 0.01" density="2000"
                          friction="1 0.005 0.0001"/>
                  </body>
                </body>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <contact>
    <exclude body1="cabinet" body2="drawer"/>
    <exclude body1="palm" body2="finger_1"/>
    <exclude body1="palm" body2="finger_2"/>
  </contact>
  <actuator>
    <general joint="x" gainprm="1" biastype="affine" biasprm="0 -20000 0"/>
    <general joint="y" gainprm="1" biastype="affine" biasprm="0 -20000 0"/>
    <general joint="z" gainprm="1" biastype="affine" biasprm="0 -20000 0"/>
    <general joint="roll" gainprm="1" biastype="affine" biasprm="0 -100 0"/>
    <general joint="pitch" gainprm="1" biastype="affine" biasprm="0 -100 0"/>
    <general joint="yaw" gainprm="1" biastype="affine" biasprm="0 -100 0"/>
    <general joint="finger_1" gainprm="1" biastype="affine" biasprm="0 -2000 0"
             forcelimited="true" forcerange="-30 30"/>
    <general joint="finger_2" gainprm="1" biastype="affine" biasprm="0 -2000 0"
             forcelimited="true" forcerange="-30 30"/>
  </actuator>
</mujoco>
)";

// Parses and compiles MJCF text; exits on error.
mjModel* LoadFromString(const std::string& xml) {
  char error[1024] = "";
  mjSpec* spec = mj_parseXMLString(xml.c_str(), nullptr, error, sizeof(error));
  mjModel* m = spec ? mj_compile(spec, nullptr) : nullptr;
  if (!m) {
    std::fprintf(stderr, "raw MJCF failed to load: %s\n", spec ? mjs_getError(spec) : error);
    std::exit(1);
  }
  mj_deleteSpec(spec);
  return m;
}

// Which clock times the episodes: wall-clock (default) or the thread's CPU time, which leaves out
// the time the thread waits for a core on a loaded machine.
bool g_cpu_clock = false;

/// Current time in seconds on the chosen clock.
double Now() {
  if (g_cpu_clock) {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct EpisodeResult {
  double seconds = 0.0;  // time of the stepping loop
  double opening = 0.0;  // final drawer position (m)
};

/// A model stepped directly through MuJoCo's C API, with where its 8 gripper controls go.
struct RawRun {
  const mjModel* m = nullptr;
  mjData* d = nullptr;
  int drawer_qposadr = -1;
  std::array<int, 8> actuator{};  // actuator of each gripper dof
  std::array<int, 8> dof{};       // its dof (qvel address)
  std::array<double, 8> kp{};     // control = kp target - c qvel
  std::array<double, 8> c{};

  /// Finds the actuator and dof of each drive by its joint; `joints` in kDrives order.
  void SetDrives(const std::array<int, 8>& joints) {
    for (int i = 0; i < 8; ++i) {
      actuator[i] = -1;
      for (int k = 0; k < m->nu; ++k)
        if (m->actuator_trntype[k] == mjTRN_JOINT && m->actuator_trnid[2 * k] == joints[i])
          actuator[i] = k;
      if (actuator[i] < 0) {
        std::fprintf(stderr, "no actuator on joint %d\n", joints[i]);
        std::exit(1);
      }
      dof[i] = m->jnt_dofadr[joints[i]];
      kp[i] = kDrives[i].kp;
      c[i] = VelocityGain(kDrives[i]);
    }
  }
};

/// One episode against MuJoCo directly: reset, then set controls (the backward-Euler drive law,
/// velocity targets 0) and step.
EpisodeResult RunRawEpisode(const RawRun& run) {
  const mjModel* m = run.m;
  mjData* d = run.d;
  mj_resetData(m, d);
  std::array<double, 8> q;
  double start = Now();
  for (int k = 0; k < kSteps; ++k) {
    Targets(d->time, &q);
    for (int i = 0; i < 8; ++i)
      d->ctrl[run.actuator[i]] = run.kp[i] * q[i] - run.c[i] * d->qvel[run.dof[i]];
    mj_step(m, d);
  }
  double stop = Now();
  return {stop - start, d->qpos[run.drawer_qposadr]};
}

// ---------------------------------------------------------------------------------------------
// (a) partsim: the same scene through the builders

using partsim::JointType;
using partsim::PhysicalMaterial;
using partsim::Pose;

/// Rotation that takes the x axis onto `axis` (one of +-x, +-y, +-z).
Eigen::Quaterniond XTo(const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), axis);
}

Pose P(double x, double y, double z) { return Pose(Eigen::Vector3d(x, y, z)); }

partsim::Articulation BuildCabinet(partsim::Scene* scene) {
  PhysicalMaterial grip{kGripFriction, kGripFriction, 0.0};
  partsim::ArticulationBuilder b = scene->CreateArticulationBuilder();
  b.SetName("cabinet");
  // body: back, sides, top, bottom, divider
  partsim::LinkBuilder* body = b.CreateLinkBuilder();
  body->SetName("body");
  body->AddBoxCollision(P(-0.24, 0, 0.4), {0.01, 0.28, 0.38}, {}, kWood)
      .AddBoxCollision(P(0, 0.29, 0.4), {0.25, 0.01, 0.4}, {}, kWood)
      .AddBoxCollision(P(0, -0.29, 0.4), {0.25, 0.01, 0.4}, {}, kWood)
      .AddBoxCollision(P(0, 0, 0.79), {0.25, 0.28, 0.01}, {}, kWood)
      .AddBoxCollision(P(0, 0, 0.01), {0.25, 0.28, 0.01}, {}, kWood)
      .AddBoxCollision(P(0.01, 0, 0.55), {0.24, 0.28, 0.01}, {}, kWood);
  // drawer: front, bottom, sides, back, and the handle (a bar along y on two posts along x)
  partsim::LinkBuilder* drawer = b.CreateLinkBuilder(body);
  drawer->SetName("drawer");
  drawer->SetJointName("drawer");
  drawer->SetJointProperties(JointType::kPrismatic, {0.0, kDrawerTravel}, P(0.25, 0, kDrawerZ),
                             Pose(), kDrawerFriction, kDrawerDamping);
  drawer->AddBoxCollision(P(-0.01, 0, 0), {0.01, 0.277, 0.107}, {}, kWood)
      .AddBoxCollision(P(-0.245, 0, -0.095), {0.225, 0.272, 0.01}, {}, kWood)
      .AddBoxCollision(P(-0.245, 0.262, -0.005), {0.225, 0.01, 0.1}, {}, kWood)
      .AddBoxCollision(P(-0.245, -0.262, -0.005), {0.225, 0.01, 0.1}, {}, kWood)
      .AddBoxCollision(P(-0.46, 0, -0.005), {0.01, 0.252, 0.1}, {}, kWood)
      .AddCylinderCollision(Pose(Eigen::Vector3d(0.04, 0, 0), XTo(Eigen::Vector3d::UnitY())), 0.01,
                            0.1, grip, kAluminium)
      .AddCylinderCollision(P(0.02, 0.08, 0), 0.007, 0.02, {}, kAluminium)
      .AddCylinderCollision(P(0.02, -0.08, 0), 0.007, 0.02, {}, kAluminium);
  b.SetInitialPose(Pose());
  return b.Build(/*fix_root_link=*/true);
}

partsim::Articulation BuildGripper(partsim::Scene* scene) {
  PhysicalMaterial grip{kGripFriction, kGripFriction, 0.0};
  partsim::ArticulationBuilder b = scene->CreateArticulationBuilder();
  b.SetName("gripper");
  partsim::LinkBuilder* root = b.CreateLinkBuilder();
  root->SetName("gripper");
  // base: slides along x, y, z, then turns about x, y, z; joint frames turn x onto each axis
  const char* names[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                   Eigen::Vector3d::UnitZ()};
  partsim::LinkBuilder* parent = root;
  for (int i = 0; i < 6; ++i) {
    partsim::LinkBuilder* link = b.CreateLinkBuilder(parent);
    Pose frame(Eigen::Vector3d::Zero(), XTo(axes[i % 3]));
    link->SetName(i < 5 ? std::string("base_") + names[i] : "palm");
    link->SetJointName(names[i]);
    link->SetJointProperties(i < 3 ? JointType::kPrismatic : JointType::kRevolute,
                             {-partsim::kInf, partsim::kInf}, frame, frame);
    if (i < 5) {
      link->SetMassAndInertia(kLinkMass, Pose(), Eigen::Vector3d::Constant(kLinkInertia));
    }
    parent = link;
  }
  partsim::LinkBuilder* palm = parent;
  palm->AddBoxCollision(Pose(), {0.015, 0.04, 0.07}, {}, kGripperDensity);
  // two fingers closing along -z and +z onto the bar
  for (int side : {1, -1}) {
    partsim::LinkBuilder* finger = b.CreateLinkBuilder(palm);
    std::string name = side > 0 ? "finger_1" : "finger_2";
    Pose frame(Eigen::Vector3d::Zero(), XTo(-side * Eigen::Vector3d::UnitZ()));
    finger->SetName(name);
    finger->SetJointName(name);
    finger->SetJointProperties(JointType::kPrismatic, {0.0, kFingerTravel}, frame, frame);
    finger->AddBoxCollision(P(-0.045, 0, side * 0.05), {0.03, 0.015, 0.01}, grip, kGripperDensity);
  }
  b.SetInitialPose(Pose(kGripperStart));
  partsim::Articulation gripper = b.Build(/*fix_root_link=*/true);
  // PD drives, in joint order x, y, z, roll, pitch, yaw, finger_1, finger_2
  std::vector<partsim::Joint> joints = gripper.GetActiveJoints();
  for (int i = 0; i < 8; ++i) {
    if (i < 6)
      joints[i].SetDriveProperty(kDrives[i].kp, kDrives[i].kd);
    else
      joints[i].SetDriveProperty(kDrives[i].kp, kDrives[i].kd, kFingerForceLimit);
  }
  return gripper;
}

/// One episode through partsim: restore the initial state, then set drive targets and step.
EpisodeResult RunPartsimEpisode(partsim::Scene* scene, const std::vector<char>& initial,
                                partsim::Articulation* gripper, const partsim::Joint& drawer) {
  scene->Unpack(initial);
  std::array<double, 8> q;
  Eigen::VectorXd target(8);
  double start = Now();
  for (int k = 0; k < kSteps; ++k) {
    Targets(scene->GetTime(), &q);
    for (int i = 0; i < 8; ++i) target[i] = q[i];
    gripper->SetDriveTarget(target);
    scene->Step();
  }
  double stop = Now();
  return {stop - start, drawer.GetQpos()};
}

// ---------------------------------------------------------------------------------------------
// Fairness check: the two compiled models must hold the same physics.

struct ModelDiff {
  int mismatches = 0;
  double Compare(const char* what, int index, double a, double b, double tol = 1e-9) {
    double err = std::abs(a - b);
    if (err > tol * std::max(1.0, std::abs(a))) {
      if (mismatches < 20) {
        std::fprintf(stderr, "model mismatch: %s[%d]: partsim %.12g, raw %.12g\n", what, index, a,
                     b);
      }
      ++mismatches;
    }
    return err;
  }
};

/// Compares body masses, inertias and world frames, geoms (type, size, world pose, friction,
/// solver parameters), joints, actuators and options. Bodies and geoms are matched by order.
int CompareModels(const mjModel* a, const mjModel* b) {
  ModelDiff diff;
  if (a->nbody != b->nbody || a->ngeom != b->ngeom || a->njnt != b->njnt || a->nv != b->nv ||
      a->nu < b->nu) {
    std::fprintf(
        stderr,
        "model mismatch: sizes (nbody, ngeom, njnt, nv, nu): partsim (%ld %ld %ld %ld %ld), "
        "raw (%ld %ld %ld %ld %ld)\n",
        static_cast<long>(a->nbody), static_cast<long>(a->ngeom), static_cast<long>(a->njnt),
        static_cast<long>(a->nv), static_cast<long>(a->nu), static_cast<long>(b->nbody),
        static_cast<long>(b->ngeom), static_cast<long>(b->njnt), static_cast<long>(b->nv),
        static_cast<long>(b->nu));
    return 1;
  }
  // options
  diff.Compare("timestep", 0, a->opt.timestep, b->opt.timestep);
  diff.Compare("iterations", 0, a->opt.iterations, b->opt.iterations);
  diff.Compare("integrator", 0, a->opt.integrator, b->opt.integrator);
  diff.Compare("cone", 0, a->opt.cone, b->opt.cone);
  diff.Compare("solver", 0, a->opt.solver, b->opt.solver);
  diff.Compare("tolerance", 0, a->opt.tolerance, b->opt.tolerance);
  diff.Compare("noslip_iterations", 0, a->opt.noslip_iterations, b->opt.noslip_iterations);
  diff.Compare("disableflags", 0, a->opt.disableflags, b->opt.disableflags);
  diff.Compare("enableflags", 0, a->opt.enableflags, b->opt.enableflags);
  for (int k = 0; k < 3; ++k) diff.Compare("gravity", k, a->opt.gravity[k], b->opt.gravity[k]);
  diff.Compare("narena", 0, a->narena, b->narena);
  // excluded body pairs (signature: body1 << 16 + body2)
  if (a->nexclude != b->nexclude) {
    diff.Compare("nexclude", 0, a->nexclude, b->nexclude);
  } else {
    for (int i = 0; i < a->nexclude; ++i)
      diff.Compare("exclude_signature", i, a->exclude_signature[i], b->exclude_signature[i]);
  }
  // world frames at qpos0
  mjData* da = mj_makeData(a);
  mjData* db = mj_makeData(b);
  mj_kinematics(a, da);
  mj_kinematics(b, db);
  for (int i = 0; i < a->nbody; ++i) {
    diff.Compare("body_parentid", i, a->body_parentid[i], b->body_parentid[i]);
    diff.Compare("body_mass", i, a->body_mass[i], b->body_mass[i]);
    for (int k = 0; k < 3; ++k) {
      diff.Compare("body_inertia", i, a->body_inertia[3 * i + k], b->body_inertia[3 * i + k]);
      diff.Compare("body_xipos", i, da->xipos[3 * i + k], db->xipos[3 * i + k]);
      diff.Compare("body_xpos", i, da->xpos[3 * i + k], db->xpos[3 * i + k]);
    }
  }
  for (int i = 0; i < a->ngeom; ++i) {
    diff.Compare("geom_type", i, a->geom_type[i], b->geom_type[i]);
    diff.Compare("geom_bodyid", i, a->geom_bodyid[i], b->geom_bodyid[i]);
    diff.Compare("geom_contype", i, a->geom_contype[i], b->geom_contype[i]);
    diff.Compare("geom_conaffinity", i, a->geom_conaffinity[i], b->geom_conaffinity[i]);
    diff.Compare("geom_condim", i, a->geom_condim[i], b->geom_condim[i]);
    diff.Compare("geom_margin", i, a->geom_margin[i], b->geom_margin[i]);
    for (int k = 0; k < 3; ++k) {
      diff.Compare("geom_size", i, a->geom_size[3 * i + k], b->geom_size[3 * i + k]);
      diff.Compare("geom_xpos", i, da->geom_xpos[3 * i + k], db->geom_xpos[3 * i + k]);
      diff.Compare("geom_friction", i, a->geom_friction[3 * i + k], b->geom_friction[3 * i + k]);
      // the z axis is what matters for cylinders; boxes need all three
      for (int c = 0; c < 3; ++c) {
        if (a->geom_type[i] == mjGEOM_CYLINDER && c != 2) continue;
        diff.Compare("geom_xmat", i, da->geom_xmat[9 * i + 3 * k + c],
                     db->geom_xmat[9 * i + 3 * k + c]);
      }
    }
    for (int k = 0; k < mjNREF; ++k)
      diff.Compare("geom_solref", i, a->geom_solref[mjNREF * i + k],
                   b->geom_solref[mjNREF * i + k]);
    for (int k = 0; k < mjNIMP; ++k)
      diff.Compare("geom_solimp", i, a->geom_solimp[mjNIMP * i + k],
                   b->geom_solimp[mjNIMP * i + k]);
  }
  for (int i = 0; i < a->njnt; ++i) {
    diff.Compare("jnt_type", i, a->jnt_type[i], b->jnt_type[i]);
    diff.Compare("jnt_limited", i, a->jnt_limited[i], b->jnt_limited[i]);
    for (int k = 0; k < 2; ++k)
      diff.Compare("jnt_range", i, a->jnt_range[2 * i + k], b->jnt_range[2 * i + k]);
    // the limits' softness (MuJoCo's defaults where a joint has no limits)
    for (int k = 0; k < mjNREF; ++k)
      diff.Compare("jnt_solref", i, a->jnt_solref[mjNREF * i + k], b->jnt_solref[mjNREF * i + k]);
    for (int k = 0; k < mjNIMP; ++k)
      diff.Compare("jnt_solimp", i, a->jnt_solimp[mjNIMP * i + k], b->jnt_solimp[mjNIMP * i + k]);
    for (int k = 0; k < 3; ++k) {
      diff.Compare("jnt_xaxis", i, da->xaxis[3 * i + k], db->xaxis[3 * i + k]);
      diff.Compare("jnt_xanchor", i, da->xanchor[3 * i + k], db->xanchor[3 * i + k]);
    }
  }
  for (int i = 0; i < a->nv; ++i) {
    diff.Compare("dof_damping", i, a->dof_damping[i], b->dof_damping[i]);
    diff.Compare("dof_frictionloss", i, a->dof_frictionloss[i], b->dof_frictionloss[i]);
    diff.Compare("dof_armature", i, a->dof_armature[i], b->dof_armature[i]);
  }
  // drives, matched by joint: same gain (1: the control carries kp target - c qdot), bias (the
  // stiffness; no velocity term) and force limit; partsim's extra actuators (undriven joints)
  // must exert no force
  std::vector<int> raw_actuator_of_joint(b->njnt, -1);
  for (int k = 0; k < b->nu; ++k) raw_actuator_of_joint[b->actuator_trnid[2 * k]] = k;
  for (int k = 0; k < a->nu; ++k) {
    int r = raw_actuator_of_joint[a->actuator_trnid[2 * k]];
    const double* pa = a->actuator_biasprm + mjNBIAS * k;
    if (r < 0) {
      diff.Compare("undriven actuator bias", k, pa[1] + pa[2], 0.0);
      continue;
    }
    const double* pb = b->actuator_biasprm + mjNBIAS * r;
    diff.Compare("actuator gaintype", k, a->actuator_gaintype[k], b->actuator_gaintype[r]);
    diff.Compare("actuator biastype", k, a->actuator_biastype[k], b->actuator_biastype[r]);
    for (int c = 0; c < 3; ++c) {
      diff.Compare("actuator gainprm", k, a->actuator_gainprm[mjNGAIN * k + c],
                   b->actuator_gainprm[mjNGAIN * r + c]);
      diff.Compare("actuator biasprm", k, pa[c], pb[c]);
    }
    diff.Compare("actuator forcelimited", k, a->actuator_forcelimited[k],
                 b->actuator_forcelimited[r]);
    for (int c = 0; c < 2; ++c) {
      diff.Compare("actuator forcerange", k, a->actuator_forcerange[2 * k + c],
                   b->actuator_forcerange[2 * r + c]);
    }
  }
  mj_deleteData(da);
  mj_deleteData(db);
  return diff.mismatches;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int ParseCount(const char* flag, const char* value) {
  char* end = nullptr;
  long n = value ? std::strtol(value, &end, 10) : 0;
  if (!value || *end != '\0' || n < 1 || n > 100000) {
    std::fprintf(stderr, "%s needs a positive integer, got '%s'\n", flag, value ? value : "");
    std::exit(2);
  }
  return static_cast<int>(n);
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5, episodes = 10;
  bool print_mjcf = false, raw_only = false;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--reps") {
      reps = ParseCount("--reps", i + 1 < argc ? argv[++i] : nullptr);
    } else if (arg == "--episodes") {
      episodes = ParseCount("--episodes", i + 1 < argc ? argv[++i] : nullptr);
    } else if (arg == "--print-mjcf") {
      print_mjcf = true;
    } else if (arg == "--cpu-time") {
      g_cpu_clock = true;
    } else if (arg == "--raw-only") {
      raw_only = true;
    } else {
      std::fprintf(stderr,
                   "unknown argument '%s'\nusage: %s [--reps N] [--episodes N] [--print-mjcf] "
                   "[--raw-only] [--cpu-time]\n",
                   arg.c_str(), argv[0]);
      return 2;
    }
  }

  // raw MuJoCo on the hand-written model
  RawRun raw;
  mjModel* raw_m = LoadFromString(kRawMjcf);
  raw.m = raw_m;
  raw.d = mj_makeData(raw_m);
  raw.drawer_qposadr = raw_m->jnt_qposadr[mj_name2id(raw_m, mjOBJ_JOINT, "drawer")];
  std::array<int, 8> drive_joints;
  const char* drive_names[8] = {"x", "y", "z", "roll", "pitch", "yaw", "finger_1", "finger_2"};
  for (int i = 0; i < 8; ++i) drive_joints[i] = mj_name2id(raw_m, mjOBJ_JOINT, drive_names[i]);
  raw.SetDrives(drive_joints);

  // partsim; and, as a diagnostic, raw MuJoCo stepping a copy of partsim's compiled model
  // (the same physics bit for bit, so the difference is the API's own cost)
  std::unique_ptr<partsim::Scene> scene;
  partsim::Articulation gripper;
  partsim::Joint drawer;
  std::vector<char> initial;
  RawRun same;
  mjModel* same_m = nullptr;
  if (!raw_only) {
    partsim::SceneConfig config;
    config.timestep = kTimestep;
    config.solver_iterations = kSolverIterations;
    scene = std::make_unique<partsim::Scene>(config);
    partsim::Articulation cabinet = BuildCabinet(scene.get());
    gripper = BuildGripper(scene.get());
    drawer = cabinet.FindJointByName("drawer");
    initial = scene->Pack();
    if (print_mjcf) std::printf("%s\n", scene->GetMjcf().c_str());
    int mismatches = CompareModels(scene->GetMjModel(), raw_m);
    if (mismatches) {
      std::fprintf(stderr, "%d differences between partsim's model and the raw MJCF\n", mismatches);
      return 1;
    }
    same_m = mj_copyModel(nullptr, scene->GetMjModel());
    same.m = same_m;
    same.d = mj_makeData(same_m);
    // the joints come in the same order in both models (CompareModels checked it): the drawer
    // is the first, the gripper's follow; controls as partsim writes them (the same drive law)
    same.drawer_qposadr = same_m->jnt_qposadr[0];
    same.SetDrives(drive_joints);
  }

  std::printf(
      "drawer pulling: dt = %g s, %d steps per episode, %d episodes per repetition, "
      "%d repetitions, episodes interleaved, %s time\n",
      kTimestep, kSteps, episodes, reps, g_cpu_clock ? "thread CPU" : "wall-clock");
  std::printf("%4s %16s %16s %8s %16s\n", "rep", "raw [steps/s]", "partsim [steps/s]", "ratio",
              "raw on partsim's model");
  std::vector<double> raw_rate, partsim_rate, same_rate, ratio, same_ratio;
  double raw_opening = 0.0, partsim_opening = 0.0, same_opening = 0.0;
  bool ok = true;
  for (int r = 0; r < reps; ++r) {
    // episodes alternate between the runs (rotating which goes first), so that all see the
    // same background load
    double raw_seconds = 0.0, partsim_seconds = 0.0, same_seconds = 0.0;
    for (int e = 0; e < episodes; ++e) {
      for (int turn = 0; turn < 3; ++turn) {
        int which = (turn + e) % 3;
        if (which == 0) {
          EpisodeResult res = RunRawEpisode(raw);
          raw_seconds += res.seconds;
          raw_opening = res.opening;
          ok = ok && res.opening >= kMinOpening;
        } else if (which == 1 && !raw_only) {
          EpisodeResult res = RunPartsimEpisode(scene.get(), initial, &gripper, drawer);
          partsim_seconds += res.seconds;
          partsim_opening = res.opening;
          ok = ok && res.opening >= kMinOpening;
        } else if (which == 2 && !raw_only) {
          EpisodeResult res = RunRawEpisode(same);
          same_seconds += res.seconds;
          same_opening = res.opening;
        }
      }
    }
    raw_rate.push_back(episodes * kSteps / raw_seconds);
    if (!raw_only) {
      partsim_rate.push_back(episodes * kSteps / partsim_seconds);
      same_rate.push_back(episodes * kSteps / same_seconds);
      ratio.push_back(partsim_rate.back() / raw_rate.back());
      same_ratio.push_back(partsim_rate.back() / same_rate.back());
      std::printf("%4d %16.0f %16.0f %8.3f %16.0f\n", r, raw_rate.back(), partsim_rate.back(),
                  ratio.back(), same_rate.back());
    } else {
      std::printf("%4d %16.0f %16s %8s %16s\n", r, raw_rate.back(), "-", "-", "-");
    }
  }

  double raw_median = Median(raw_rate);
  std::printf("\n%-28s %14s %14s %14s\n", "", "raw MuJoCo", "partsim", "raw, partsim's");
  if (raw_only) {
    std::printf("%-28s %14.0f\n", "median steps/s", raw_median);
    std::printf("%-28s %14.7f\n", "final drawer opening [m]", raw_opening);
  } else {
    double partsim_median = Median(partsim_rate);
    std::printf("%-28s %14.0f %14.0f %14.0f\n", "median steps/s", raw_median, partsim_median,
                Median(same_rate));
    std::printf("%-28s %14.7f %14.7f %14.7f\n", "final drawer opening [m]", raw_opening,
                partsim_opening, same_opening);
    std::printf("%-28s %29.2e\n", "partsim - raw: opening [m]", partsim_opening - raw_opening);
    std::printf("%-28s %29.3f\n", "partsim / raw: of medians", partsim_median / raw_median);
    std::printf("%-28s %29.3f\n", "partsim / raw: median", Median(ratio));
    std::printf("%-28s %29.3f\n", "partsim / raw on its model", Median(same_ratio));
    // partsim grows its contact buffers (a recompile) when a step fills them: its model would
    // then no longer be the one compared above
    for (const partsim::Warning& w : scene->GetWarnings())
      std::fprintf(stderr, "partsim warning at t = %g s: %s\n", w.time, w.message.c_str());
    if (same_opening != partsim_opening) {
      std::fprintf(stderr,
                   "note: raw MuJoCo on partsim's model ended at %.9f m, partsim at %.9f m\n",
                   same_opening, partsim_opening);
    }
  }
  if (!ok) {
    std::fprintf(stderr, "FAILED: the drawer must open by at least %.2f m in every episode\n",
                 kMinOpening);
  }
  mj_deleteData(raw.d);
  mj_deleteModel(raw_m);
  if (same_m) {
    mj_deleteData(same.d);
    mj_deleteModel(same_m);
  }
  return ok ? 0 : 1;
}
