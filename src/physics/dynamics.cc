// Free functions over the compiled model and the data: drives, forward dynamics and the
// dynamics queries.
#include "physics/dynamics.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <vector>

#include "partsim/core/check.h"

namespace partsim {
namespace internal {

namespace {

// Mass matrix over the articulation's MuJoCo dofs, without the inertia of backward-Euler drives.
Eigen::MatrixXd MjMassMatrix(const Model& model, const Data& data, const CompiledArticulation& c) {
  const mjModel* m = model.mj.get();
  const int nv = m->nv;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> full(nv, nv);
  mj_fullM(m, data.mj.get(), full.data());
  for (int k = 0; k < c.Dof(); ++k) {
    const CompiledJoint& j = c.DofJoint(k);
    full(j.dofadr, j.dofadr) -= j.drive.armature;
  }
  const int n = static_cast<int>(c.mj_dofs.size());
  Eigen::MatrixXd out(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) out(i, j) = full(c.mj_dofs[i], c.mj_dofs[j]);
  return out;
}

const CompiledArticulation& Dynamic(const Model& model, int articulation) {
  const CompiledArticulation& c = model.articulations.at(articulation);
  PARTSIM_DEMAND(!c.kinematic);
  return c;
}

}  // namespace

Eigen::VectorXd MjDofs(const CompiledArticulation& c, const double* src) {
  Eigen::VectorXd out(c.mj_dofs.size());
  for (size_t i = 0; i < c.mj_dofs.size(); ++i)
    out[static_cast<Eigen::Index>(i)] = src[c.mj_dofs[i]];
  return out;
}

void ApplyDrives(const Model& model, Data& data) {
  mjData* d = data.mj.get();
  for (const auto& [id, c] : model.articulations) {
    if (c.kinematic) continue;
    const ArticulationData& a = data.articulations.at(id);
    for (int k = 0; k < c.Dof(); ++k) {
      const CompiledJoint& j = c.DofJoint(k);
      d->ctrl[j.actuator] = j.drive.stiffness * a.drive_target[k] +
                            j.drive.damping * a.drive_velocity_target[k] -
                            j.drive.velocity_gain * d->qvel[j.dofadr];
    }
  }
}

void Forward(const Model& model, Data& data) {
  if (data.forward_valid) return;
  ApplyDrives(model, data);
  mj_forward(model.mj.get(), data.mj.get());
  data.forward_valid = true;
}

void Kinematics(const Model& model, Data& data) {
  if (data.kinematics_valid || data.forward_valid) return;
  const mjModel* m = model.mj.get();
  mjData* d = data.mj.get();
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  data.kinematics_valid = true;
}

Eigen::MatrixXd MassMatrix(const Model& model, const Data& data, int articulation) {
  const CompiledArticulation& c = Dynamic(model, articulation);
  return c.G.transpose() * MjMassMatrix(model, data, c) * c.G;
}

Eigen::VectorXd BiasForce(const Model& model, const Data& data, int articulation) {
  const CompiledArticulation& c = Dynamic(model, articulation);
  return c.G.transpose() * MjDofs(c, data.mj->qfrc_bias);
}

Eigen::VectorXd PassiveForce(const Model& model, Data& data, int articulation, bool gravity,
                             bool coriolis, bool external) {
  const CompiledArticulation& c = Dynamic(model, articulation);
  Forward(model, data);
  const mjModel* m = model.mj.get();
  mjData* d = data.mj.get();
  // qfrc_bias = C(q, qdot) qdot + g(q); gravity alone is the bias at zero velocity
  Eigen::VectorXd bias = MjDofs(c, d->qfrc_bias);
  Eigen::VectorXd grav = Eigen::VectorXd::Zero(bias.size());
  if (gravity || coriolis) {
    std::vector<double> saved(d->qvel, d->qvel + m->nv), g(m->nv);
    std::fill(d->qvel, d->qvel + m->nv, 0.0);
    mj_comVel(m, d);
    mj_rne(m, d, 0, g.data());
    std::copy(saved.begin(), saved.end(), d->qvel);
    mj_comVel(m, d);
    grav = MjDofs(c, g.data());
  }
  Eigen::VectorXd f = Eigen::VectorXd::Zero(bias.size());
  if (gravity) f += grav;
  if (coriolis) f += bias - grav;
  if (external && data.xfrc_dirty) {
    // the wrenches waiting in xfrc_applied (at the links' centres of mass), in joint space
    std::vector<double> qfrc(m->nv, 0.0);
    std::vector<int> bodies = c.link_body;
    std::sort(bodies.begin(), bodies.end());
    bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
    for (int b : bodies) {
      const double* w = d->xfrc_applied + 6 * b;
      mj_applyFT(m, d, w, w + 3, d->xipos + 3 * b, b, qfrc.data());
    }
    f -= MjDofs(c, qfrc.data());
  }
  return c.G.transpose() * f;
}

Eigen::VectorXd ForwardDynamics(const Model& model, Data& data, int articulation,
                                const Eigen::VectorXd& qf) {
  Forward(model, data);
  return MassMatrix(model, data, articulation)
      .ldlt()
      .solve(qf - BiasForce(model, data, articulation));
}

Eigen::VectorXd InverseDynamics(const Model& model, Data& data, int articulation,
                                const Eigen::VectorXd& qacc) {
  Forward(model, data);
  const CompiledArticulation& c = Dynamic(model, articulation);
  return c.G.transpose() *
         (MjMassMatrix(model, data, c) * (c.G * qacc) + MjDofs(c, data.mj->qfrc_bias));
}

Eigen::MatrixXd LinkJacobian(const Model& model, Data& data, int articulation, int link) {
  const CompiledArticulation& c = Dynamic(model, articulation);
  Kinematics(model, data);
  const int nv = model.mj->nv;
  Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> jp(3, nv), jr(3, nv);
  mj_jacBody(model.mj.get(), data.mj.get(), jp.data(), jr.data(),
             c.link_body.at(static_cast<size_t>(link)));
  const int n = static_cast<int>(c.mj_dofs.size());
  Eigen::MatrixXd J(6, n);
  for (int i = 0; i < n; ++i) {
    J.block<3, 1>(0, i) = jp.col(c.mj_dofs[i]);
    J.block<3, 1>(3, i) = jr.col(c.mj_dofs[i]);
  }
  return J * c.G;
}

BodyFrameMotion FrameMotion(const Model& model, Data& data, int body,
                            const Eigen::Vector3d& point) {
  Forward(model, data);
  const mjModel* m = model.mj.get();
  mjData* d = data.mj.get();
  mj_rnePostConstraint(m, d);
  // cvel and cacc are spatial (angular; linear) at the subtree centre of mass of the root, in
  // world orientation; cacc of the world is -gravity, so this is proper acceleration
  Eigen::Map<const Eigen::Matrix<double, 6, 1>> cvel(d->cvel + 6 * body), cacc(d->cacc + 6 * body);
  Eigen::Map<const Eigen::Vector3d> com(d->subtree_com + 3 * m->body_rootid[body]);
  const Eigen::Vector3d r = point - com;
  BodyFrameMotion out;
  out.angular_velocity = cvel.head<3>();
  out.linear_velocity = cvel.tail<3>() + out.angular_velocity.cross(r);
  out.angular_acceleration = cacc.head<3>();
  out.linear_acceleration =
      cacc.tail<3>() + cacc.head<3>().cross(r) + out.angular_velocity.cross(out.linear_velocity);
  return out;
}

Model Model::Copy() const {
  Model out;
  out.mj.reset(mj_copyModel(nullptr, mj.get()));
  if (!out.mj) throw Error("MuJoCo could not allocate a copy of the scene's model: out of memory");
  out.spec = spec;
  out.actors = actors;
  out.articulations = articulations;
  out.geom_owner = geom_owner;
  return out;
}

Data Data::CopyFor(const Model& model) const {
  Data out;
  out.mj.reset(mj_copyData(nullptr, model.mj.get(), mj.get()));
  if (!out.mj) throw Error("MuJoCo could not allocate a copy of the scene's data: out of memory");
  out.articulations = articulations;
  out.forward_valid = forward_valid;
  out.kinematics_valid = kinematics_valid;
  out.xfrc_dirty = xfrc_dirty;
  return out;
}

}  // namespace internal
}  // namespace partsim
