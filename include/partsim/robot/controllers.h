// Robot controllers run from the step loop at a control rate below the physics rate, the way a
// real robot's controller runs: joint effort, joint position (PD), joint velocity, joint
// trajectory and end-effector (pose or twist through damped least-squares IK); and an IMU.
//
// Like a real robot's, a controller can fail: a target it cannot reach (outside the joint
// limits, out of the arm's reach, or blocked for longer than its timeout) sets its status to
// kFailed with a message, instead of silently doing something else. Bad input (wrong sizes, NaN
// or infinite values) throws partsim::Error naming the controller and the entry, and leaves the
// controller and the scene as they were.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"
#include "partsim/robot/kinematics.h"
#include "partsim/robot/trajectory.h"

namespace partsim {

/// Where a controller stands.
enum class ControllerState {
  kIdle,     ///< no target yet
  kRunning,  ///< moving towards the target
  kReached,  ///< within tolerance of the target
  kFailed,   ///< the target cannot be reached (see message)
};
const char* ControllerStateName(ControllerState s);

struct ControllerStatus {
  ControllerState state = ControllerState::kIdle;
  std::string message;  ///< why it failed, or what was clamped
};

/// Common settings of the joint controllers.
struct JointControllerOptions {
  double control_rate = 100.0;       ///< Hz; the controller updates every round(1/(rate dt)) steps
  bool gravity_compensation = true;  ///< add the passive force (gravity, Coriolis) as qf
  double stiffness = 1e4;            ///< PD gains written to the joints' drives
  double damping = 1e3;
  double force_limit = kInf;         ///< per joint; also clamps efforts
  double position_tolerance = 1e-2;  ///< rad or m, for kReached
  double velocity_tolerance = 5e-2;  ///< rad/s or m/s, for kReached
  double timeout = 5.0;              ///< s without reaching the target before kFailed
};

/// Base class: a controller of some joints of one articulation.
class Controller {
 public:
  /// `joints`: names of the controlled joints (each with one dof); empty means every active
  /// joint. Throws partsim::Error naming an unknown joint or a joint without a dof.
  Controller(const Articulation& robot, const std::vector<std::string>& joints,
             const JointControllerOptions& options);
  virtual ~Controller() = default;

  const std::string& GetName() const { return name_; }
  void SetName(const std::string& name) { name_ = name; }
  int NumJoints() const { return static_cast<int>(dofs_.size()); }
  const std::vector<int>& GetDofs() const { return dofs_; }
  const std::vector<std::string>& GetJointNames() const { return joint_names_; }
  const JointControllerOptions& GetOptions() const { return options_; }
  const ControllerStatus& GetStatus() const { return status_; }
  Articulation GetRobot() const { return robot_; }
  /// Physics steps between two updates.
  int Period() const;
  /// Called by ControlLoop every Period() steps, before the physics steps.
  virtual void Update() = 0;
  /// Writes this controller's drive gains to its joints: PD (stiffness, damping) for position
  /// control, damping only for velocity control, none for efforts. The constructor and
  /// ControlLoop::Add call it, so that switching between controllers of the same joints
  /// switches the drives too.
  virtual void ConfigureDrives();

  /// Current positions and velocities of the controlled joints.
  Eigen::VectorXd GetQpos() const;
  Eigen::VectorXd GetQvel() const;

 protected:
  /// Throws partsim::Error unless v has NumJoints() finite entries.
  void CheckVector(const Eigen::VectorXd& v, const char* what) const;
  Articulation robot_;
  std::vector<int> dofs_;
  std::vector<std::string> joint_names_;
  JointControllerOptions options_;
  ControllerStatus status_;
  std::string name_;
};

/// Applies joint efforts (N m or N), clamped to +-force_limit and to each joint's own
/// effort_limit (URDF <limit effort>; the status message says which were clamped), plus gravity
/// compensation if enabled. The controlled
/// joints' drives are switched off. With no target yet it applies only the compensation; once
/// a target is set the status is kReached (there is nothing to wait for).
class JointEffortController : public Controller {
 public:
  JointEffortController(const Articulation& robot, const std::vector<std::string>& joints,
                        const JointControllerOptions& options);
  void SetTarget(const Eigen::VectorXd& effort);
  void Update() override;
  void ConfigureDrives() override;

 private:
  Eigen::VectorXd effort_;
};

/// PD position control through the joints' drives. A target outside the joint limits is clamped
/// to them and the status is kFailed (naming the joint): the robot goes as far as it can. Until
/// the first target it holds the position it had when constructed.
class JointPositionController : public Controller {
 public:
  JointPositionController(const Articulation& robot, const std::vector<std::string>& joints,
                          const JointControllerOptions& options);
  void SetTarget(const Eigen::VectorXd& q);
  Eigen::VectorXd GetTarget() const { return target_; }
  void Update() override;

 private:
  Eigen::VectorXd target_;
  double set_time_ = 0.0;  ///< scene time of the target (or of returning to it)
};

/// Velocity control through the joints' drives (stiffness 0, the given damping as gain). A
/// joint at a limit cannot keep moving: kFailed after `timeout` of not reaching the velocity.
class JointVelocityController : public Controller {
 public:
  JointVelocityController(const Articulation& robot, const std::vector<std::string>& joints,
                          const JointControllerOptions& options);
  void SetTarget(const Eigen::VectorXd& qd);
  void Update() override;
  void ConfigureDrives() override;

 private:
  Eigen::VectorXd target_;
  double ok_time_ = 0.0;  ///< last scene time the velocity was within tolerance (or set)
};

/// Follows a JointTrajectory (times from the moment it is set) with the drives' PD on the
/// interpolated position and velocity plus inverse-dynamics feed-forward. kReached at the end
/// within tolerance; kFailed when the tracking error exceeds `path_tolerance`, or a waypoint lies
/// outside the joint limits (then nothing moves).
class JointTrajectoryController : public Controller {
 public:
  JointTrajectoryController(const Articulation& robot, const std::vector<std::string>& joints,
                            const JointControllerOptions& options);
  double path_tolerance = 0.1;  ///< rad or m
  void SetTrajectory(const JointTrajectory& trajectory);
  /// A path without times: TimeParameterize with these limits, then follow it.
  void SetPath(const std::vector<Eigen::VectorXd>& path, const Eigen::VectorXd& velocity_limits,
               const Eigen::VectorXd& acceleration_limits);
  const JointTrajectory& GetTrajectory() const { return trajectory_; }
  void Update() override;

 private:
  JointTrajectory trajectory_;
  double start_time_ = 0.0;
  bool started_ = false;
};

/// Frame in which end-effector targets are given.
enum class ControlFrame { kWorld, kBase };

/// End-effector control: a target pose or twist of a frame on a link, turned into joint position
/// targets by damped least-squares IK each update. A pose target that InverseKinematics cannot
/// reach sets kFailed and leaves the robot where it is. A pose target is approached along a
/// commanded pose that moves at most max_linear_speed / max_angular_speed; kReached when the
/// measured frame is within position_tolerance and rotation_tolerance and the joints have
/// settled, kFailed if that has not happened `timeout` after the commanded pose arrived. A twist
/// beyond the speed limits is scaled down (said in the message); a twist that drives the frame
/// out of reach stops it there with kFailed.
class EndEffectorController : public Controller {
 public:
  /// `ee_link`: the link to move; `tcp`: the controlled frame on it.
  EndEffectorController(const Articulation& robot, const std::vector<std::string>& joints,
                        const std::string& ee_link, const Pose& tcp,
                        const JointControllerOptions& options);
  IkOptions ik;                        ///< IK settings used for pose targets
  double max_linear_speed = 0.5;       ///< m/s, pose targets are approached no faster
  double max_angular_speed = 1.5;      ///< rad/s
  double position_tolerance = 2e-3;    ///< m, of the measured frame, for kReached
  double rotation_tolerance = 1.5e-2;  ///< rad, of the measured frame, for kReached
  void SetTargetPose(const Pose& target, ControlFrame frame = ControlFrame::kWorld);
  /// Linear (m/s) and angular (rad/s) velocity, stacked; held until changed.
  void SetTargetTwist(const Eigen::Matrix<double, 6, 1>& twist,
                      ControlFrame frame = ControlFrame::kWorld);
  /// Current pose of the controlled frame (world).
  Pose GetEndEffectorPose() const;
  void Update() override;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

/// Runs controllers from the step loop: Step(n) advances the scene n physics steps and updates
/// each controller every Period() steps (a controller's first update happens at the first step).
class ControlLoop {
 public:
  explicit ControlLoop(Scene* scene);
  void Add(std::shared_ptr<Controller> controller);
  void Remove(const std::shared_ptr<Controller>& controller);
  void Step(int n = 1);
  /// Steps until all controllers are kReached, kFailed or kIdle, or `max_seconds` pass;
  /// returns whether they all are and none failed.
  bool RunUntilDone(double max_seconds);
  Scene* GetScene() const { return scene_; }

 private:
  struct Entry {
    std::shared_ptr<Controller> controller;
    long long next_update;  ///< step count of its next update
  };
  Scene* scene_;
  std::vector<Entry> entries_;
  long long step_count_ = 0;
};

/// What an IMU reads, in its own frame.
struct ImuReading {
  Eigen::Vector4d orientation;          ///< quaternion wxyz of the sensor in the world
  Eigen::Vector3d linear_acceleration;  ///< proper acceleration (m/s^2): +9.81 up at rest
  Eigen::Vector3d angular_velocity;     ///< rad/s
  double time = 0.0;                    ///< simulation time of the reading
};

/// An inertial measurement unit fixed to a link or an actor at `local_pose`.
class Imu {
 public:
  Imu(const Link& link, const Pose& local_pose = Pose());
  Imu(const Actor& actor, const Pose& local_pose = Pose());
  /// Reading at the current state (after the last step).
  ImuReading Read() const;

 private:
  Scene* scene_;
  bool is_link_;
  int articulation_id_ = -1, link_index_ = -1, actor_id_ = -1;
  Pose local_pose_;
};

}  // namespace partsim
