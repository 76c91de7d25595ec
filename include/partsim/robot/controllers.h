// Robot controllers run from the step loop at a control rate below the physics rate, the way a
// real robot's controller runs: joint effort, joint position (PD), joint velocity, joint
// trajectory and end-effector (pose or twist through damped least-squares IK). The IMU, once
// declared here, has its own header, partsim/robot/imu.h, which this one includes.
//
// Like a real robot's, a controller can fail: a target it cannot reach (outside the joint
// limits, out of the arm's reach, or blocked for longer than its timeout) sets its status to
// kFailed with a message, instead of silently doing something else. Bad input (wrong sizes, NaN
// or infinite values) throws partsim::Error naming the controller and the entry, and leaves the
// controller and the scene as they were. Settings are checked where they take effect: the
// options when a controller is made, the settings a controller exposes as fields (speeds,
// tolerances, IK options) whenever a target is set and at every update; a setting out of range
// (a negative speed or gain, a NaN) throws partsim::Error naming the setting and its value.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"
#include "partsim/robot/imu.h"
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

/// Common settings of the joint controllers. Infinity is allowed where it means "no limit"
/// (force_limit, the tolerances, timeout).
struct JointControllerOptions {
  double control_rate = 100.0;       ///< Hz, finite, > 0; the controller updates every
                                     ///< round(1/(rate dt)) steps
  bool gravity_compensation = true;  ///< add the passive force (gravity, Coriolis) as qf
  double stiffness = 1e4;            ///< N/m or N m/rad, finite, >= 0: PD gain of the drives
  double damping = 1e3;              ///< N s/m or N m s/rad, finite, >= 0: PD gain of the drives
  double force_limit = kInf;         ///< N or N m, > 0, per joint; also clamps efforts
  double position_tolerance = 1e-2;  ///< rad or m, > 0, for kReached
  double velocity_tolerance = 5e-2;  ///< rad/s or m/s, > 0, for kReached
  double timeout = 5.0;              ///< s, > 0, without reaching the target before kFailed

  /// Throws partsim::Error naming the first setting out of its range above and its value
  /// ("`who`: control_rate must be finite and > 0, got -1").
  void Validate(const std::string& who) const;
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
  /// Throws partsim::Error naming a setting of this controller that is out of range, and its
  /// value. The options are checked once, by the constructor; controllers that expose settings
  /// as fields check them again where they are used (targets, updates).
  virtual void CheckSettings() const;
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
  double path_tolerance = 0.1;  ///< rad or m, > 0
  void SetTrajectory(const JointTrajectory& trajectory);
  /// A path without times: TimeParameterize with these limits, then follow it.
  void SetPath(const std::vector<Eigen::VectorXd>& path, const Eigen::VectorXd& velocity_limits,
               const Eigen::VectorXd& acceleration_limits);
  const JointTrajectory& GetTrajectory() const { return trajectory_.trajectory(); }
  /// The trajectory as it is followed, ready to sample (in seconds since it was set).
  const TrajectorySampler& GetSampler() const { return trajectory_; }
  void Update() override;
  /// The options, and path_tolerance > 0.
  void CheckSettings() const override;

 private:
  TrajectorySampler trajectory_;
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
  IkOptions ik;                        ///< IK settings used for pose targets (offset unused)
  double max_linear_speed = 0.5;       ///< m/s, > 0: pose targets are approached no faster
  double max_angular_speed = 1.5;      ///< rad/s, > 0
  double position_tolerance = 2e-3;    ///< m, > 0, of the measured frame, for kReached
  double rotation_tolerance = 1.5e-2;  ///< rad, > 0, of the measured frame, for kReached
  void SetTargetPose(const Pose& target, ControlFrame frame = ControlFrame::kWorld);
  /// Linear (m/s) and angular (rad/s) velocity, stacked; held until changed.
  void SetTargetTwist(const Eigen::Matrix<double, 6, 1>& twist,
                      ControlFrame frame = ControlFrame::kWorld);
  /// Current pose of the controlled frame (world).
  Pose GetEndEffectorPose() const;
  void Update() override;
  /// The options, the speeds and tolerances above (> 0) and the IK options (tolerances and
  /// max_step > 0, damping finite and >= 0, max_iterations >= 1, restarts >= 0, active empty or
  /// one entry per dof).
  void CheckSettings() const override;

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

}  // namespace partsim
