// Kinematics of an articulation over its description, without MuJoCo. A link's pose is
//   X_WL = X_WP * pose_in_parent * motion(q) * pose_in_child^-1,
// where motion(q) rotates about x by q (revolute, continuous, screw), translates along x by q
// (prismatic) or by pitch * q (screw), the convention of the compiler (src/physics/compiler.cc).
// Dofs are numbered as the compiler numbers them: one per joint that is not fixed, in link
// order.
#include "partsim/physics/kinematics.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <string>

#include "partsim/core/error.h"

namespace partsim {

std::vector<int> DofLinks(const ArticulationDesc& art) {
  std::vector<int> out;
  for (size_t i = 0; i < art.links.size(); ++i)
    if (art.links[i].parent >= 0 && art.links[i].joint.type != JointType::kFixed)
      out.push_back(static_cast<int>(i));
  return out;
}

Eigen::MatrixX2d DofLimits(const ArticulationDesc& art) {
  const std::vector<int> dof_links = DofLinks(art);
  Eigen::MatrixX2d out(static_cast<Eigen::Index>(dof_links.size()), 2);
  for (size_t k = 0; k < dof_links.size(); ++k) {
    const JointDesc& j = art.links[dof_links[k]].joint;
    const bool limited = j.type != JointType::kContinuous;
    out(k, 0) = limited ? j.lower : -kInf;
    out(k, 1) = limited ? j.upper : kInf;
  }
  return out;
}

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
  std::vector<int> dof_links;  ///< dof -> link
  Eigen::MatrixX2d limits;
  std::map<std::string, int> link_by_name, link_by_joint;
};

namespace {

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
  root_pose_.q.normalize();
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
  data->dof_links = DofLinks(art);
  for (size_t k = 0; k < data->dof_links.size(); ++k)
    data->links[data->dof_links[k]].dof = static_cast<int>(k);
  data->limits = DofLimits(art);
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

void KinematicModel::CheckJointPositions(const Eigen::VectorXd& q, const char* what) const {
  if (q.size() != Dof())
    throw Error(std::string("KinematicModel: ") + what + " has " + std::to_string(q.size()) +
                " entries, the model has " + std::to_string(Dof()) + " dof");
  for (Eigen::Index i = 0; i < q.size(); ++i)
    if (!std::isfinite(q[i]))
      throw Error(std::string("KinematicModel: ") + what + "[" + std::to_string(i) +
                  "] is not finite");
}

void KinematicModel::CheckLinkIndex(int link) const {
  if (link < 0 || link >= NumLinks())
    throw IndexError("KinematicModel: link index " + std::to_string(link) +
                     " is out of range (model has " + std::to_string(NumLinks()) + " links)");
}

std::vector<Pose> KinematicModel::ForwardKinematics(const Eigen::VectorXd& q) const {
  CheckJointPositions(q, "q");
  const Data& d = *data_;
  std::vector<Pose> X_WL(d.links.size());
  // Validate has checked that parents come before their children
  for (size_t i = 0; i < d.links.size(); ++i) {
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
  CheckLinkIndex(link);
  return ForwardKinematics(q)[link] * offset;
}

Eigen::MatrixXd KinematicModel::Jacobian(const Eigen::VectorXd& q, int link,
                                         const Pose& offset) const {
  CheckLinkIndex(link);
  const Data& d = *data_;
  std::vector<Pose> X_WL = ForwardKinematics(q);
  const Eigen::Vector3d p = (X_WL[link] * offset).p;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, Dof());
  // every moving joint between the link and the root adds its column
  for (int i = link; i >= 0 && d.links[i].parent >= 0; i = d.links[i].parent) {
    const Data::LinkInfo& li = d.links[i];
    if (li.type == JointType::kFixed) continue;
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

}  // namespace partsim
