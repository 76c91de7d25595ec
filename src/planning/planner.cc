// Motion planning with OMPL over a private clone of the scene; collisions from a proximity
// query (partsim/physics/proximity.h) with the arm's moving links inflated by the clearance.
#include "partsim/planning/planner.h"

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/kpiece/KPIECE1.h>
#include <ompl/geometric/planners/prm/PRM.h>
#include <ompl/geometric/planners/rrt/RRT.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>

#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "partsim/physics/proximity.h"
#include "partsim/robot/kinematics.h"

namespace partsim {

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

bool Cancelled(const PlannerOptions& opt) { return opt.cancel && opt.cancel->load(); }

}  // namespace

struct MotionPlanner::Impl {
  Articulation arm;
  std::vector<std::string> names;
  std::vector<int> dofs;  ///< articulation dof index per planned joint
  Eigen::VectorXd velocity_limits, acceleration_limits;
  Eigen::MatrixX2d limits;          ///< planned joints, (lower, upper)
  std::vector<uint64_t> link_mask;  ///< per link: bit p set when planned joint p moves it

  // snapshot: the world as it was, with the arm's moving links as the queried shapes
  std::unique_ptr<ProximityQuery> world;
  Articulation world_arm;
  Eigen::VectorXd base_q;    ///< the arm's full qpos at the snapshot
  std::vector<bool> moving;  ///< per link: moved by a planned joint

  void Snapshot() {
    if (world)
      world->Refresh();
    else
      world = std::make_unique<ProximityQuery>(arm);
    world_arm = world->GetArticulation();
    base_q = arm.GetQpos();
    moving.assign(link_mask.size(), false);
    for (size_t l = 0; l < link_mask.size(); ++l) moving[l] = link_mask[l] != 0;
  }

  Eigen::VectorXd Full(const Eigen::VectorXd& q) const {
    Eigen::VectorXd full = base_q;
    for (size_t i = 0; i < dofs.size(); ++i) full[dofs[i]] = q[static_cast<Eigen::Index>(i)];
    return full;
  }

  // The name of a shape's body in the snapshot.
  std::string BodyName(const ShapeOwner& o) const {
    Scene& scene = world->GetScene();
    if (o.actor_id >= 0) return "actor '" + Actor(&scene, o.actor_id).GetName() + "'";
    const Articulation art(&scene, o.articulation_id);
    if (o.articulation_id == arm.GetId())
      return "link '" + art.GetLink(o.link_index).GetName() + "'";
    return "link '" + art.GetLink(o.link_index).GetName() + "' of articulation '" + art.GetName() +
           "'";
  }

  bool Check(const Eigen::VectorXd& q, double clearance, std::string* reason) {
    for (Eigen::Index i = 0; i < q.size(); ++i)
      if (!(q[i] >= limits(i, 0) - 1e-9 && q[i] <= limits(i, 1) + 1e-9)) {
        if (reason) {
          std::ostringstream os;
          os << "joint '" << names[i] << "' = " << q[i] << " is outside its limits ["
             << limits(i, 0) << ", " << limits(i, 1) << "]";
          *reason = os.str();
        }
        return false;
      }
    if (!world) Snapshot();
    world_arm.SetQpos(Full(q));
    // the moving links against everything within the clearance, and against the arm's links
    // that move otherwise only when they penetrate
    for (const ShapeProximity& c : world->Query(clearance, moving)) {
      const int l0 = c.shape0.link_index;
      const int l1 = c.shape1.articulation_id == arm.GetId() ? c.shape1.link_index : -1;
      const bool bad =
          l1 >= 0 ? link_mask[l0] != link_mask[l1] && c.distance < 0 : c.distance < clearance;
      if (!bad) continue;
      if (reason) {
        std::ostringstream os;
        os << BodyName(c.shape0) << " and " << BodyName(c.shape1) << " are " << c.distance
           << " m apart (clearance " << clearance << " m)";
        *reason = os.str();
      }
      return false;
    }
    return true;
  }

  void CheckVector(const Eigen::VectorXd& v, const char* what) const {
    if (v.size() != static_cast<Eigen::Index>(dofs.size()))
      throw Error(std::string("MotionPlanner: ") + what + " has " + std::to_string(v.size()) +
                  " entries, expected " + std::to_string(dofs.size()) + " (one per planned joint)");
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (!std::isfinite(v[i]))
        throw Error(std::string("MotionPlanner: ") + what + " entry " + std::to_string(i) + " ('" +
                    names[i] + "') is not finite");
  }

  PlanResult Plan(const Eigen::VectorXd& goal, const PlannerOptions& opt,
                  std::chrono::steady_clock::time_point t0);
};

namespace {

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void CheckPlannerOptions(const PlannerOptions& opt) {
  if (!(opt.time_limit > 0) || !std::isfinite(opt.time_limit))
    throw Error("PlannerOptions: time_limit must be finite and > 0");
  if (!(opt.resolution > 0) || !std::isfinite(opt.resolution))
    throw Error("PlannerOptions: resolution must be finite and > 0");
  if (!(opt.clearance >= 0) || !std::isfinite(opt.clearance))
    throw Error("PlannerOptions: clearance must be finite and >= 0");
  static const char* known[] = {"RRTConnect", "RRT", "RRTstar", "PRM", "KPIECE1"};
  if (std::find(std::begin(known), std::end(known), opt.algorithm) == std::end(known))
    throw Error("PlannerOptions: unknown algorithm '" + opt.algorithm +
                "' (RRTConnect, RRT, RRTstar, PRM or KPIECE1)");
}

namespace {

ob::PlannerPtr MakePlanner(const std::string& name, const ob::SpaceInformationPtr& si) {
  if (name == "RRT") return std::make_shared<og::RRT>(si);
  if (name == "RRTstar") return std::make_shared<og::RRTstar>(si);
  if (name == "PRM") return std::make_shared<og::PRM>(si);
  if (name == "KPIECE1") return std::make_shared<og::KPIECE1>(si);
  return std::make_shared<og::RRTConnect>(si);
}

/// Inserts waypoints so that no joint moves more than `step` between two of them.
std::vector<Eigen::VectorXd> Densify(const std::vector<Eigen::VectorXd>& path, double step) {
  std::vector<Eigen::VectorXd> out = {path.front()};
  for (size_t i = 1; i < path.size(); ++i) {
    double d = (path[i] - path[i - 1]).cwiseAbs().maxCoeff();
    int n = std::max(1, static_cast<int>(std::ceil(d / step)));
    for (int k = 1; k <= n; ++k)
      out.push_back(path[i - 1] + (path[i] - path[i - 1]) * (static_cast<double>(k) / n));
  }
  return out;
}

/// TimeParameterize only ever slows a trajectory down from its rest-to-rest first guess; this
/// scales time uniformly so that the fastest joint just meets its velocity or acceleration
/// limit (2 % margin for the sampling). Positions along the path do not change.
void SpeedUp(JointTrajectory* t, const Eigen::VectorXd& vmax, const Eigen::VectorXd& amax) {
  const double duration = t->Duration();
  if (!(duration > 0)) return;
  double r = 0.0;
  Eigen::VectorXd q, qd, qdd;
  for (int k = 0; k <= 1000; ++k) {
    t->Sample(duration * k / 1000.0, &q, &qd, &qdd);
    r = std::max({r, qd.cwiseQuotient(vmax).cwiseAbs().maxCoeff(),
                  std::sqrt(qdd.cwiseQuotient(amax).cwiseAbs().maxCoeff())});
  }
  const double s = r * 1.02;  // new time = s * old time
  if (!(s > 0) || s >= 1.0) return;
  for (double& time : t->times) time *= s;
  for (Eigen::VectorXd& v : t->velocities) v /= s;
  for (Eigen::VectorXd& a : t->accelerations) a /= s * s;
}

/// Rest-to-rest quintic segments between the waypoints: the trajectory keeps exactly to the
/// straight segments of the path. Each segment lasts as long as its slowest joint needs (peak
/// velocity 15/8 d/T, peak acceleration 10/sqrt(3) d/T^2).
JointTrajectory StopAtEveryWaypoint(const std::vector<Eigen::VectorXd>& path,
                                    const Eigen::VectorXd& vmax, const Eigen::VectorXd& amax) {
  JointTrajectory t;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(path.front().size());
  double time = 0.0;
  for (size_t i = 0; i < path.size(); ++i) {
    if (i > 0) {
      double h = 1e-3;
      for (Eigen::Index k = 0; k < zero.size(); ++k) {
        const double d = std::abs(path[i][k] - path[i - 1][k]);
        h = std::max({h, 1.875 * d / vmax[k], std::sqrt(5.7736 * d / amax[k])});
      }
      time += h;
    }
    t.times.push_back(time);
    t.positions.push_back(path[i]);
    t.velocities.push_back(zero);
    t.accelerations.push_back(zero);
  }
  return t;
}

}  // namespace

MotionPlanner::MotionPlanner(const Articulation& arm, const std::vector<std::string>& joints,
                             const Eigen::VectorXd& velocity_limits,
                             const Eigen::VectorXd& acceleration_limits)
    : impl_(std::make_unique<Impl>()) {
  Impl& p = *impl_;
  p.arm = arm;
  if (joints.empty()) {
    for (const Joint& j : arm.GetActiveJoints()) p.names.push_back(j.GetName());
  } else {
    p.names = joints;
  }
  if (p.names.empty())
    throw Error("MotionPlanner: articulation '" + arm.GetName() + "' has no dof");
  if (p.names.size() > 64) throw Error("MotionPlanner: at most 64 planned joints");
  const int n = static_cast<int>(p.names.size());
  Eigen::MatrixX2d all = arm.GetQlimits();
  p.limits.resize(n, 2);
  std::vector<int> planned_of_link(arm.GetLinks().size(), -1);
  for (int i = 0; i < n; ++i) {
    Joint j = arm.FindJointByName(p.names[i]);
    if (j.GetDofIndex() < 0)
      throw Error("MotionPlanner: joint '" + p.names[i] + "' has no dof of its own");
    if (std::find(p.dofs.begin(), p.dofs.end(), j.GetDofIndex()) != p.dofs.end())
      throw Error("MotionPlanner: joint '" + p.names[i] + "' is listed twice");
    p.dofs.push_back(j.GetDofIndex());
    planned_of_link[j.GetIndex()] = i;
    p.limits.row(i) = all.row(j.GetDofIndex());
    // unlimited joints are sampled over one turn either way
    if (!std::isfinite(p.limits(i, 0))) p.limits(i, 0) = -2 * M_PI;
    if (!std::isfinite(p.limits(i, 1))) p.limits(i, 1) = 2 * M_PI;
  }
  // which planned joints move each link: those on its path to the root
  std::vector<Link> links = arm.GetLinks();
  p.link_mask.assign(links.size(), 0);
  for (size_t l = 0; l < links.size(); ++l) {
    uint64_t mask = 0;
    for (int k = static_cast<int>(l); k >= 0; k = links[k].GetParentIndex())
      if (planned_of_link[k] >= 0) mask |= uint64_t{1} << planned_of_link[k];
    p.link_mask[l] = mask;
  }
  p.velocity_limits =
      velocity_limits.size() == 0 ? Eigen::VectorXd::Constant(n, 1.0) : velocity_limits;
  p.acceleration_limits =
      acceleration_limits.size() == 0 ? Eigen::VectorXd::Constant(n, 2.0) : acceleration_limits;
  p.CheckVector(p.velocity_limits, "velocity_limits");
  p.CheckVector(p.acceleration_limits, "acceleration_limits");
  if (!(p.velocity_limits.minCoeff() > 0) || !(p.acceleration_limits.minCoeff() > 0))
    throw Error("MotionPlanner: velocity and acceleration limits must be > 0");
}

MotionPlanner::~MotionPlanner() = default;

const std::vector<std::string>& MotionPlanner::GetJointNames() const { return impl_->names; }

Eigen::VectorXd MotionPlanner::GetCurrentPositions() const {
  Eigen::VectorXd full = impl_->arm.GetQpos(), q(impl_->dofs.size());
  for (size_t i = 0; i < impl_->dofs.size(); ++i)
    q[static_cast<Eigen::Index>(i)] = full[impl_->dofs[i]];
  return q;
}

void MotionPlanner::UpdateSnapshot() { impl_->Snapshot(); }

bool MotionPlanner::IsStateValid(const Eigen::VectorXd& q, double clearance, std::string* reason) {
  impl_->CheckVector(q, "q");
  if (!(clearance >= 0) || !std::isfinite(clearance))
    throw Error("MotionPlanner: clearance must be finite and >= 0");
  return impl_->Check(q, clearance, reason);
}

PlanResult MotionPlanner::PlanToJoints(const Eigen::VectorXd& goal, const PlannerOptions& options) {
  auto t0 = std::chrono::steady_clock::now();
  impl_->CheckVector(goal, "goal");
  CheckPlannerOptions(options);
  if (!options.use_last_snapshot || !impl_->world) impl_->Snapshot();
  return impl_->Plan(goal, options, t0);
}

PlanResult MotionPlanner::Impl::Plan(const Eigen::VectorXd& goal_in, const PlannerOptions& opt,
                                     std::chrono::steady_clock::time_point t0) {
  PlanResult r;
  auto fail = [&](const std::string& msg) {
    r.success = false;
    r.message = msg;
    r.planning_time = Seconds(t0);
    return r;
  };
  const int n = static_cast<int>(dofs.size());
  Eigen::VectorXd start(n);
  for (int i = 0; i < n; ++i) start[i] = base_q[dofs[i]];
  // a start a hair outside the limits (physics: a joint resting on its limit), or a goal taken
  // from such a state, is pulled in
  Eigen::VectorXd goal = goal_in;
  for (Eigen::VectorXd* q : {&start, &goal})
    for (int i = 0; i < n; ++i)
      if ((*q)[i] >= limits(i, 0) - 1e-3 && (*q)[i] <= limits(i, 1) + 1e-3)
        (*q)[i] = std::clamp((*q)[i], limits(i, 0), limits(i, 1));
  std::string why;
  if (!Check(goal, opt.clearance, &why)) return fail("the goal is not valid: " + why);
  if (!Check(start, opt.clearance, &why)) return fail("the start is not valid: " + why);

  // OMPL problem over the planned joints
  ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);
  auto space = std::make_shared<ob::RealVectorStateSpace>(n);
  ob::RealVectorBounds bounds(n);
  for (int i = 0; i < n; ++i) {
    bounds.setLow(i, limits(i, 0));
    bounds.setHigh(i, std::max(limits(i, 1), limits(i, 0) + 1e-9));
  }
  space->setBounds(bounds);
  og::SimpleSetup ss(space);
  const double clearance = opt.clearance;
  ss.setStateValidityChecker([this, n, clearance](const ob::State* s) {
    const auto* v = s->as<ob::RealVectorStateSpace::StateType>();
    Eigen::VectorXd q(n);
    for (int i = 0; i < n; ++i) q[i] = v->values[i];
    return Check(q, clearance, nullptr);
  });
  ss.getSpaceInformation()->setStateValidityCheckingResolution(
      std::min(1.0, opt.resolution / std::max(1e-9, space->getMaximumExtent())));
  ss.setPlanner(MakePlanner(opt.algorithm, ss.getSpaceInformation()));
  ob::ScopedState<> s0(space), s1(space);
  for (int i = 0; i < n; ++i) {
    s0[i] = start[i];
    s1[i] = goal[i];
  }
  ss.setStartAndGoalStates(s0, s1, 1e-4);

  // is every state of a timed trajectory, sampled at the path's resolution, collision-free?
  const double dt = opt.resolution / velocity_limits.maxCoeff();
  auto timed_ok = [&](const JointTrajectory& t) {
    Eigen::VectorXd q;
    for (double time = 0; time < t.Duration() + dt; time += dt) {
      t.Sample(std::min(time, t.Duration()), &q);
      if (!Check(q, clearance, &why)) return false;
    }
    return true;
  };
  // OMPL checks the path's segments at discrete states, so a path found may still graze an
  // obstacle between them, and the spline through it may cut corners: a path whose timing fails
  // is planned again while the time limit allows (at least twice)
  for (int round = 0;; ++round) {
    const double left = opt.time_limit - Seconds(t0);
    if (round > 0) {
      if (round > 2 && left <= 0) break;
      ss.clear();
    }
    // the time left, or sooner when the caller cancels
    const double budget = std::max(left, round == 0 ? opt.time_limit : 0.25);
    const std::atomic<bool>* cancel = opt.cancel;
    ob::PlannerStatus status = ss.solve(ob::plannerOrTerminationCondition(
        ob::timedPlannerTerminationCondition(budget),
        ob::PlannerTerminationCondition([cancel] { return cancel && cancel->load(); })));
    if (Cancelled(opt)) return fail("cancelled");
    if (!status || !ss.haveExactSolutionPath()) {
      if (round > 0) break;
      return fail("no collision-free path found in " + FormatNumber(opt.time_limit) + " s (" +
                  opt.algorithm + ")");
    }
    if (opt.simplify) ss.simplifySolution(1.0);
    const og::PathGeometric& path = ss.getSolutionPath();
    std::vector<Eigen::VectorXd> waypoints;
    for (std::size_t k = 0; k < path.getStateCount(); ++k) {
      const auto* v = path.getState(k)->as<ob::RealVectorStateSpace::StateType>();
      Eigen::VectorXd q(n);
      for (int i = 0; i < n; ++i) q[i] = v->values[i];
      waypoints.push_back(q);
    }
    waypoints.front() = start;
    if ((waypoints.back() - goal).cwiseAbs().maxCoeff() > 0) waypoints.push_back(goal);

    // time it: a smooth spline through the waypoints, densified until it stays collision-free;
    // failing that, a stop at every waypoint, which keeps exactly to the straight segments
    auto done = [&](JointTrajectory t) {
      r.path = waypoints;
      r.trajectory = std::move(t);
      r.success = true;
      r.message.clear();
      r.planning_time = Seconds(t0);
      return r;
    };
    double step = 0.8;
    for (int attempt = 0; attempt < 7; ++attempt, step /= 2) {
      JointTrajectory t =
          TimeParameterize(Densify(waypoints, step), velocity_limits, acceleration_limits);
      SpeedUp(&t, velocity_limits, acceleration_limits);
      if (timed_ok(t)) return done(std::move(t));
    }
    JointTrajectory stops = StopAtEveryWaypoint(waypoints, velocity_limits, acceleration_limits);
    if (timed_ok(stops)) return done(std::move(stops));
  }
  return fail("the timed trajectory leaves the collision-free path: " + why);
}

PlanResult MotionPlanner::PlanToPose(const std::string& link, const Pose& tcp_offset,
                                     const Pose& target, const PlannerOptions& options) {
  auto t0 = std::chrono::steady_clock::now();
  Impl& p = *impl_;
  CheckPlannerOptions(options);
  if (!target.p.allFinite() || !target.q.coeffs().allFinite())
    throw Error("MotionPlanner::PlanToPose: target is not finite");
  if (!options.use_last_snapshot || !p.world) p.Snapshot();
  KinematicModel model = KinematicModel::FromArticulation(p.world_arm);
  const int link_index = model.LinkIndex(link);
  IkOptions ik;
  ik.offset = tcp_offset;
  ik.active.assign(model.Dof(), false);
  for (int d : p.dofs) ik.active[d] = true;
  ik.restarts = 0;
  const int n = static_cast<int>(p.dofs.size());
  Eigen::VectorXd start(n);
  for (int i = 0; i < n; ++i) start[i] = p.base_q[p.dofs[i]];
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  bool found = false;
  Eigen::VectorXd best;
  std::string last = "IK found no solution";
  for (int a = 0; a < std::max(1, options.ik_attempts); ++a) {
    if (Cancelled(options)) {
      last = "cancelled";
      break;
    }
    Eigen::VectorXd init = p.base_q;
    if (a > 0)
      for (int i = 0; i < n; ++i)
        init[p.dofs[i]] = p.limits(i, 0) + u(rng) * (p.limits(i, 1) - p.limits(i, 0));
    IkResult res = InverseKinematics(model, link_index, target, init, ik);
    if (!res.success) {
      last = "IK: " + res.message;
      continue;
    }
    Eigen::VectorXd q(n);
    for (int i = 0; i < n; ++i) q[i] = res.q[p.dofs[i]];
    std::string why;
    if (!p.Check(q, options.clearance, &why)) {
      last = "IK solution in collision: " + why;
      continue;
    }
    if (!found || (q - start).norm() < (best - start).norm()) best = q;
    found = true;
  }
  if (!found) {
    PlanResult r;
    r.message = "no valid joint goal for the pose (" + std::to_string(options.ik_attempts) +
                " IK attempts; last: " + last + ")";
    r.planning_time = Seconds(t0);
    return r;
  }
  return p.Plan(best, options, t0);
}

}  // namespace partsim
