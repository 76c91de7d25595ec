// Motion planning: collision-free joint paths for an arm in the current scene (OMPL sampling
// planners, MuJoCo collision checking on a private copy of the scene), time-parameterised for
// the JointTrajectoryController. Joint vectors have one entry per planned joint, in the order
// the joints were given to the planner.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"
#include "partsim/robot/trajectory.h"

namespace partsim {

/// Settings of one planning request.
struct PlannerOptions {
  /// s of planning (OMPL solve); simplification gets up to 1 s more. A path whose timed
  /// trajectory leaves the free space is planned again, within this limit (twice at least).
  double time_limit = 2.0;
  double resolution = 0.01;  ///< rad or m: largest joint step between two checked states
  double clearance = 0.005;  ///< m: the arm keeps at least this far from the rest of the scene
  unsigned seed = 0;         ///< seed of the IK restarts of PlanToPose
  /// "RRTConnect", "RRT", "RRTstar", "PRM" or "KPIECE1"; anything else throws partsim::Error.
  std::string algorithm = "RRTConnect";
  bool simplify = true;  ///< shortcut and smooth the path found
  /// Plan against the snapshot of the last UpdateSnapshot() instead of taking one now. A server
  /// takes the snapshot on its simulation thread and plans on another: with this set, planning
  /// reads nothing of the live scene.
  bool use_last_snapshot = false;
  int ik_attempts = 8;  ///< PlanToPose: IK solutions tried (from the start, then random)
  /// When set, planning stops as soon as *cancel turns true (checked by OMPL's termination
  /// condition and between IK attempts) and fails with "cancelled". Must outlive the call.
  const std::atomic<bool>* cancel = nullptr;
};

/// Throws partsim::Error naming the first bad field: time_limit and resolution must be finite
/// and > 0, clearance finite and >= 0, algorithm one of those listed above.
void CheckPlannerOptions(const PlannerOptions& options);

/// What a planning request produced.
struct PlanResult {
  bool success = false;
  std::string message;                ///< why it failed (empty on success)
  std::vector<Eigen::VectorXd> path;  ///< joint waypoints from the start to the goal
  JointTrajectory trajectory;         ///< the path timed from 0, at rest at both ends
  double planning_time = 0.0;         ///< s of wall-clock time, IK and timing included
};

/// Plans for some joints of an articulation; the others stay where they are. Each plan starts
/// from the arm's current positions and checks collisions against a snapshot of the scene taken
/// when planning starts (other bodies are held where they are); the user's scene is not changed.
///
/// A state is valid when it lies within the joint limits, no link moved by the planned joints is
/// closer than `clearance` to a shape of another actor or articulation, and no two links whose
/// relative pose depends on the planned joints penetrate (pairs that cannot move relative to
/// each other, and parent-child pairs, are not checked).
class MotionPlanner {
 public:
  /// `joints`: planned joints (one dof each); empty means every active joint. Limits (rad/s,
  /// rad/s^2 or m/s, m/s^2), one per planned joint, time the trajectory; empty means 1 and 2.
  /// Throws partsim::Error naming an unknown joint, a joint without a dof or a bad limit.
  MotionPlanner(const Articulation& arm, const std::vector<std::string>& joints = {},
                const Eigen::VectorXd& velocity_limits = Eigen::VectorXd(),
                const Eigen::VectorXd& acceleration_limits = Eigen::VectorXd());
  ~MotionPlanner();
  MotionPlanner(const MotionPlanner&) = delete;
  MotionPlanner& operator=(const MotionPlanner&) = delete;

  const std::vector<std::string>& GetJointNames() const;
  /// Current positions of the planned joints.
  Eigen::VectorXd GetCurrentPositions() const;

  /// A path from the current positions to `goal` (one entry per planned joint). A goal outside
  /// the limits or in collision, a start in collision, or no path within the time limit gives
  /// success = false with a message. Throws partsim::Error on a wrong size or a non-finite goal.
  PlanResult PlanToJoints(const Eigen::VectorXd& goal,
                          const PlannerOptions& options = PlannerOptions());
  /// A path that brings frame `tcp_offset` of `link` to world pose `target`: IK solutions from
  /// the current positions and random restarts (up to options.ik_attempts), the collision-free
  /// one nearest to the start is planned to. Throws partsim::Error on an unknown link or a
  /// non-finite target.
  PlanResult PlanToPose(const std::string& link, const Pose& tcp_offset, const Pose& target,
                        const PlannerOptions& options = PlannerOptions());

  /// Whether planned-joint positions `q` are valid (limits, collisions with `clearance`) in the
  /// snapshot of the last plan (taken now if there is none yet). `reason`, when given, receives
  /// what is wrong.
  bool IsStateValid(const Eigen::VectorXd& q, double clearance = 0.005,
                    std::string* reason = nullptr);
  /// Takes a new snapshot of the scene for IsStateValid.
  void UpdateSnapshot();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace partsim
