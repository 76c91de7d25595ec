// Damped least-squares inverse kinematics over the forward kinematics and Jacobians of
// KinematicModel (partsim/physics/kinematics.h), without MuJoCo.
#include "partsim/robot/kinematics.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "partsim/core/error.h"

namespace partsim {

Eigen::Matrix<double, 6, 1> PoseError(const Pose& current, const Pose& target) {
  Eigen::Matrix<double, 6, 1> e;
  e.head<3>() = target.p - current.p;
  Eigen::Quaterniond r = target.q.normalized() * current.q.normalized().conjugate();
  if (r.w() < 0) r.coeffs() = -r.coeffs();
  Eigen::Vector3d v = r.vec();
  double s = v.norm();
  // axis * angle, with angle = 2 atan2(|v|, w); the small-angle limit is 2 v / w
  e.tail<3>() = s < 1e-12 ? Eigen::Vector3d(2.0 * v / r.w())
                          : Eigen::Vector3d(v / s * 2.0 * std::atan2(s, r.w()));
  return e;
}

namespace {

// squared norm of the part of the error IK minimises
double Cost(const Eigen::Matrix<double, 6, 1>& e, bool position_only) {
  return position_only ? e.head<3>().squaredNorm() : e.squaredNorm();
}

Eigen::VectorXd Clamp(const Eigen::VectorXd& q, const Eigen::MatrixX2d& limits) {
  return q.cwiseMax(limits.col(0)).cwiseMin(limits.col(1));
}

}  // namespace

IkResult InverseKinematics(const KinematicModel& model, int link, const Pose& target,
                           const Eigen::VectorXd& q_init, const IkOptions& options) {
  const int dof = model.Dof();
  model.CheckLinkIndex(link);
  model.CheckJointPositions(q_init, "IK q_init");
  if (!target.p.allFinite() || !target.q.coeffs().allFinite() || target.q.norm() < 1e-9)
    throw Error("InverseKinematics: target pose " + target.ToString() + " is not finite");
  if (!options.offset.IsValid()) throw Error("InverseKinematics: options.offset is not valid");
  if (!options.active.empty() && static_cast<int>(options.active.size()) != dof)
    throw Error("InverseKinematics: options.active has " + std::to_string(options.active.size()) +
                " entries, the model has " + std::to_string(dof) + " dof");
  if (!(options.position_tolerance > 0) || !(options.rotation_tolerance > 0))
    throw Error("InverseKinematics: tolerances must be > 0");
  if (options.max_iterations < 1 || options.restarts < 0 || !(options.max_step > 0) ||
      !(options.damping >= 0))
    throw Error(
        "InverseKinematics: max_iterations must be >= 1, restarts >= 0, max_step > 0 and "
        "damping >= 0");
  Pose goal = target;
  goal.q.normalize();
  const Eigen::MatrixX2d limits = model.Limits();
  const bool pos_only = options.position_only;
  const int rows = pos_only ? 3 : 6;
  Eigen::VectorXd mask = Eigen::VectorXd::Ones(dof);
  for (int k = 0; k < dof && !options.active.empty(); ++k) mask[k] = options.active[k] ? 1 : 0;

  IkResult best;
  best.q = Clamp(q_init, limits);
  double best_cost = kInf;
  std::mt19937 rng(options.seed);
  int total_iterations = 0;

  auto evaluate = [&](const Eigen::VectorXd& q) {
    return PoseError(model.LinkPose(q, link, options.offset), goal);
  };
  auto done = [&](const Eigen::Matrix<double, 6, 1>& e) {
    return e.head<3>().norm() <= options.position_tolerance &&
           (pos_only || e.tail<3>().norm() <= options.rotation_tolerance);
  };
  auto record = [&](const Eigen::VectorXd& q, const Eigen::Matrix<double, 6, 1>& e) {
    // the best q is the one that meets the tolerances, else the smallest error
    double c = Cost(e, pos_only) * (done(e) ? 0.0 : 1.0);
    if (c < best_cost || (c == best_cost && !best.success)) {
      best_cost = c;
      best.q = q;
      best.position_error = e.head<3>().norm();
      best.rotation_error = e.tail<3>().norm();
      best.success = done(e);
    }
  };

  for (int attempt = 0; attempt <= options.restarts && !best.success; ++attempt) {
    Eigen::VectorXd q = Clamp(q_init, limits);
    if (attempt > 0) {
      // a random start inside the limits (around q_init for unlimited joints)
      std::uniform_real_distribution<double> u(0.0, 1.0);
      for (int k = 0; k < dof; ++k) {
        if (mask[k] == 0) continue;
        double lo = std::isfinite(limits(k, 0)) ? limits(k, 0) : q_init[k] - M_PI;
        double hi = std::isfinite(limits(k, 1)) ? limits(k, 1) : q_init[k] + M_PI;
        q[k] = lo + (hi - lo) * u(rng);
      }
    }
    Eigen::Matrix<double, 6, 1> e = evaluate(q);
    double cost = Cost(e, pos_only);
    record(q, e);
    double lambda = std::max(options.damping, 1e-6);
    double window_cost = cost;  // cost at the start of the current progress window
    for (int it = 0; it < options.max_iterations && !done(e); ++it) {
      ++total_iterations;
      Eigen::MatrixXd J = model.Jacobian(q, link, options.offset).topRows(rows);
      for (int k = 0; k < dof; ++k) J.col(k) *= mask[k];
      Eigen::VectorXd err = e.head(rows);
      // damped least squares; a joint whose step would cross a limit stops at the limit and
      // the others solve for what remains of the error
      Eigen::VectorXd dq = Eigen::VectorXd::Zero(dof), fixed = Eigen::VectorXd::Zero(dof);
      for (int pass = 0; pass <= dof; ++pass) {
        Eigen::MatrixXd A = J * J.transpose();
        A.diagonal().array() += lambda * lambda;
        dq = fixed + J.transpose() * A.ldlt().solve(err);
        bool froze = false;
        for (int k = 0; k < dof; ++k) {
          if (J.col(k).squaredNorm() == 0) continue;
          double bound = q[k] + dq[k] < limits(k, 0)   ? limits(k, 0)
                         : q[k] + dq[k] > limits(k, 1) ? limits(k, 1)
                                                       : q[k] + dq[k];
          if (bound == q[k] + dq[k]) continue;
          fixed[k] = bound - q[k];
          err -= J.col(k) * fixed[k];
          J.col(k).setZero();
          froze = true;
        }
        if (!froze) break;
      }
      double largest = dq.cwiseAbs().maxCoeff();
      if (largest > options.max_step) dq *= options.max_step / largest;
      Eigen::VectorXd q_new = Clamp(q + dq, limits);
      Eigen::Matrix<double, 6, 1> e_new = evaluate(q_new);
      double cost_new = Cost(e_new, pos_only);
      // adaptive damping (Levenberg-Marquardt): accept improvements, else damp harder
      if (cost_new < cost) {
        q = q_new;
        e = e_new;
        cost = cost_new;
        lambda = std::max(lambda * 0.3, 1e-6);
        record(q, e);
      } else {
        lambda *= 4.0;
      }
      // stuck in a local minimum or at the limits: restart
      if (lambda > 1e3) break;
      if ((it + 1) % 30 == 0) {
        if (cost > 0.8 * window_cost) break;
        window_cost = cost;
      }
    }
  }
  best.iterations = total_iterations;
  if (!best.success) {
    std::ostringstream s;
    s << "InverseKinematics: target out of reach of link " << link << ": closest position error "
      << best.position_error << " m";
    if (!pos_only) s << ", rotation error " << best.rotation_error << " rad";
    s << " after " << total_iterations << " iterations and " << options.restarts << " restarts";
    best.message = s.str();
  }
  return best;
}

}  // namespace partsim
