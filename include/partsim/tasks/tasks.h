// The SAPIEN paper's two interaction tasks, drawer pulling and door opening, on generated
// StorageFurniture cabinets or on PartNet-Mobility folders (real or generated) with the flying
// gripper; and the heuristic solvers of the paper.
//
// World layout: the cabinet stands with its base on z = 0 and its front facing +x, centred on
// the origin; the gripper starts in front of it (x > 0); three cameras look at the cabinet from
// the left, the right and the front.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "partsim/assets/partnet_mobility.h"
#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"
#include "partsim/render/camera.h"
#include "partsim/robot/robots.h"

namespace partsim {

enum class TaskType { kPullDrawer, kOpenDoor };
const char* TaskTypeName(TaskType t);  ///< "drawer" or "door"
/// "drawer" or "door"; throws partsim::Error naming anything else.
TaskType ParseTaskType(const std::string& name);

/// The semantics.txt label of the task's target parts: "drawer" or "rotation_door".
const char* TaskTargetLabel(TaskType t);

/// Settings of a task.
struct TaskOptions {
  TaskType type = TaskType::kPullDrawer;
  int object_index = 0;            ///< index of the StorageFurniture object in the generator
  std::uint64_t dataset_seed = 0;  ///< generator seed
  /// A PartNet-Mobility folder (real or generated) to use instead of the generator's object;
  /// "" uses object_index and dataset_seed.
  std::string object_folder;
  int target = -1;  ///< which drawer (door) of the object, in link order; -1: drawn by Reset's seed
  std::string asset_dir;  ///< where the object's folder is written; "" = <tmp>/partsim-assets
  bool cameras = true;    ///< add the left, right and front cameras
  int camera_width = 320;
  int camera_height = 240;
  std::string render_backend = "rasterizer";
  double timestep = 1.0 / 500.0;  ///< physics step (s)
  double control_rate = 50.0;     ///< Hz; Step() advances one control period
  double max_seconds = 20.0;      ///< episode length before truncation (s)
  double success_fraction = 0.9;  ///< of the joint's range, for success
  bool init_on_handle = false;    ///< Reset() places the gripper, closed, on the handle
  /// Both > 0: the scene also gets a camera "video" of this size (pixels) with a three-quarter
  /// view of the cabinet, a floor that only cameras see (no contact: the dynamics are those of
  /// a task without it) and shadows from the key light. For recording (GetVideoCamera); the
  /// solvers do not perceive through it.
  int video_width = 0;
  int video_height = 0;
  /// The cabinet's links never collide with each other: its base is fixed and its doors and
  /// drawers move along their joints only (joint limits, not contacts, stop them), yet their
  /// collision pairs (neighbouring panels' bounding volumes overlap) cost most of the collision
  /// detection. The gripper still collides with every link. One thing it does change: a part
  /// that another part blocks (a drawer behind a closed door, in some real objects) passes
  /// through it; set false for such objects. On by default (the tasks' speed, issue 18); the
  /// heuristic solvers' results on the generated cabinets are the same either way.
  bool filter_collisions = true;
  /// Collision meshes of the cabinet whose vertices are the corners of an axis-aligned box (the
  /// generator's panels, frames and bar handles) collide as boxes: the engine's box collider
  /// instead of the general convex one. Masses and inertias are the links' own (the URDF's),
  /// unchanged. On by default (the tasks' speed, issue 18).
  bool box_primitives = true;
};

/// Candidate objects: the first `count` StorageFurniture indices (from 0) whose object has at
/// least one drawer (door) with a handle.
std::vector<int> FindTaskObjects(TaskType type, int count, std::uint64_t dataset_seed = 0);

/// The task's targets in a PartNet-Mobility object: ids N of the links link_N whose semantics
/// label is TaskTargetLabel(type), that move along a joint with a finite range and that carry a
/// handle (a part or visual named "handle"), in id order. TaskOptions::target indexes this list.
std::vector<int> FindTaskTargets(const PartNetMobilityObject& object, TaskType type);

/// A door-opening or drawer-pulling episode: scene, cabinet, flying gripper, cameras.
///
/// Actions (SetAction / the 7-vector of ApplyAction): the gripper's TCP twist in the world frame
/// (linear m/s, angular rad/s), followed by the gripper command in [-1, 1] (-1 close, 1 open).
/// Linear speed is clamped to 1 m/s and angular to 3 rad/s (documented clamp); NaN, infinite or
/// wrongly sized actions throw partsim::Error and change nothing.
class ArticulationTask {
 public:
  explicit ArticulationTask(const TaskOptions& options);
  ~ArticulationTask();
  ArticulationTask(const ArticulationTask&) = delete;
  ArticulationTask& operator=(const ArticulationTask&) = delete;

  /// Starts a new episode: the same cabinet, joints closed, the target chosen by `seed` (unless
  /// options.target is set), the gripper open at a pose drawn from `seed` in front of the
  /// cabinet (or on the handle with init_on_handle).
  void Reset(std::uint64_t seed);
  const TaskOptions& GetOptions() const;

  Scene& GetScene();
  /// The scene, shared (it outlives the task while held).
  std::shared_ptr<Scene> GetSharedScene() const;
  const RobotModel& GetRobotModel() const;
  Articulation GetRobot() const;
  Articulation GetObject() const;
  /// The target door or drawer: its link, its joint, its semantic label and render entity id.
  Link GetTargetLink() const;
  Joint GetTargetJoint() const;
  /// Names of the target's candidates (links with the task's label and a handle).
  std::vector<std::string> GetTargetCandidates() const;
  /// Render visual ids of the target's handle pieces.
  std::vector<uint32_t> GetHandleVisualIds() const;
  uint32_t GetTargetEntityId() const;

  /// Fraction of the joint's range opened, from its closed end (0) to its far end (1).
  double GetProgress() const;
  /// Progress reached options.success_fraction.
  bool IsSuccess() const;
  /// The joint moved the wrong way past its closed end by more than 2% of the range (only
  /// possible for joints whose closed end is not a limit).
  bool IsFailure() const;
  /// Simulated seconds since Reset; truncated when past options.max_seconds.
  double GetElapsed() const;
  bool IsTruncated() const;

  // --- the robot ---
  /// World pose of the tool centre point.
  Pose GetTcpPose() const;
  /// TCP linear and angular velocity (world).
  Eigen::Matrix<double, 6, 1> GetTcpVelocity() const;
  /// Moves the hand towards a world pose (position control of the six arm joints; the closed
  /// form inverse kinematics of the flying gripper).
  void SetTcpTarget(const Pose& target);
  /// Moves the hand with a world twist (velocity control), held until changed.
  void SetTcpVelocity(const Eigen::Matrix<double, 6, 1>& twist);
  /// Finger opening as a fraction: 1 fully open, 0 closed (clamped to [0, 1]).
  void SetGripper(double fraction);
  /// Current opening of the fingers, 0..1.
  double GetGripperOpening() const;
  /// Whether a finger touches the target link (handle or panel).
  bool GripperTouchesTarget() const;
  /// Applies a 7-vector action (see the class comment).
  void ApplyAction(const Eigen::VectorXd& action);
  /// Advances one control period (options.timestep steps at options.control_rate).
  void Step();

  // --- observations ---
  /// Renders the cameras (left, right, front) at the current state.
  void TakePictures();
  std::vector<Camera> GetCameras() const;
  Camera GetCamera(const std::string& name) const;
  /// The "video" camera of TaskOptions::video_width; throws partsim::Error when the task has
  /// none.
  Camera GetVideoCamera() const;
  /// raw: qpos and qvel of the cabinet, then the TCP pose (p, wxyz), TCP twist and gripper
  /// opening.
  Eigen::VectorXd GetRawObservation() const;
  /// mobility: the target joint's axis origin (3) and direction (3) in the world, the target
  /// part's average outward normal (3), joint position and velocity (2), then the robot state as
  /// in raw.
  Eigen::VectorXd GetMobilityObservation() const;
  /// Dense reward of the last Step: 10 x progress gained, +1 per step at success, -0.1 per step
  /// that the fingers do not touch the target after they have touched it in this episode (the
  /// gripper fell off the handle), minus 0.5 x the TCP's distance to the handle while it has not
  /// been touched.
  double GetReward() const;

  // Internals used by the solvers; not part of the stable API.
  struct Impl;
  Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// ApplyAction(actions.row(i)) and Step() of every task, in parallel: task 0 on the calling
/// thread, each other on a thread of its own, each holding its scene (Scene::Use) meanwhile.
/// `actions` is tasks.size() x 7; a wrong shape, a non-finite entry or a task given twice
/// throws partsim::Error before any task moves. Call it from a thread that holds none of the
/// tasks' scenes.
void StepTasks(const std::vector<ArticulationTask*>& tasks, const Eigen::MatrixXd& actions);

/// Outcome of a heuristic solver run.
struct SolverResult {
  bool success = false;
  double progress = 0.0;  ///< final fraction of the range
  double seconds = 0.0;   ///< simulated time used
  std::string stage;      ///< stage reached ("perceive", "grasp", "pull", "open", "done")
  std::string message;    ///< why it failed
};

/// Options of the heuristic solvers.
struct SolverOptions {
  bool use_cameras = true;  ///< perceive the handle from the segmented point clouds (else the
                            ///< handle's mesh from the scene: ground-truth geometry)
  /// Write the recording camera's colour as frame_NNNNN.png every `frame_every` control steps:
  /// the task's "video" camera when it has one (TaskOptions::video_width), else "front".
  std::string frames_dir;
  /// Write the same frames as an H.264 MP4 (VideoWriter) at control_rate / frame_every frames
  /// per second, i.e. in real time; "" for none.
  std::string video_path;
  int frame_every = 10;
};

/// The paper's drawer heuristic: find the handle in the segmented point cloud, grasp it, close
/// the gripper, pull along the joint axis with a velocity controller.
SolverResult SolvePullDrawer(ArticulationTask& task, const SolverOptions& options = {});
/// The paper's door heuristic: grasp the handle, open a little, then follow the door with
/// position-based visual servoing (the door's angle measured from its segmented points) while
/// turning about the hinge; re-grasps when the grip is lost.
SolverResult SolveOpenDoor(ArticulationTask& task, const SolverOptions& options = {});
/// The solver of the task's type.
SolverResult SolveTask(ArticulationTask& task, const SolverOptions& options = {});

}  // namespace partsim
