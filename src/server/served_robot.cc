#include "partsim/server/served_robot.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <future>
#include <map>
#include <thread>

#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"

namespace partsim {

namespace {

/// Checks a vector of one value per commanded joint.
void CheckValues(const std::vector<double>& v, size_t n, const std::string& what) {
  if (v.size() != n)
    throw Error(what + ": " + std::to_string(v.size()) + " values for " + std::to_string(n) +
                " joints");
  for (size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) throw Error(what + ": value " + std::to_string(i) + " is not finite");
}

Eigen::VectorXd ToVector(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

/// The optical frame (x right, y down, z forward) of a camera posed in partsim's convention
/// (x forward, y left, z up).
Pose OpticalPose(const Pose& camera) {
  return camera * Pose(Eigen::Vector3d::Zero(), Eigen::Quaterniond(RotationCameraToCv()));
}

}  // namespace

struct ServedRobot::Impl {
  SimServer* sim;
  Scene* scene;
  ControlLoop* loop;
  std::vector<std::string> joint_names;
  std::shared_ptr<JointPositionController> position;
  std::shared_ptr<JointVelocityController> velocity;
  std::shared_ptr<JointEffortController> effort;
  std::shared_ptr<JointTrajectoryController> trajectory;
  std::shared_ptr<Controller> active;  // simulation thread only
  double default_path_tolerance = 0.1;
  Eigen::MatrixX2d limits;  ///< per commanded joint: (lower, upper)

  // the running trajectory goal (simulation thread only)
  struct Goal {
    long long id = 0;
    DoneCallback done;
    FeedbackCallback feedback;
    double start = 0.0, end = 0.0;  ///< simulation times
    double goal_time_tolerance = 0.0;
    Eigen::VectorXd path_tolerance, goal_tolerance;  ///< per commanded joint
    double next_feedback = 0.0;
  };
  std::unique_ptr<Goal> goal;
  std::atomic<long long> next_goal{1};

  std::atomic<long long> commands{0}, latency_sum{0}, max_latency{0};
  long long rendered_at = -1;  // clock step of the last UpdateRender
  std::vector<long long> pictured_at;

  // planning worker
  std::unique_ptr<MotionPlanner> planner;
  std::string ee_link;
  std::thread worker;
  std::mutex jobs_mutex;
  std::condition_variable jobs_cv;
  /// A plan waiting for the worker, or running.
  struct PlanJob {
    const void* owner = nullptr;
    std::shared_ptr<std::atomic<bool>> cancel;  ///< the plan's own cancel flag
    std::function<void()> run;
    std::function<void()> report_cancelled;  ///< on_result with "cancelled", for a dropped plan
  };
  std::deque<PlanJob> jobs;                           // jobs_mutex
  const void* running_owner = nullptr;                // jobs_mutex
  std::shared_ptr<std::atomic<bool>> running_cancel;  // jobs_mutex; null when none runs
  bool stopping = false;

  /// Runs `apply` on the simulation thread between steps, counting the latency.
  void Post(std::function<void()> apply, ErrorSink on_error) {
    const long long arrival = sim->GetClockSteps();
    sim->Post([this, arrival, apply = std::move(apply), on_error = std::move(on_error)] {
      long long lat = sim->GetClockSteps() - arrival;
      latency_sum += lat;
      long long m = max_latency;
      while (lat > m && !max_latency.compare_exchange_weak(m, lat)) {
      }
      ++commands;
      try {
        apply();
      } catch (const std::exception& e) {
        if (on_error) on_error(e.what());
      }
    });
  }

  /// Checks a target of one value per joint, then sets it on `controller` and makes that the
  /// active controller, between two steps.
  template <class C>
  void Command(const std::shared_ptr<C>& controller, const std::vector<double>& values,
               const std::string& what, ErrorSink on_error) {
    CheckValues(values, joint_names.size(), what);
    Eigen::VectorXd v = ToVector(values);
    Post(
        [this, controller, v] {
          controller->SetTarget(v);
          Activate(controller);
        },
        std::move(on_error));
  }

  /// Ends the running goal, if any (simulation thread).
  void Finish(TrajectoryOutcome outcome, const std::string& message) {
    if (!goal) return;
    std::unique_ptr<Goal> g = std::move(goal);
    if (g->done) g->done(outcome, message);
  }

  void Activate(const std::shared_ptr<Controller>& c) {
    if (c != trajectory) Finish(TrajectoryOutcome::kPreempted, "another command took over");
    if (active == c) return;
    if (active) loop->Remove(active);
    loop->Add(c);
    active = c;
  }

  /// Holds the robot where it is (simulation thread).
  void Hold() {
    position->SetTarget(position->GetQpos());
    Activate(position);
  }

  /// After each step: feedback and the end of the running goal.
  void OnStep() {
    if (!goal) return;
    if (active != trajectory) return Finish(TrajectoryOutcome::kPreempted, "controller replaced");
    const double now = scene->GetTime(), t = now - goal->start;
    const ControllerStatus& st = trajectory->GetStatus();
    Eigen::VectorXd desired, desired_v;
    trajectory->GetSampler().Sample(std::min(t, goal->end - goal->start), &desired, &desired_v);
    const Eigen::VectorXd actual = trajectory->GetQpos(), err = desired - actual;
    if (goal->feedback && now + 1e-9 >= goal->next_feedback) {
      goal->next_feedback = now + 0.02;  // 50 Hz of simulated time
      TrajectoryFeedback f;
      f.time = now;
      f.joint_names = joint_names;
      f.desired = desired;
      f.actual = actual;
      f.error = err;
      f.desired_velocity = desired_v;
      f.actual_velocity = trajectory->GetQvel();
      goal->feedback(f);
    }
    // the joint furthest beyond its tolerance (0: unbounded), or -1 if none is beyond
    auto worst = [&](const Eigen::VectorXd& tol) {
      int w = -1;
      double excess = 0;
      for (Eigen::Index i = 0; i < err.size(); ++i) {
        double e = std::abs(err[i]) - tol[i];
        if (tol[i] > 0 && e > excess) {
          excess = e;
          w = static_cast<int>(i);
        }
      }
      return w;
    };
    if (st.state == ControllerState::kFailed && t <= goal->end - goal->start) {
      Finish(TrajectoryOutcome::kPathToleranceViolated, st.message);
      return Hold();
    }
    if (t <= goal->end - goal->start) {
      const int w = worst(goal->path_tolerance);
      if (w >= 0) {
        std::string msg = "joint '" + joint_names[w] + "' is " + FormatNumber(err[w]) +
                          " from the trajectory at t = " + FormatNumber(t) + " s (path tolerance " +
                          FormatNumber(goal->path_tolerance[w]) + ")";
        Finish(TrajectoryOutcome::kPathToleranceViolated, msg);
        return Hold();
      }
      return;
    }
    const int w = worst(goal->goal_tolerance);
    if (w < 0) return Finish(TrajectoryOutcome::kSucceeded, "");
    if (t > goal->end - goal->start + goal->goal_time_tolerance) {
      std::string msg = "joint '" + joint_names[w] + "' is " + FormatNumber(err[w]) +
                        " from its goal " + FormatNumber(goal->goal_time_tolerance) +
                        " s after the trajectory's end (goal tolerance " +
                        FormatNumber(goal->goal_tolerance[w]) + ")";
      Finish(TrajectoryOutcome::kGoalToleranceViolated, msg);
      Hold();
    }
  }

  /// Index of each named joint among the commanded ones; throws naming `what`.
  std::vector<int> Indices(const std::vector<std::string>& names, const std::string& what) const {
    std::vector<int> index;
    for (const std::string& n : names) {
      auto it = std::find(joint_names.begin(), joint_names.end(), n);
      if (it == joint_names.end()) throw Error(what + ": unknown joint '" + n + "'");
      int i = static_cast<int>(it - joint_names.begin());
      if (std::find(index.begin(), index.end(), i) != index.end())
        throw Error(what + ": joint '" + n + "' is named twice");
      index.push_back(i);
    }
    return index;
  }

  /// Per-joint tolerances from (name, value) pairs: `fallback` where none (or 0) is given, no
  /// bound where negative.
  Eigen::VectorXd Tolerances(const std::vector<std::pair<std::string, double>>& given,
                             double fallback, const std::string& what) const {
    Eigen::VectorXd tol =
        Eigen::VectorXd::Constant(static_cast<Eigen::Index>(joint_names.size()), fallback);
    for (const auto& [name, value] : given) {
      int i = Indices({name}, what).front();
      if (!std::isfinite(value)) throw Error(what + ": tolerance of '" + name + "' is not finite");
      if (value > 0) tol[i] = value;
      if (value < 0) tol[i] = 0;  // 0 in `tol` means unbounded
    }
    return tol;
  }

  void WorkerLoop() {
    for (;;) {
      PlanJob job;
      {
        std::unique_lock<std::mutex> lock(jobs_mutex);
        jobs_cv.wait(lock, [this] { return stopping || !jobs.empty(); });
        if (stopping) return;
        job = std::move(jobs.front());
        jobs.pop_front();
        running_owner = job.owner;
        running_cancel = job.cancel;
      }
      job.run();
      std::lock_guard<std::mutex> lock(jobs_mutex);
      running_owner = nullptr;
      running_cancel.reset();
    }
  }

  /// Runs `f` on the simulation thread and waits for it; false if stopping or `cancel` turns
  /// true first.
  bool OnSimThread(const std::function<void()>& f, const std::atomic<bool>* cancel = nullptr) {
    auto done = std::make_shared<std::promise<void>>();
    std::future<void> fut = done->get_future();
    sim->Post([f, done] {
      try {
        f();
        done->set_value();
      } catch (...) {  // to the waiting thread, not the simulation thread's
        done->set_exception(std::current_exception());
      }
    });
    while (fut.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      if (cancel && *cancel) return false;
      std::lock_guard<std::mutex> lock(jobs_mutex);
      if (stopping) return false;
    }
    fut.get();  // rethrows what f threw
    return true;
  }
};

ServedRobot::ServedRobot(SimServer* sim, Scene* scene, ControlLoop* loop, const Articulation& robot,
                         const std::string& name, const ServedRobotOptions& options)
    : name_(name),
      sim_(sim),
      scene_(scene),
      robot_(robot),
      options_(options),
      impl_(std::make_unique<Impl>()) {
  if (!sim || !scene || !loop) throw Error("ServedRobot: sim, scene and loop must not be null");
  for (double r : {options.control_rate, options.camera_rate, options.imu_rate})
    if (!(r >= 0) || !std::isfinite(r))
      throw Error("ServedRobot: rates must be finite and >= 0 (0: every step)");
  Impl& m = *impl_;
  m.sim = sim;
  m.scene = scene;
  m.loop = loop;
  for (const Joint& j : robot.GetActiveJoints()) m.joint_names.push_back(j.GetName());
  JointControllerOptions co;
  co.control_rate = options.control_rate > 0 ? options.control_rate : 1.0 / scene->GetTimestep();
  m.position = std::make_shared<JointPositionController>(robot, std::vector<std::string>{}, co);
  m.velocity = std::make_shared<JointVelocityController>(robot, std::vector<std::string>{}, co);
  m.effort = std::make_shared<JointEffortController>(robot, std::vector<std::string>{}, co);
  m.trajectory = std::make_shared<JointTrajectoryController>(robot, std::vector<std::string>{}, co);
  m.default_path_tolerance = m.trajectory->path_tolerance;
  m.limits = robot.GetQlimits();  // active joints, in the controllers' order
  m.Activate(m.position);

  const std::vector<Link> links = robot.GetLinks();
  if (!links.empty()) {
    Link l = options.imu_link.empty() ? links.back() : robot.FindLinkByName(options.imu_link);
    imu_ = std::make_unique<Imu>(l);
    imu_frame_ = l.GetName();
    m.ee_link = options.ee_link.empty() ? links.back().GetName()
                                        : robot.FindLinkByName(options.ee_link).GetName();
  }
  for (const Camera& cam : partsim::GetCameras(*scene))
    cameras_.push_back({cam, cam.GetName(), cam.GetName() + "_optical_frame"});
  m.pictured_at.assign(cameras_.size(), -1);
  if (robot.Dof() > 0) m.planner = std::make_unique<MotionPlanner>(robot);
  sim->AddStepCallback([this](long long) { impl_->OnStep(); });
  m.worker = std::thread([this] { impl_->WorkerLoop(); });
}

ServedRobot::~ServedRobot() { Close(); }

void ServedRobot::Close() {
  {
    std::lock_guard<std::mutex> lock(impl_->jobs_mutex);
    impl_->stopping = true;
    if (impl_->running_cancel) *impl_->running_cancel = true;  // stops within milliseconds
  }
  impl_->jobs_cv.notify_all();
  if (impl_->worker.joinable()) impl_->worker.join();
}

const std::vector<std::string>& ServedRobot::GetJointNames() const { return impl_->joint_names; }

void ServedRobot::CommandPositions(const std::vector<double>& values, const std::string& what,
                                   ErrorSink on_error) {
  impl_->Command(impl_->position, values, what, std::move(on_error));
}

void ServedRobot::CommandVelocities(const std::vector<double>& values, const std::string& what,
                                    ErrorSink on_error) {
  impl_->Command(impl_->velocity, values, what, std::move(on_error));
}

void ServedRobot::CommandEfforts(const std::vector<double>& values, const std::string& what,
                                 ErrorSink on_error) {
  impl_->Command(impl_->effort, values, what, std::move(on_error));
}

void ServedRobot::CheckTrajectory(const TrajectoryCommand& c, const std::string& what) const {
  Impl* m = impl_.get();
  const std::vector<int> index = m->Indices(c.joint_names, what);
  if (index.empty()) throw Error(what + ": no joint_names");
  if (c.times.empty() || c.positions.size() != c.times.size())
    throw Error(what + ": " + std::to_string(c.positions.size()) + " points with positions for " +
                std::to_string(c.times.size()) + " times (need at least one point)");
  if (!c.velocities.empty() && c.velocities.size() != c.times.size())
    throw Error(what + ": velocities given for " + std::to_string(c.velocities.size()) + " of " +
                std::to_string(c.times.size()) + " points");
  for (size_t k = 0; k < c.times.size(); ++k) {
    const std::string p = what + " point " + std::to_string(k);
    if (!std::isfinite(c.times[k]) || c.times[k] < 0 || c.times[k] > kMaxTrajectorySeconds)
      throw Error(p + ": time_from_start must be from 0 to " +
                  std::to_string(static_cast<int>(kMaxTrajectorySeconds)) + " s, got " +
                  FormatNumber(c.times[k]));
    if (k > 0 && !(c.times[k] > c.times[k - 1]))
      throw Error(p + ": time_from_start does not come after the previous point's");
    CheckValues(c.positions[k], index.size(), p + " positions");
    if (!c.velocities.empty()) CheckValues(c.velocities[k], index.size(), p + " velocities");
  }
  if (!(c.goal_time_tolerance >= 0) || !std::isfinite(c.goal_time_tolerance))
    throw Error(what + ": goal_time_tolerance must be finite and >= 0");
  m->Tolerances(c.path_tolerance, 0.0, what);
  m->Tolerances(c.goal_tolerance, 0.0, what);
}

long long ServedRobot::CommandTrajectory(const TrajectoryCommand& c, const std::string& what,
                                         DoneCallback on_done, FeedbackCallback on_feedback) {
  CheckTrajectory(c, what);
  Impl* m = impl_.get();
  const std::vector<int> index = m->Indices(c.joint_names, what);
  auto g = std::make_shared<Impl::Goal>();
  g->id = m->next_goal++;
  g->done = std::move(on_done);
  g->feedback = std::move(on_feedback);
  g->path_tolerance = m->Tolerances(c.path_tolerance, m->default_path_tolerance, what);
  g->goal_tolerance =
      m->Tolerances(c.goal_tolerance, m->trajectory->GetOptions().position_tolerance, what);
  g->goal_time_tolerance =
      c.goal_time_tolerance > 0 ? c.goal_time_tolerance : m->trajectory->GetOptions().timeout;
  m->Post(
      [m, c, index, g] {
        // joints not named hold where they are; a first point after 0 starts from here. A joint
        // a hair outside its limits (contacts, soft limits) is held at the limit, or the
        // controller would refuse the waypoint.
        Eigen::VectorXd here =
            m->trajectory->GetQpos().cwiseMax(m->limits.col(0)).cwiseMin(m->limits.col(1));
        JointTrajectory traj;
        const bool vel = !c.velocities.empty();
        if (c.times.front() > 1e-9) {
          traj.times.push_back(0.0);
          traj.positions.push_back(here);
          if (vel) traj.velocities.push_back(Eigen::VectorXd::Zero(here.size()));
        }
        for (size_t k = 0; k < c.times.size(); ++k) {
          Eigen::VectorXd q = here, qd = Eigen::VectorXd::Zero(here.size());
          for (size_t i = 0; i < index.size(); ++i) {
            q[index[i]] = c.positions[k][i];
            if (vel) qd[index[i]] = c.velocities[k][i];
          }
          traj.times.push_back(c.times[k]);
          traj.positions.push_back(q);
          if (vel) traj.velocities.push_back(qd);
        }
        m->Finish(TrajectoryOutcome::kPreempted, "a new trajectory replaced it");
        m->trajectory->SetTrajectory(traj);
        m->Activate(m->trajectory);
        if (m->trajectory->GetStatus().state == ControllerState::kFailed) {
          if (g->done) g->done(TrajectoryOutcome::kInvalidGoal, m->trajectory->GetStatus().message);
          return;
        }
        auto goal = std::make_unique<Impl::Goal>(*g);
        goal->start = m->scene->GetTime();
        goal->end = goal->start + traj.Duration();
        goal->next_feedback = goal->start;
        m->goal = std::move(goal);
      },
      [g](const std::string& e) {
        if (g->done) g->done(TrajectoryOutcome::kInvalidGoal, e);
      });
  return g->id;
}

void ServedRobot::CancelTrajectory(long long id) {
  Impl* m = impl_.get();
  m->Post(
      [m, id] {
        if (!m->goal || m->goal->id != id) return;
        m->Finish(TrajectoryOutcome::kPreempted, "cancelled");
        m->Hold();
      },
      {});
}

void ServedRobot::Plan(const PlanRequest& request, PlanCallback on_result, DoneCallback on_done) {
  Impl* m = impl_.get();
  if (!m->planner) throw Error("plan: robot '" + name_ + "' has no joints to plan for");
  if (!request.joint_goal.empty())
    CheckValues(request.joint_goal, m->joint_names.size(), "plan: joint_goal");
  else if (!request.pose_goal.p.allFinite() || !request.pose_goal.q.coeffs().allFinite() ||
           std::abs(request.pose_goal.q.norm() - 1.0) > 1e-3)
    throw Error("plan: pose_goal must be finite with a unit quaternion");
  PlannerOptions opt = request.options;
  opt.use_last_snapshot = true;
  auto cancel = std::make_shared<std::atomic<bool>>(false);
  opt.cancel = cancel.get();  // the job holds `cancel`
  try {                       // now, so that a bad request fails on the caller's thread
    CheckPlannerOptions(opt);
  } catch (const Error& e) {
    throw Error(std::string("plan: ") + e.what());
  }
  // one worker plans for every client: a long request would hold up the others
  if (opt.time_limit > kMaxPlanSeconds)
    throw Error("plan: time_limit must be at most " +
                std::to_string(static_cast<int>(kMaxPlanSeconds)) + " s, got " +
                FormatNumber(opt.time_limit));
  Impl::PlanJob job;
  job.owner = request.owner;
  job.cancel = cancel;
  job.report_cancelled = [on_result] {
    PlanResult r;
    r.success = false;
    r.message = "cancelled";
    if (on_result) on_result(r);
  };
  job.run = [this, m, request, opt, cancel, on_result, on_done] {
    PlanResult r;
    try {
      if (!m->OnSimThread([m] { m->planner->UpdateSnapshot(); }, cancel.get())) {
        if (!*cancel) return;  // shutting down: dropped
        r.success = false;
        r.message = "cancelled";
      } else {
        r = request.joint_goal.empty()
                ? m->planner->PlanToPose(m->ee_link, options_.tcp_in_ee, request.pose_goal, opt)
                : m->planner->PlanToJoints(ToVector(request.joint_goal), opt);
      }
    } catch (const std::exception& e) {
      r.success = false;
      r.message = e.what();
    }
    if (on_result) on_result(r);
    // a plan cancelled after it was found is not executed: its client has gone
    if (!r.success || !request.execute || *cancel) return;
    TrajectoryCommand c;
    c.joint_names = m->planner->GetJointNames();
    const JointTrajectory& t = r.trajectory;
    for (size_t k = 0; k < t.times.size(); ++k) {
      c.times.push_back(t.times[k]);
      c.positions.emplace_back(t.positions[k].data(),
                               t.positions[k].data() + t.positions[k].size());
      if (!t.velocities.empty())
        c.velocities.emplace_back(t.velocities[k].data(),
                                  t.velocities[k].data() + t.velocities[k].size());
    }
    try {
      CommandTrajectory(c, "plan", on_done);
    } catch (const std::exception& e) {
      if (on_done) on_done(TrajectoryOutcome::kInvalidGoal, e.what());
    }
  };
  {
    std::lock_guard<std::mutex> lock(m->jobs_mutex);
    if (m->stopping) throw Error("plan: the server is shutting down");
    // one worker plans for every client: bounded per client and in all, so that nobody's
    // plan waits behind minutes of others'
    const size_t all = m->jobs.size() + (m->running_cancel ? 1 : 0);
    if (all >= kMaxPlans)
      throw Error("plan: " + std::to_string(all) + " plans are waiting or running (at most " +
                  std::to_string(kMaxPlans) + " in all); try again later");
    if (request.owner) {
      size_t mine = m->running_cancel && m->running_owner == request.owner ? 1 : 0;
      for (const Impl::PlanJob& j : m->jobs) mine += j.owner == request.owner;
      if (mine >= kMaxPlansPerOwner)
        throw Error("plan: this client has " + std::to_string(mine) +
                    " plans waiting or running (at most " + std::to_string(kMaxPlansPerOwner) +
                    "); wait for their answers");
    }
    m->jobs.push_back(std::move(job));
  }
  m->jobs_cv.notify_all();
}

void ServedRobot::CancelPlans(const void* owner) {
  if (!owner) return;
  Impl* m = impl_.get();
  std::vector<Impl::PlanJob> dropped;
  {
    std::lock_guard<std::mutex> lock(m->jobs_mutex);
    for (auto it = m->jobs.begin(); it != m->jobs.end();) {
      if (it->owner == owner) {
        dropped.push_back(std::move(*it));
        it = m->jobs.erase(it);
      } else {
        ++it;
      }
    }
    if (m->running_cancel && m->running_owner == owner) *m->running_cancel = true;
  }
  for (Impl::PlanJob& j : dropped) j.report_cancelled();
}

CommandStats ServedRobot::GetCommandStats() const {
  CommandStats s;
  s.commands = impl_->commands;
  s.mean_latency_steps =
      s.commands > 0 ? static_cast<double>(impl_->latency_sum) / s.commands : 0.0;
  s.max_latency_steps = impl_->max_latency;
  return s;
}

JointStateReading ServedRobot::ReadJointStates() const {
  JointStateReading r;
  for (const Articulation& a : scene_->GetArticulations()) {
    Eigen::VectorXd q = a.GetQpos(), qd = a.GetQvel(), f = a.GetQf();
    std::vector<Joint> joints = a.GetActiveJoints();
    for (size_t i = 0; i < joints.size(); ++i) {
      r.names.push_back(joints[i].GetName());
      r.position.push_back(q[i]);
      r.velocity.push_back(qd[i]);
      r.effort.push_back(f[i]);
    }
  }
  return r;
}

std::vector<FrameReading> ServedRobot::ReadFrames() const {
  std::vector<FrameReading> frames;
  for (const Articulation& a : scene_->GetArticulations())
    for (const Link& l : a.GetLinks()) frames.push_back({l.GetName(), l.GetPose()});
  for (const CameraSensor& c : cameras_)
    frames.push_back({c.frame, OpticalPose(c.camera.GetPose())});
  return frames;
}

const Camera& ServedRobot::TakePicture(size_t i) {
  Impl& m = *impl_;
  const long long step = sim_->GetClockSteps();
  if (m.pictured_at.at(i) == step) return cameras_[i].camera;
  if (m.rendered_at != step) UpdateRender(*scene_);  // this step's poses, once for all cameras
  m.rendered_at = step;
  cameras_[i].camera.TakePicture(kColor | kPosition);  // what the topics carry: the fast path
  m.pictured_at[i] = step;
  return cameras_[i].camera;
}

std::string SensorTopic(const ServedRobot& robot, SensorStream stream, size_t camera) {
  if (stream == SensorStream::kImu) return "/imu";
  const std::string base = "/" + robot.GetCameras().at(camera).name;
  switch (stream) {
    case SensorStream::kImage:
      return base + "/image_raw";
    case SensorStream::kPoints:
      return base + "/points";
    default:
      return base + "/camera_info";
  }
}

SensorSchedule::SensorSchedule(ServedRobot* robot) : robot_(robot) {
  if (!robot) throw Error("SensorSchedule: robot is null");
  cameras_.resize(robot->GetCameras().size());
}

void SensorSchedule::Publish(double t, const Listened& listened, const Output& out) {
  // a message is due once the simulated time reaches its next time (within rounding)
  const double eps = 1e-9;
  const ServedRobotOptions& ro = robot_->GetOptions();
  // which streams are due and listened to, asked before anything is read
  const bool imu = robot_->GetImu() && t + eps >= imu_next_ && listened(SensorStream::kImu, 0);
  struct Want {
    bool image = false, points = false, info = false;
  };
  std::vector<Want> want(cameras_.size());
  for (size_t i = 0; i < cameras_.size(); ++i) {
    if (t + eps >= cameras_[i].next_picture) {
      want[i].image = listened(SensorStream::kImage, i);
      want[i].points = listened(SensorStream::kPoints, i);
    }
    if (t + eps >= cameras_[i].next_info) want[i].info = listened(SensorStream::kCameraInfo, i);
  }
  if (imu) {
    imu_next_ = ro.imu_rate > 0 ? t + 1.0 / ro.imu_rate : 0;
    out.imu(robot_->GetImu()->Read());
  }
  const double period = ro.camera_rate > 0 ? 1.0 / ro.camera_rate : 0;
  for (size_t i = 0; i < cameras_.size(); ++i) {
    if (want[i].image || want[i].points) {
      const Camera& pictured = robot_->TakePicture(i);
      cameras_[i].next_picture = t + period;
      out.picture(i, pictured, want[i].image, want[i].points);
    }
    if (want[i].info) {
      cameras_[i].next_info = t + period;
      out.camera_info(i, robot_->GetCameras()[i].camera);
    }
  }
}

std::vector<uint8_t> CameraRgb8(const Camera& cam) {
  const size_t n = static_cast<size_t>(cam.GetWidth()) * cam.GetHeight();
  std::vector<uint8_t> rgba = cam.GetColorRGBA8(), rgb(n * 3);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) rgb[i * 3 + k] = rgba[i * 4 + k];
  return rgb;
}

std::vector<float> CameraOpticalPoints(const Camera& cam) {
  PointCloud pc = MakePointCloud(cam, PointCloudFrame::kCamera);
  std::vector<float> xyz(pc.positions.size());
  for (size_t i = 0; i < pc.Size(); ++i) {  // OpenGL camera frame to the optical frame
    xyz[3 * i] = pc.positions[3 * i];
    xyz[3 * i + 1] = -pc.positions[3 * i + 1];
    xyz[3 * i + 2] = -pc.positions[3 * i + 2];
  }
  return xyz;
}

std::vector<double> CameraProjection(const Camera& cam) {
  Eigen::Matrix3d K = cam.GetIntrinsicMatrix();
  std::vector<double> p;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) p.push_back(K(r, c));
    p.push_back(0.0);
  }
  return p;
}

}  // namespace partsim
