// Joint and end-effector controllers and the control loop that runs them from the step loop.
// Each controller writes only its own dofs: drive targets per joint, and its entries of qf
// (read, modified and written back) so that several controllers can share one robot.
#include "partsim/robot/controllers.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "partsim/core/check.h"
#include "partsim/core/error.h"

namespace partsim {

const char* ControllerStateName(ControllerState s) {
  switch (s) {
    case ControllerState::kIdle:
      return "idle";
    case ControllerState::kRunning:
      return "running";
    case ControllerState::kReached:
      return "reached";
    case ControllerState::kFailed:
      return "failed";
  }
  return "unknown";
}

namespace {

// index of the entry of largest magnitude
int Worst(const Eigen::VectorXd& v) {
  Eigen::Index i = 0;
  if (v.size()) v.cwiseAbs().maxCoeff(&i);
  return static_cast<int>(i);
}

bool Done(ControllerState s) {
  return s == ControllerState::kReached || s == ControllerState::kFailed ||
         s == ControllerState::kIdle;
}

// Checks of one setting: each throws naming `who`, the setting and its value. NaN fails all.
void CheckPositive(const std::string& who, const char* setting, double value) {
  if (!(value > 0)) throw Error(who + ": " + setting + " must be > 0, got " + FormatNumber(value));
}

void CheckFinitePositive(const std::string& who, const char* setting, double value) {
  if (!(value > 0) || !std::isfinite(value))
    throw Error(who + ": " + setting + " must be finite and > 0, got " + FormatNumber(value));
}

void CheckFiniteNonNegative(const std::string& who, const char* setting, double value) {
  if (!(value >= 0) || !std::isfinite(value))
    throw Error(who + ": " + setting + " must be finite and >= 0, got " + FormatNumber(value));
}

}  // namespace

void JointControllerOptions::Validate(const std::string& who) const {
  CheckFinitePositive(who, "control_rate", control_rate);
  CheckFiniteNonNegative(who, "stiffness", stiffness);
  CheckFiniteNonNegative(who, "damping", damping);
  CheckPositive(who, "force_limit", force_limit);
  CheckPositive(who, "position_tolerance", position_tolerance);
  CheckPositive(who, "velocity_tolerance", velocity_tolerance);
  CheckPositive(who, "timeout", timeout);
}

// ---------------------------------------------------------------------------------------------
// Controller

Controller::Controller(const Articulation& robot, const std::vector<std::string>& joints,
                       const JointControllerOptions& options)
    : robot_(robot), options_(options), name_("controller") {
  const std::string who = "controller of '" + robot.GetName() + "'";
  if (robot.IsKinematic())
    throw Error(who + ": the articulation is kinematic; controllers drive dynamic ones");
  options.Validate(who + ": options");
  if (joints.empty()) {
    for (const Joint& j : robot.GetActiveJoints()) {
      dofs_.push_back(j.GetDofIndex());
      joint_names_.push_back(j.GetName());
    }
  } else {
    for (const std::string& n : joints) {
      Joint j = robot.FindJointByName(n);  // throws naming a missing joint
      if (j.GetDof() != 1)
        throw Error(who + ": joint '" + n + "' has no degree of freedom (fixed)");
      if (std::find(joint_names_.begin(), joint_names_.end(), n) != joint_names_.end())
        throw Error(who + ": joint '" + n + "' is listed twice");
      dofs_.push_back(j.GetDofIndex());
      joint_names_.push_back(n);
    }
  }
  if (dofs_.empty()) throw Error(who + ": no joint to control");
}

int Controller::Period() const {
  double dt = robot_.GetScene()->GetTimestep();
  return std::max(1, static_cast<int>(std::lround(1.0 / (options_.control_rate * dt))));
}

Eigen::VectorXd Controller::GetQpos() const {
  Eigen::VectorXd all = robot_.GetQpos(), out(NumJoints());
  for (int i = 0; i < NumJoints(); ++i) out[i] = all[dofs_[i]];
  return out;
}

Eigen::VectorXd Controller::GetQvel() const {
  Eigen::VectorXd all = robot_.GetQvel(), out(NumJoints());
  for (int i = 0; i < NumJoints(); ++i) out[i] = all[dofs_[i]];
  return out;
}

void Controller::CheckSettings() const { options_.Validate(name_ + ": options"); }

void Controller::CheckVector(const Eigen::VectorXd& v, const char* what) const {
  if (v.size() != NumJoints())
    throw Error(name_ + ": " + what + " has " + std::to_string(v.size()) + " entries, expected " +
                std::to_string(NumJoints()) + " (one per controlled joint)");
  for (int i = 0; i < NumJoints(); ++i)
    if (!std::isfinite(v[i]))
      throw Error(name_ + ": " + what + "[" + std::to_string(i) + "] (joint '" + joint_names_[i] +
                  "') is not finite");
}

namespace {

// Drive gains on the controlled joints.
void SetGains(Articulation& robot, const std::vector<std::string>& joints, double stiffness,
              double damping, double force_limit) {
  for (const std::string& n : joints)
    robot.FindJointByName(n).SetDriveProperty(stiffness, damping, force_limit);
}

// Position and velocity targets of the controlled joints' drives.
void SetTargets(Articulation& robot, const std::vector<std::string>& joints,
                const Eigen::VectorXd& q, const Eigen::VectorXd* qd) {
  for (size_t i = 0; i < joints.size(); ++i) {
    Joint j = robot.FindJointByName(joints[i]);
    j.SetDriveTarget(q[static_cast<Eigen::Index>(i)]);
    j.SetDriveVelocityTarget(qd ? (*qd)[static_cast<Eigen::Index>(i)] : 0.0);
  }
}

// Writes `f` (one per controlled joint) into the controlled dofs of qf, plus the passive force
// (gravity, Coriolis) on them when `compensate`; other dofs keep their values.
void WriteQf(Articulation& robot, const std::vector<int>& dofs, const Eigen::VectorXd& f,
             bool compensate) {
  Eigen::VectorXd qf = robot.GetQf();
  Eigen::VectorXd passive;
  if (compensate) passive = robot.ComputePassiveForce(true, true);
  for (size_t i = 0; i < dofs.size(); ++i)
    qf[dofs[i]] = f[static_cast<Eigen::Index>(i)] + (compensate ? passive[dofs[i]] : 0.0);
  robot.SetQf(qf);
}

// Limits of the controlled joints, n x 2.
Eigen::MatrixX2d ControlledLimits(const Articulation& robot, const std::vector<int>& dofs) {
  Eigen::MatrixX2d all = robot.GetQlimits(), out(dofs.size(), 2);
  for (size_t i = 0; i < dofs.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = all.row(dofs[i]);
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// JointEffortController

JointEffortController::JointEffortController(const Articulation& robot,
                                             const std::vector<std::string>& joints,
                                             const JointControllerOptions& options)
    : Controller(robot, joints, options) {
  name_ = "JointEffortController of '" + robot.GetName() + "'";
  JointEffortController::ConfigureDrives();
}

void JointEffortController::ConfigureDrives() {
  SetGains(robot_, joint_names_, 0.0, 0.0, kInf);  // the drives must not fight the efforts
}

void JointEffortController::SetTarget(const Eigen::VectorXd& effort) {
  CheckVector(effort, "effort");
  effort_ = effort;
  std::string clamped;
  for (int i = 0; i < NumJoints(); ++i) {
    // the controller's bound, and the joint's own actuator limit (URDF <limit effort>)
    const double limit = std::min(options_.force_limit,
                                  robot_.FindJointByName(joint_names_[i]).GetDesc().effort_limit);
    if (std::abs(effort_[i]) <= limit) continue;
    clamped += (clamped.empty() ? "" : ", ") + joint_names_[i] + " (" + FormatNumber(effort_[i]) +
               " to +-" + FormatNumber(limit) + ")";
    effort_[i] = std::clamp(effort_[i], -limit, limit);
  }
  status_.state = ControllerState::kReached;
  status_.message = clamped.empty() ? "" : "efforts clamped: " + clamped;
}

void JointEffortController::Update() {
  Eigen::VectorXd f = effort_.size() ? effort_ : Eigen::VectorXd::Zero(NumJoints());
  WriteQf(robot_, dofs_, f, options_.gravity_compensation);
}

// ---------------------------------------------------------------------------------------------
// JointPositionController

JointPositionController::JointPositionController(const Articulation& robot,
                                                 const std::vector<std::string>& joints,
                                                 const JointControllerOptions& options)
    : Controller(robot, joints, options) {
  name_ = "JointPositionController of '" + robot.GetName() + "'";
  SetGains(robot_, joint_names_, options_.stiffness, options_.damping, options_.force_limit);
  // hold where the robot stands until a target comes
  target_ = GetQpos();
  SetTargets(robot_, joint_names_, target_, nullptr);
}

void JointPositionController::SetTarget(const Eigen::VectorXd& q) {
  CheckVector(q, "target");
  Eigen::MatrixX2d limits = ControlledLimits(robot_, dofs_);
  Eigen::VectorXd clamped = q.cwiseMax(limits.col(0)).cwiseMin(limits.col(1));
  std::string out_of_limits;
  for (int i = 0; i < NumJoints(); ++i)
    if (clamped[i] != q[i])
      out_of_limits += (out_of_limits.empty() ? "" : "; ") + std::string("joint '") +
                       joint_names_[i] + "' target " + FormatNumber(q[i]) + " is outside [" +
                       FormatNumber(limits(i, 0)) + ", " + FormatNumber(limits(i, 1)) +
                       "], clamped to " + FormatNumber(clamped[i]);
  target_ = clamped;
  set_time_ = robot_.GetScene()->GetTime();
  status_.state = out_of_limits.empty() ? ControllerState::kRunning : ControllerState::kFailed;
  status_.message = out_of_limits;
}

void JointPositionController::Update() {
  SetTargets(robot_, joint_names_, target_, nullptr);
  WriteQf(robot_, dofs_, Eigen::VectorXd::Zero(NumJoints()), options_.gravity_compensation);
  if (status_.state == ControllerState::kIdle || status_.state == ControllerState::kFailed) return;
  Eigen::VectorXd err = target_ - GetQpos(), qd = GetQvel();
  bool within = err.cwiseAbs().maxCoeff() <= options_.position_tolerance &&
                qd.cwiseAbs().maxCoeff() <= options_.velocity_tolerance;
  double now = robot_.GetScene()->GetTime();
  if (within) {
    status_.state = ControllerState::kReached;
  } else if (status_.state == ControllerState::kReached) {
    // pushed away after reaching: move back, with a fresh timeout
    status_.state = ControllerState::kRunning;
    set_time_ = now;
  } else if (now - set_time_ > options_.timeout) {
    int w = Worst(err);
    status_.state = ControllerState::kFailed;
    status_.message = "joint '" + joint_names_[w] + "' is " + FormatNumber(err[w]) +
                      " from its target after the timeout of " + FormatNumber(options_.timeout) +
                      " s (blocked?)";
  }
}

// ---------------------------------------------------------------------------------------------
// JointVelocityController

JointVelocityController::JointVelocityController(const Articulation& robot,
                                                 const std::vector<std::string>& joints,
                                                 const JointControllerOptions& options)
    : Controller(robot, joints, options) {
  name_ = "JointVelocityController of '" + robot.GetName() + "'";
  JointVelocityController::ConfigureDrives();
  target_ = Eigen::VectorXd::Zero(NumJoints());
  SetTargets(robot_, joint_names_, GetQpos(), &target_);
}

void JointVelocityController::ConfigureDrives() {
  SetGains(robot_, joint_names_, 0.0, options_.damping, options_.force_limit);
}

void JointVelocityController::SetTarget(const Eigen::VectorXd& qd) {
  CheckVector(qd, "velocity target");
  target_ = qd;
  ok_time_ = robot_.GetScene()->GetTime();
  status_.state = ControllerState::kRunning;
  status_.message.clear();
}

void JointVelocityController::Update() {
  SetTargets(robot_, joint_names_, GetQpos(), &target_);
  WriteQf(robot_, dofs_, Eigen::VectorXd::Zero(NumJoints()), options_.gravity_compensation);
  if (status_.state == ControllerState::kIdle || status_.state == ControllerState::kFailed) return;
  Eigen::VectorXd err = target_ - GetQvel();
  double now = robot_.GetScene()->GetTime();
  if (err.cwiseAbs().maxCoeff() <= options_.velocity_tolerance) {
    status_.state = ControllerState::kReached;
    ok_time_ = now;
  } else if (now - ok_time_ > options_.timeout) {
    int w = Worst(err);
    Eigen::MatrixX2d limits = ControlledLimits(robot_, dofs_);
    double q = GetQpos()[w];
    bool at_limit = std::abs(q - limits(w, 0)) < options_.position_tolerance ||
                    std::abs(q - limits(w, 1)) < options_.position_tolerance;
    status_.state = ControllerState::kFailed;
    status_.message = "joint '" + joint_names_[w] + "' has not reached velocity " +
                      FormatNumber(target_[w]) + " for " + FormatNumber(options_.timeout) + " s" +
                      (at_limit ? " (at its limit " + FormatNumber(q) + ")" : " (blocked?)");
  } else if (status_.state == ControllerState::kReached) {
    status_.state = ControllerState::kRunning;
  }
}

// ---------------------------------------------------------------------------------------------
// JointTrajectoryController

JointTrajectoryController::JointTrajectoryController(const Articulation& robot,
                                                     const std::vector<std::string>& joints,
                                                     const JointControllerOptions& options)
    : Controller(robot, joints, options) {
  name_ = "JointTrajectoryController of '" + robot.GetName() + "'";
  SetGains(robot_, joint_names_, options_.stiffness, options_.damping, options_.force_limit);
  SetTargets(robot_, joint_names_, GetQpos(), nullptr);
}

void JointTrajectoryController::SetTrajectory(const JointTrajectory& trajectory) {
  try {
    trajectory.Validate(NumJoints());
  } catch (const Error& e) {
    throw Error(name_ + ": " + e.what());
  }
  CheckSettings();
  Eigen::MatrixX2d limits = ControlledLimits(robot_, dofs_);
  for (size_t w = 0; w < trajectory.positions.size(); ++w) {
    const Eigen::VectorXd& p = trajectory.positions[w];
    for (int i = 0; i < NumJoints(); ++i) {
      if (p[i] >= limits(i, 0) && p[i] <= limits(i, 1)) continue;
      // refuse the whole trajectory: hold where the robot is
      trajectory_ = TrajectorySampler();
      started_ = false;
      SetTargets(robot_, joint_names_, GetQpos(), nullptr);
      status_.state = ControllerState::kFailed;
      status_.message = "waypoint " + std::to_string(w) + ": joint '" + joint_names_[i] +
                        "' position " + FormatNumber(p[i]) + " is outside its limits [" +
                        FormatNumber(limits(i, 0)) + ", " + FormatNumber(limits(i, 1)) + "]";
      return;
    }
  }
  trajectory_ = TrajectorySampler(trajectory);
  start_time_ = robot_.GetScene()->GetTime();
  started_ = true;
  status_.state = ControllerState::kRunning;
  status_.message.clear();
}

void JointTrajectoryController::SetPath(const std::vector<Eigen::VectorXd>& path,
                                        const Eigen::VectorXd& velocity_limits,
                                        const Eigen::VectorXd& acceleration_limits) {
  JointTrajectory t;
  try {
    for (size_t i = 0; i < path.size(); ++i) CheckVector(path[i], "path waypoint");
    t = TimeParameterize(path, velocity_limits, acceleration_limits);
  } catch (const Error& e) {
    throw Error(name_ + ": " + e.what());
  }
  SetTrajectory(t);
}

void JointTrajectoryController::CheckSettings() const {
  Controller::CheckSettings();
  CheckPositive(name_, "path_tolerance", path_tolerance);
}

void JointTrajectoryController::Update() {
  CheckSettings();
  if (!started_) {
    WriteQf(robot_, dofs_, Eigen::VectorXd::Zero(NumJoints()), options_.gravity_compensation);
    return;
  }
  const double now = robot_.GetScene()->GetTime(), t = now - start_time_;
  Eigen::VectorXd q, qd, qdd;
  trajectory_.Sample(t, &q, &qd, &qdd);
  const Eigen::VectorXd err = q - GetQpos();
  if (status_.state == ControllerState::kRunning && err.cwiseAbs().maxCoeff() > path_tolerance) {
    // abort and hold where the robot is
    int w = Worst(err);
    started_ = false;
    SetTargets(robot_, joint_names_, GetQpos(), nullptr);
    WriteQf(robot_, dofs_, Eigen::VectorXd::Zero(NumJoints()), options_.gravity_compensation);
    status_.state = ControllerState::kFailed;
    status_.message = "joint '" + joint_names_[w] + "' is " + FormatNumber(err[w]) +
                      " from the trajectory at t = " + FormatNumber(t) + " s (path_tolerance " +
                      FormatNumber(path_tolerance) + ")";
    return;
  }
  SetTargets(robot_, joint_names_, q, &qd);
  // feed-forward: M qdd on the controlled dofs, plus the passive force if compensating
  Eigen::VectorXd qacc = Eigen::VectorXd::Zero(robot_.Dof());
  for (int i = 0; i < NumJoints(); ++i) qacc[dofs_[i]] = qdd[i];
  Eigen::VectorXd mqdd = robot_.ComputeManipulatorInertiaMatrix() * qacc, ff(NumJoints());
  for (int i = 0; i < NumJoints(); ++i) ff[i] = mqdd[dofs_[i]];
  WriteQf(robot_, dofs_, ff, options_.gravity_compensation);
  const double duration = trajectory_.trajectory().Duration();
  if (t < duration) return;
  const Eigen::VectorXd qd_now = GetQvel();
  if (err.cwiseAbs().maxCoeff() <= options_.position_tolerance &&
      qd_now.cwiseAbs().maxCoeff() <= options_.velocity_tolerance) {
    status_.state = ControllerState::kReached;
  } else if (status_.state == ControllerState::kRunning && t > duration + options_.timeout) {
    int w = Worst(err);
    status_.state = ControllerState::kFailed;
    status_.message = "joint '" + joint_names_[w] + "' did not settle at the last waypoint (" +
                      FormatNumber(err[w]) + " away " + FormatNumber(options_.timeout) +
                      " s after the end)";
  }
}

// ---------------------------------------------------------------------------------------------
// EndEffectorController

struct EndEffectorController::State {
  enum class Mode { kHold, kPose, kTwist };
  KinematicModel model;
  int link = -1;
  Pose tcp;
  Mode mode = Mode::kHold;
  Pose target;   ///< world, pose mode
  Pose command;  ///< world, the speed-limited intermediate pose
  Eigen::Matrix<double, 6, 1> twist = Eigen::Matrix<double, 6, 1>::Zero();  ///< world
  Eigen::VectorXd q_cmd;  ///< all dofs: joint targets sent to the drives
  double arrived = 0.0;   ///< time the command reached the target
  bool command_at_target = false;
  explicit State(const KinematicModel& m) : model(m) {}
};

EndEffectorController::EndEffectorController(const Articulation& robot,
                                             const std::vector<std::string>& joints,
                                             const std::string& ee_link, const Pose& tcp,
                                             const JointControllerOptions& options)
    : Controller(robot, joints, options) {
  name_ = "EndEffectorController of '" + robot.GetName() + "'";
  CheckPose(name_ + ": tcp", tcp);
  state_ = std::make_shared<State>(KinematicModel::FromArticulation(robot));
  state_->link = state_->model.LinkIndex(ee_link);  // throws naming a missing link
  state_->tcp = tcp;
  state_->tcp.q.normalize();
  state_->q_cmd = robot.GetQpos();
  ik.offset = state_->tcp;
  SetGains(robot_, joint_names_, options_.stiffness, options_.damping, options_.force_limit);
  SetTargets(robot_, joint_names_, GetQpos(), nullptr);
}

Pose EndEffectorController::GetEndEffectorPose() const {
  return robot_.GetLink(state_->link).GetPose() * state_->tcp;
}

void EndEffectorController::CheckSettings() const {
  Controller::CheckSettings();
  CheckPositive(name_, "max_linear_speed", max_linear_speed);
  CheckPositive(name_, "max_angular_speed", max_angular_speed);
  CheckPositive(name_, "position_tolerance", position_tolerance);
  CheckPositive(name_, "rotation_tolerance", rotation_tolerance);
  CheckPositive(name_, "ik.position_tolerance", ik.position_tolerance);
  CheckPositive(name_, "ik.rotation_tolerance", ik.rotation_tolerance);
  CheckPositive(name_, "ik.max_step", ik.max_step);
  CheckFiniteNonNegative(name_, "ik.damping", ik.damping);
  if (ik.max_iterations < 1)
    throw Error(name_ + ": ik.max_iterations must be >= 1, got " +
                std::to_string(ik.max_iterations));
  if (ik.restarts < 0)
    throw Error(name_ + ": ik.restarts must be >= 0, got " + std::to_string(ik.restarts));
  if (!ik.active.empty() && static_cast<int>(ik.active.size()) != robot_.Dof())
    throw Error(name_ + ": ik.active has " + std::to_string(ik.active.size()) +
                " entries, expected none or one per dof (" + std::to_string(robot_.Dof()) + ")");
}

namespace {

Pose ToWorld(const Articulation& robot, const Pose& pose, ControlFrame frame) {
  return frame == ControlFrame::kBase ? robot.GetRootPose() * pose : pose;
}

}  // namespace

void EndEffectorController::SetTargetPose(const Pose& target, ControlFrame frame) {
  CheckPose(name_ + ": target", target);
  CheckSettings();
  State& s = *state_;
  s.model.SetRootPose(robot_.GetRootPose());
  Pose goal = ToWorld(robot_, target, frame);
  goal.q.normalize();
  // the controlled joints only (and those the user's IK options allow)
  IkOptions opt = ik;
  opt.offset = s.tcp;
  opt.active.assign(robot_.Dof(), false);
  for (int d : dofs_) opt.active[d] = ik.active.empty() || ik.active[d];
  const Eigen::VectorXd q_now = robot_.GetQpos();
  IkResult r = InverseKinematics(s.model, s.link, goal, q_now, opt);
  // the commanded motion starts from where the robot stands
  s.q_cmd = q_now;
  s.command = s.model.LinkPose(q_now, s.link, s.tcp);
  if (!r.success) {
    s.mode = State::Mode::kHold;
    SetTargets(robot_, joint_names_, GetQpos(), nullptr);
    status_.state = ControllerState::kFailed;
    status_.message = "target pose " + goal.ToString() + " is out of reach: " + r.message;
    return;
  }
  s.mode = State::Mode::kPose;
  s.target = goal;
  s.command_at_target = false;
  status_.state = ControllerState::kRunning;
  status_.message.clear();
}

void EndEffectorController::SetTargetTwist(const Eigen::Matrix<double, 6, 1>& twist,
                                           ControlFrame frame) {
  CheckFinite(name_ + ": twist", twist);
  CheckSettings();
  State& s = *state_;
  s.model.SetRootPose(robot_.GetRootPose());
  Eigen::Matrix<double, 6, 1> w = twist;
  if (frame == ControlFrame::kBase) {
    Eigen::Quaterniond r = robot_.GetRootPose().q.normalized();
    w.head<3>() = r * twist.head<3>();
    w.tail<3>() = r * twist.tail<3>();
  }
  // speeds beyond the limits are scaled down (said in the status message)
  std::string clamped;
  double v = w.head<3>().norm(), a = w.tail<3>().norm();
  if (v > max_linear_speed) {
    w.head<3>() *= max_linear_speed / v;
    clamped = "linear speed clamped to " + FormatNumber(max_linear_speed) + " m/s";
  }
  if (a > max_angular_speed) {
    w.tail<3>() *= max_angular_speed / a;
    clamped += (clamped.empty() ? "" : "; ") + std::string("angular speed clamped to ") +
               FormatNumber(max_angular_speed) + " rad/s";
  }
  if (s.mode != State::Mode::kTwist) {
    s.q_cmd = robot_.GetQpos();
    s.command = s.model.LinkPose(s.q_cmd, s.link, s.tcp);
  }
  s.twist = w;
  s.mode = State::Mode::kTwist;
  status_.state = ControllerState::kRunning;
  status_.message = clamped;
}

void EndEffectorController::Update() {
  CheckSettings();
  State& s = *state_;
  const double now = robot_.GetScene()->GetTime();
  const double dt = Period() * robot_.GetScene()->GetTimestep();
  if (s.mode != State::Mode::kHold) {
    s.model.SetRootPose(robot_.GetRootPose());
    // move the commanded pose: towards the target no faster than the speed limits, or along
    // the twist
    if (s.mode == State::Mode::kPose) {
      Eigen::Matrix<double, 6, 1> e = PoseError(s.command, s.target);
      double lin = e.head<3>().norm(), ang = e.tail<3>().norm();
      double f = 1.0;
      if (lin > 0) f = std::min(f, max_linear_speed * dt / lin);
      if (ang > 0) f = std::min(f, max_angular_speed * dt / ang);
      if (f >= 1.0) {
        s.command = s.target;
        if (!s.command_at_target) s.arrived = now;
        s.command_at_target = true;
      } else {
        s.command.p += f * e.head<3>();
        s.command.q = s.command.q.slerp(f, s.target.q).normalized();
      }
    } else {
      s.command.p += s.twist.head<3>() * dt;
      double a = s.twist.tail<3>().norm() * dt;
      if (a > 0)
        s.command.q =
            (Eigen::Quaterniond(Eigen::AngleAxisd(a, s.twist.tail<3>().normalized())) * s.command.q)
                .normalized();
    }
    // a few damped least-squares steps from the last command to the commanded pose
    IkOptions opt = ik;
    opt.offset = s.tcp;
    opt.max_iterations = 10;
    opt.restarts = 0;
    opt.active.assign(robot_.Dof(), false);
    for (int d : dofs_) opt.active[d] = ik.active.empty() || ik.active[d];
    IkResult r = InverseKinematics(s.model, s.link, s.command, s.q_cmd, opt);
    s.q_cmd = r.q;
    if (s.mode == State::Mode::kTwist && r.position_error > 5e-3 + max_linear_speed * dt) {
      // the twist drives the frame out of reach (or into a limit): stop there
      s.mode = State::Mode::kHold;
      s.command = s.model.LinkPose(s.q_cmd, s.link, s.tcp);
      status_.state = ControllerState::kFailed;
      status_.message = "the twist drives the end effector out of reach (" +
                        FormatNumber(r.position_error) + " m from the commanded pose)";
    }
  }
  Eigen::VectorXd q_targets(NumJoints());
  for (int i = 0; i < NumJoints(); ++i) q_targets[i] = s.q_cmd[dofs_[i]];
  SetTargets(robot_, joint_names_, q_targets, nullptr);
  WriteQf(robot_, dofs_, Eigen::VectorXd::Zero(NumJoints()), options_.gravity_compensation);
  if (s.mode != State::Mode::kPose || !s.command_at_target) return;
  // reached when the measured frame is within tolerance and the joints have settled
  Eigen::Matrix<double, 6, 1> e = PoseError(GetEndEffectorPose(), s.target);
  bool within = e.head<3>().norm() <= position_tolerance &&
                e.tail<3>().norm() <= rotation_tolerance &&
                GetQvel().cwiseAbs().maxCoeff() <= options_.velocity_tolerance;
  if (within) {
    status_.state = ControllerState::kReached;
  } else if (status_.state == ControllerState::kReached) {
    status_.state = ControllerState::kRunning;
    s.arrived = now;
  } else if (status_.state == ControllerState::kRunning && now - s.arrived > options_.timeout) {
    status_.state = ControllerState::kFailed;
    status_.message = "the end effector is " + FormatNumber(e.head<3>().norm()) + " m and " +
                      FormatNumber(e.tail<3>().norm()) +
                      " rad from the target after the timeout of " +
                      FormatNumber(options_.timeout) + " s (blocked?)";
  }
}

// ---------------------------------------------------------------------------------------------
// ControlLoop

ControlLoop::ControlLoop(Scene* scene) : scene_(scene) {
  if (!scene) throw Error("ControlLoop: scene is null");
}

void Controller::ConfigureDrives() {
  SetGains(robot_, joint_names_, options_.stiffness, options_.damping, options_.force_limit);
}

void ControlLoop::Add(std::shared_ptr<Controller> controller) {
  if (!controller) throw Error("ControlLoop::Add: controller is null");
  if (controller->GetRobot().GetScene() != scene_)
    throw Error("ControlLoop::Add: " + controller->GetName() +
                " controls a robot of another scene");
  for (const Entry& e : entries_)
    if (e.controller == controller)
      throw Error("ControlLoop::Add: " + controller->GetName() + " was already added");
  controller->ConfigureDrives();
  // its first update comes with the next step
  entries_.push_back({std::move(controller), step_count_});
}

void ControlLoop::Remove(const std::shared_ptr<Controller>& controller) {
  entries_.erase(std::remove_if(entries_.begin(), entries_.end(),
                                [&](const Entry& e) { return e.controller == controller; }),
                 entries_.end());
}

void ControlLoop::Step(int n) {
  if (n < 0) throw Error("ControlLoop::Step: n must be >= 0, got " + std::to_string(n));
  long long end = step_count_ + n;
  while (step_count_ < end) {
    // update the controllers that are due, then step to the next update of any of them
    long long next = end;
    for (Entry& e : entries_) {
      if (e.next_update <= step_count_) {
        e.controller->Update();
        e.next_update = step_count_ + e.controller->Period();
      }
      next = std::min(next, e.next_update);
    }
    int steps = static_cast<int>(next - step_count_);
    scene_->Step(steps);
    step_count_ = next;
  }
}

bool ControlLoop::RunUntilDone(double max_seconds) {
  if (!(max_seconds >= 0)) throw Error("ControlLoop::RunUntilDone: max_seconds must be >= 0");
  const double dt = scene_->GetTimestep();
  const long long max_steps = static_cast<long long>(std::ceil(max_seconds / dt - 1e-9));
  auto all_done = [&]() {
    for (const Entry& e : entries_)
      if (!Done(e.controller->GetStatus().state)) return false;
    return true;
  };
  auto all_reached = [&]() {
    for (const Entry& e : entries_) {
      ControllerState s = e.controller->GetStatus().state;
      if (s == ControllerState::kFailed) return false;
    }
    return true;
  };
  for (long long k = 0; k < max_steps && !all_done(); ++k) Step(1);
  return all_done() && all_reached();
}

}  // namespace partsim
