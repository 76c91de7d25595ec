// Forward kinematics, geometric Jacobians and damped least-squares inverse kinematics over an
// ArticulationDesc, without MuJoCo. A link's pose is
//   X_WL = X_WP * pose_in_parent * motion(q) * pose_in_child^-1,
// where motion(q) rotates about x by q (revolute, continuous, screw), translates along x by q
// (prismatic) or by pitch * q (screw), the convention of the compiler (src/physics/compiler.cc).
#include "partsim/robot/kinematics.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <sstream>

#include "partsim/core/error.h"

namespace partsim {

struct KinematicModel::Data {
  struct LinkInfo {
    std::string name;
    int parent = -1;
    JointType type = JointType::kFixed;
    std::string joint_name;
    Pose X_PJ;  ///< pose_in_parent
    Pose X_JC;  ///< pose_in_child^-1
    double pitch = 0.0;
    int dof = -1;  ///< dof index, -1 for fixed or root
    // coupled joints: q = multiplier * q[source link] + offset
    int coupling_source_link = -1;
    double multiplier = 1.0;
    double offset = 0.0;
  };
  std::vector<LinkInfo> links;
  std::vector<int> order;      ///< link indices, parents first
  std::vector<int> dof_links;  ///< dof -> link
  Eigen::MatrixX2d limits;
  std::map<std::string, int> link_by_name, link_by_joint;
};

namespace {

bool Moves(JointType t) { return t != JointType::kFixed; }

// motion(q) of a joint in its own frame
Pose Motion(JointType type, double q, double pitch) {
  Pose m;
  switch (type) {
    case JointType::kPrismatic:
      m.p.x() = q;
      break;
    case JointType::kRevolute:
    case JointType::kContinuous:
      m.q = Eigen::AngleAxisd(q, Eigen::Vector3d::UnitX());
      break;
    case JointType::kScrew:
      m.q = Eigen::AngleAxisd(q, Eigen::Vector3d::UnitX());
      m.p.x() = pitch * q;
      break;
    case JointType::kFixed:
      break;
  }
  return m;
}

}  // namespace

KinematicModel::KinematicModel(const ArticulationDesc& art) : root_pose_(art.root_pose) {
  Validate(art, "KinematicModel");
  auto data = std::make_shared<Data>();
  const size_t n = art.links.size();
  data->links.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const LinkDesc& l = art.links[i];
    Data::LinkInfo& li = data->links[i];
    li.name = l.name;
    li.parent = l.parent;
    data->link_by_name.emplace(l.name, static_cast<int>(i));
    if (l.parent < 0) continue;
    li.type = l.joint.type;
    li.joint_name = l.joint.name;
    li.X_PJ = l.joint.pose_in_parent;
    li.X_PJ.q.normalize();
    li.X_JC = l.joint.pose_in_child.Inverse();
    li.X_JC.q.normalize();
    li.pitch = l.joint.pitch;
    data->link_by_joint.emplace(l.joint.name, static_cast<int>(i));
  }
  // couplings: the coupled joint keeps its dof, but its motion follows its source
  for (const JointCoupling& c : art.couplings) {
    auto j = data->link_by_joint.find(c.joint), s = data->link_by_joint.find(c.source);
    if (j == data->link_by_joint.end() || s == data->link_by_joint.end())
      throw Error("KinematicModel: coupling of joint '" + c.joint + "' to '" + c.source +
                  "' names a missing joint");
    Data::LinkInfo& li = data->links[j->second];
    li.coupling_source_link = s->second;
    li.multiplier = c.multiplier;
    li.offset = c.offset;
  }
  // dofs in link order, as the compiler numbers them
  for (size_t i = 0; i < n; ++i) {
    Data::LinkInfo& li = data->links[i];
    if (li.parent < 0 || !Moves(li.type)) continue;
    li.dof = static_cast<int>(data->dof_links.size());
    data->dof_links.push_back(static_cast<int>(i));
  }
  data->limits.resize(static_cast<Eigen::Index>(data->dof_links.size()), 2);
  for (size_t k = 0; k < data->dof_links.size(); ++k) {
    const JointDesc& j = art.links[data->dof_links[k]].joint;
    bool limited = j.type != JointType::kContinuous;
    data->limits(k, 0) = limited ? j.lower : -kInf;
    data->limits(k, 1) = limited ? j.upper : kInf;
  }
  // parents first (the description promises it, but do not rely on it)
  std::vector<int> state(n, 0);
  std::vector<int> stack;
  for (size_t i = 0; i < n; ++i) {
    // walk up to the first placed ancestor, then place the chain top-down
    stack.clear();
    for (int k = static_cast<int>(i); k >= 0 && !state[k]; k = data->links[k].parent)
      stack.push_back(k);
    for (auto it = stack.rbegin(); it != stack.rend(); ++it) {
      state[*it] = 1;
      data->order.push_back(*it);
    }
  }
  data_ = std::move(data);
}

KinematicModel KinematicModel::FromArticulation(const Articulation& articulation) {
  KinematicModel model(articulation.GetDesc());
  model.SetRootPose(articulation.GetRootPose());
  return model;
}

int KinematicModel::Dof() const { return static_cast<int>(data_->dof_links.size()); }
int KinematicModel::NumLinks() const { return static_cast<int>(data_->links.size()); }

int KinematicModel::LinkIndex(const std::string& name) const {
  auto it = data_->link_by_name.find(name);
  if (it == data_->link_by_name.end()) throw Error("KinematicModel: no link named '" + name + "'");
  return it->second;
}

int KinematicModel::DofIndex(const std::string& joint_name) const {
  auto it = data_->link_by_joint.find(joint_name);
  if (it == data_->link_by_joint.end())
    throw Error("KinematicModel: no joint named '" + joint_name + "'");
  return data_->links[it->second].dof;
}

Eigen::MatrixX2d KinematicModel::Limits() const { return data_->limits; }
const Pose& KinematicModel::GetRootPose() const { return root_pose_; }

void KinematicModel::SetRootPose(const Pose& pose) {
  if (!pose.IsValid()) throw Error("KinematicModel: root pose is not finite or not unit");
  root_pose_ = pose;
  root_pose_.q.normalize();
}

namespace {

void CheckQ(const Eigen::VectorXd& q, int dof, const char* what) {
  if (q.size() != dof)
    throw Error(std::string("KinematicModel: ") + what + " has " + std::to_string(q.size()) +
                " entries, the model has " + std::to_string(dof) + " dof");
  for (Eigen::Index i = 0; i < q.size(); ++i)
    if (!std::isfinite(q[i]))
      throw Error(std::string("KinematicModel: ") + what + "[" + std::to_string(i) +
                  "] is not finite");
}

void CheckLink(int link, int n) {
  if (link < 0 || link >= n)
    throw IndexError("KinematicModel: link index " + std::to_string(link) +
                     " is out of range (model has " + std::to_string(n) + " links)");
}

}  // namespace

std::vector<Pose> KinematicModel::ForwardKinematics(const Eigen::VectorXd& q) const {
  CheckQ(q, Dof(), "q");
  const Data& d = *data_;
  std::vector<Pose> X_WL(d.links.size());
  for (int i : d.order) {
    const Data::LinkInfo& li = d.links[i];
    if (li.parent < 0) {
      X_WL[i] = root_pose_;
      continue;
    }
    double qi = 0.0;
    if (li.dof >= 0) qi = q[li.dof];
    if (li.coupling_source_link >= 0)
      qi = li.multiplier * q[d.links[li.coupling_source_link].dof] + li.offset;
    X_WL[i] = X_WL[li.parent] * li.X_PJ * Motion(li.type, qi, li.pitch) * li.X_JC;
  }
  return X_WL;
}

Pose KinematicModel::LinkPose(const Eigen::VectorXd& q, int link, const Pose& offset) const {
  CheckLink(link, NumLinks());
  return ForwardKinematics(q)[link] * offset;
}

Eigen::MatrixXd KinematicModel::Jacobian(const Eigen::VectorXd& q, int link,
                                         const Pose& offset) const {
  CheckLink(link, NumLinks());
  const Data& d = *data_;
  std::vector<Pose> X_WL = ForwardKinematics(q);
  const Eigen::Vector3d p = (X_WL[link] * offset).p;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, Dof());
  // every moving joint between the link and the root adds its column
  for (int i = link; i >= 0 && d.links[i].parent >= 0; i = d.links[i].parent) {
    const Data::LinkInfo& li = d.links[i];
    if (!Moves(li.type)) continue;
    int col = li.dof;
    double factor = 1.0;
    if (li.coupling_source_link >= 0) {
      col = d.links[li.coupling_source_link].dof;
      factor = li.multiplier;
    }
    // the joint frame in the world (its x axis is the same before and after the motion)
    Pose X_WJ = X_WL[li.parent] * li.X_PJ;
    Eigen::Vector3d axis = X_WJ.q * Eigen::Vector3d::UnitX();
    Eigen::Matrix<double, 6, 1> c = Eigen::Matrix<double, 6, 1>::Zero();
    if (li.type == JointType::kPrismatic) {
      c.head<3>() = axis;
    } else {
      c.head<3>() = axis.cross(p - X_WJ.p);
      c.tail<3>() = axis;
      if (li.type == JointType::kScrew) c.head<3>() += li.pitch * axis;
    }
    J.col(col) += factor * c;
  }
  return J;
}

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
  CheckLink(link, model.NumLinks());
  CheckQ(q_init, dof, "IK q_init");
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
