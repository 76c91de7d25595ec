// A robot served to network clients, shared by the protocol front-ends (rosbridge, native ROS 1):
// its controllers and the commands that switch between them, trajectory goals with tolerances
// and an outcome (what ROS's follow_joint_trajectory action reports), motion planning off the
// simulation thread, the readings the front-ends publish (joint states, frames, cameras, IMU)
// and the schedule of the sensor topics (SensorSchedule). Commands are checked on the caller's
// thread and applied on the simulation thread between two steps, so several front-ends can drive
// one robot at once without racing.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"
#include "partsim/planning/planner.h"
#include "partsim/render/camera.h"
#include "partsim/robot/controllers.h"
#include "partsim/server/sim_server.h"

namespace partsim {

struct ServedRobotOptions {
  double control_rate = 0.0;  ///< Hz of the robot controllers; 0: every physics step
  /// Hz (simulated time) of the camera topics; 0: every step. Front-ends render a camera only
  /// while a client listens to it, and at most once per step whoever asks.
  double camera_rate = 10.0;
  double imu_rate = 0.0;  ///< Hz (simulated time) of the IMU topic; 0: every step
  /// Link of the robot carrying the IMU; empty: the robot's last link (its end effector).
  std::string imu_link;
  /// Link whose pose end-effector planning goals name; empty: the robot's last link.
  std::string ee_link;
  Pose tcp_in_ee;  ///< the tool centre point in ee_link's frame: what pose goals place
};

/// One joint-state sample of every articulation's active joints.
struct JointStateReading {
  std::vector<std::string> names;
  std::vector<double> position, velocity, effort;
};

/// A frame of the scene in the world frame ("world"): every link of every articulation, and
/// each camera's optical frame (x right, y down, z forward, the ROS camera convention).
struct FrameReading {
  std::string child;
  Pose pose;
};

/// A camera of the scene as the front-ends publish it.
struct CameraSensor {
  Camera camera;
  std::string name;   ///< topics /<name>/image_raw, /<name>/camera_info, /<name>/points
  std::string frame;  ///< <name>_optical_frame
};

/// Most points a trajectory command from the network may have (a minute at 100 Hz is 6,000):
/// the rosbridge server and the ROS 1 bridge refuse more before converting any.
constexpr size_t kMaxTrajectoryPoints = 10000;

/// Longest planning time_limit (s) a served robot accepts.
constexpr double kMaxPlanSeconds = 30.0;

/// Plans one owner (a network client) may have waiting or running at once.
constexpr size_t kMaxPlansPerOwner = 2;

/// Plans waiting or running at once, all owners together.
constexpr size_t kMaxPlans = 8;

/// Latest time_from_start (s) a trajectory point may have: a day.
constexpr double kMaxTrajectorySeconds = 86400.0;

/// A trajectory as ROS messages carry it: joints by name (a subset of the robot's, in any
/// order; the others hold where they are), points with times from the start (at most
/// kMaxTrajectorySeconds).
struct TrajectoryCommand {
  std::vector<std::string> joint_names;
  std::vector<double> times;
  std::vector<std::vector<double>> positions;
  std::vector<std::vector<double>> velocities;  ///< empty, or one per point
  /// Tolerances of follow_joint_trajectory, by joint name; 0 or absent: the default.
  std::vector<std::pair<std::string, double>> path_tolerance, goal_tolerance;
  double goal_time_tolerance = 0.0;  ///< s after the last point; 0: the controller's timeout
};

/// How a trajectory goal ended (the codes of control_msgs/FollowJointTrajectoryResult).
enum class TrajectoryOutcome {
  kSucceeded = 0,
  kInvalidGoal = -1,
  kInvalidJoints = -2,
  kPathToleranceViolated = -4,
  kGoalToleranceViolated = -5,
  kPreempted = 1,  ///< replaced by another command or cancelled (not an error code in ROS)
};

/// Progress of a running trajectory goal, sampled on the simulation thread.
struct TrajectoryFeedback {
  double time = 0.0;  ///< simulation time
  std::vector<std::string> joint_names;
  Eigen::VectorXd desired, actual, error;  ///< positions (error = desired - actual)
  Eigen::VectorXd desired_velocity, actual_velocity;
};

/// A planning request from the network: a joint goal, or a pose goal for the end-effector link.
struct PlanRequest {
  std::vector<double> joint_goal;  ///< one per commanded joint; empty: use `pose_goal`
  Pose pose_goal;
  bool execute = true;  ///< run the plan through the trajectory controller when found
  /// PlannerOptions::cancel is ignored: each plan has a cancel flag of its own (CancelPlans).
  PlannerOptions options;
  /// Who asks (a front-end's client), for the per-owner bound and CancelPlans; never
  /// dereferenced. Null: bounded only by kMaxPlans.
  const void* owner = nullptr;
};

/// Counters of the commands applied, for the front-ends' statistics.
struct CommandStats {
  long long commands = 0;
  double mean_latency_steps = 0.0;  ///< steps between a command's arrival and its application
  long long max_latency_steps = 0;
};

class ServedRobot {
 public:
  using ErrorSink = std::function<void(const std::string& message)>;
  using DoneCallback = std::function<void(TrajectoryOutcome outcome, const std::string& message)>;
  using FeedbackCallback = std::function<void(const TrajectoryFeedback& feedback)>;
  using PlanCallback = std::function<void(const PlanResult& result)>;

  /// Adds the robot's position controller to `loop` (holding the current pose) and the
  /// SimServer step callback that finishes trajectory goals; call before sim->Start(). The
  /// cameras are the scene's at construction. All pointers must outlive this object, and the
  /// SimServer must be stopped before it is destroyed.
  ServedRobot(SimServer* sim, Scene* scene, ControlLoop* loop, const Articulation& robot,
              const std::string& name, const ServedRobotOptions& options = {});
  ~ServedRobot();
  ServedRobot(const ServedRobot&) = delete;
  ServedRobot& operator=(const ServedRobot&) = delete;

  const std::string& GetName() const { return name_; }
  SimServer* GetSim() const { return sim_; }
  Scene* GetScene() const { return scene_; }
  const Articulation& GetRobot() const { return robot_; }
  const ServedRobotOptions& GetOptions() const { return options_; }
  /// The commanded joints (every active joint of the robot), in command order.
  const std::vector<std::string>& GetJointNames() const;

  // ---- commands: checked here (partsim::Error naming `what`), applied between steps ----
  /// Joint positions, velocities or efforts, one per commanded joint. Errors found when the
  /// command is applied (none expected) go to `on_error`.
  void CommandPositions(const std::vector<double>& values, const std::string& what,
                        ErrorSink on_error = {});
  void CommandVelocities(const std::vector<double>& values, const std::string& what,
                         ErrorSink on_error = {});
  void CommandEfforts(const std::vector<double>& values, const std::string& what,
                      ErrorSink on_error = {});
  /// Throws partsim::Error naming `what` and the fault if `command` is malformed (unknown or
  /// repeated joints, counts that do not match, non-finite values, times not increasing).
  void CheckTrajectory(const TrajectoryCommand& command, const std::string& what) const;
  /// Starts a trajectory (replacing any running goal, whose `on_done` reports kPreempted).
  /// Throws for malformed input; a well-formed goal the controller refuses (a waypoint outside
  /// the joint limits) ends through `on_done` with kInvalidGoal. `on_feedback` runs on the
  /// simulation thread at the control rate while the goal runs. Returns the goal's id.
  long long CommandTrajectory(const TrajectoryCommand& command, const std::string& what,
                              DoneCallback on_done = {}, FeedbackCallback on_feedback = {});
  /// Stops goal `id` if it still runs: the robot holds where it is, on_done gets kPreempted.
  void CancelTrajectory(long long id);
  /// Plans from the current state (snapshot taken on the simulation thread, planning on a
  /// worker thread, so the simulation keeps its pace) and, if asked and found, executes the
  /// trajectory as a goal. `on_result` runs on the worker thread. Throws for a malformed
  /// request (wrong number of joints, non-finite values, bad options), and when the owner
  /// already has kMaxPlansPerOwner plans waiting or running, or kMaxPlans are in all.
  void Plan(const PlanRequest& request, PlanCallback on_result, DoneCallback on_done = {});
  /// Cancels the plans of `owner` (a client that left): those waiting are dropped, the one
  /// running stops within milliseconds; each one's `on_result` reports success = false with
  /// the message "cancelled" (the dropped ones' on this thread), and none executes.
  void CancelPlans(const void* owner);
  /// Stops the planning worker: a plan in progress finishes (its callbacks run), plans not yet
  /// started are dropped. Call after stopping the SimServer and before destroying the
  /// front-ends whose callbacks plans hold. Idempotent; the destructor calls it.
  void Close();
  CommandStats GetCommandStats() const;

  // ---- readings (simulation thread: from step callbacks or posted commands) ----
  JointStateReading ReadJointStates() const;
  std::vector<FrameReading> ReadFrames() const;
  std::vector<CameraSensor>& GetCameras() { return cameras_; }
  const std::vector<CameraSensor>& GetCameras() const { return cameras_; }
  /// Camera `i` pictured at the current step (Color and Position: images and point clouds):
  /// renders it unless it already was this step.
  const Camera& TakePicture(size_t i);
  /// The IMU (null when the robot has no links) and its frame.
  const Imu* GetImu() const { return imu_.get(); }
  const std::string& GetImuFrame() const { return imu_frame_; }

  struct Impl;

 private:
  std::string name_;
  SimServer* sim_;
  Scene* scene_;
  Articulation robot_;
  ServedRobotOptions options_;
  std::vector<CameraSensor> cameras_;
  std::unique_ptr<Imu> imu_;
  std::string imu_frame_;
  std::unique_ptr<Impl> impl_;
};

/// A sensor stream the front-ends publish: the IMU (/imu), or one of a camera's topics
/// (/<camera>/image_raw, /<camera>/points, /<camera>/camera_info).
enum class SensorStream { kImu, kImage, kPoints, kCameraInfo };

/// The topic of a sensor stream of `robot`; `camera` indexes robot.GetCameras() (unused for
/// kImu).
std::string SensorTopic(const ServedRobot& robot, SensorStream stream, size_t camera = 0);

/// One front-end's schedule of sensor messages, in simulated time: the IMU every 1/imu_rate s,
/// each camera's picture (image_raw and points) and its camera_info every 1/camera_rate s
/// (every step for a rate of 0), each only while a client listens to it. Each front-end keeps a
/// schedule of its own (their listeners differ); a camera pictured for several at one step is
/// rendered once (ServedRobot::TakePicture).
class SensorSchedule {
 public:
  /// Whether some client listens to `stream` (of camera `camera`) now.
  using Listened = std::function<bool(SensorStream stream, size_t camera)>;
  /// What a front-end publishes of the readings due (all called on the simulation thread).
  struct Output {
    std::function<void(const ImuReading& reading)> imu;
    /// Camera `camera` pictured at this step (Color and Position); `image` and `points`: which
    /// of its two picture topics are due.
    std::function<void(size_t camera, const Camera& pictured, bool image, bool points)> picture;
    /// camera_info of camera `camera` (its intrinsics; no picture is taken).
    std::function<void(size_t camera, const Camera& camera_model)> camera_info;
  };

  /// `robot` must outlive the schedule.
  explicit SensorSchedule(ServedRobot* robot);
  /// After a step, at simulation time `t` (s): asks `listened` about the streams whose time has
  /// come, reads those listened to (taking pictures as needed), hands them to `out`, and sets
  /// their next time.
  void Publish(double t, const Listened& listened, const Output& out);

 private:
  struct CameraTimes {
    double next_picture = 0, next_info = 0;  // simulated time of the next message
  };
  ServedRobot* robot_;
  double imu_next_ = 0;
  std::vector<CameraTimes> cameras_;  // one per robot->GetCameras()
};

// ---- message payloads shared by the front-ends ----
/// The camera's colour picture as packed 8-bit RGB rows (sensor_msgs/Image "rgb8").
std::vector<uint8_t> CameraRgb8(const Camera& camera);
/// The points the camera sees, in its optical frame, as x, y, z float32 triples.
std::vector<float> CameraOpticalPoints(const Camera& camera);
/// The 3x4 projection matrix P = [K | 0] of sensor_msgs/CameraInfo, row-major.
std::vector<double> CameraProjection(const Camera& camera);

}  // namespace partsim
