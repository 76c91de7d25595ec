// Computations over the compiled model and the data (stages.h), as free functions the way
// MuJoCo's take (m, d): the drives' controls, forward dynamics and kinematics when the state
// changed, and the dynamics queries of articulations and bodies. The handles (Articulation,
// Link, Actor) check their arguments and call these; so do other layers' internals that need
// the same quantities (the IMU through ComputeFrameMotion). Not part of the public API.
#pragma once

#include <Eigen/Core>

#include "partsim/core/pose.h"
#include "physics/stages.h"

namespace partsim {
namespace internal {

/// The entries of a qvel-like MuJoCo array (size nv) at the articulation's MuJoCo dofs
/// (CompiledArticulation::mj_dofs), for projections through G^T.
Eigen::VectorXd MjDofs(const CompiledArticulation& articulation, const double* src);
/// Writes every drive's control into data.mj->ctrl: stiffness target + damping
/// velocity_target - velocity_gain qvel (CompiledDrive).
void ApplyDrives(const Model& model, Data& data);
/// Applies the drives and runs mj_forward unless data.forward_valid.
void Forward(const Model& model, Data& data);
/// Runs forward kinematics and body velocities unless data is valid for them.
void Kinematics(const Model& model, Data& data);

/// Joint-space mass matrix of an articulation (dof x dof), without the inertia that
/// backward-Euler drives add to the dofs. Needs Forward.
Eigen::MatrixXd MassMatrix(const Model& model, const Data& data, int articulation);
/// Joint-space bias force C(q, qdot) qdot + g(q) (MuJoCo's qfrc_bias). Needs Forward.
Eigen::VectorXd BiasForce(const Model& model, const Data& data, int articulation);
/// The force that cancels gravity and/or the Coriolis and centrifugal terms and/or the external
/// wrenches waiting in xfrc_applied: minus the passive joint forces. Runs Forward.
Eigen::VectorXd PassiveForce(const Model& model, Data& data, int articulation, bool gravity,
                             bool coriolis, bool external);
/// qacc = M^-1 (qf - bias) without contacts, limits or drives. Runs Forward.
Eigen::VectorXd ForwardDynamics(const Model& model, Data& data, int articulation,
                                const Eigen::VectorXd& qf);
/// qf = M qacc + bias. Runs Forward.
Eigen::VectorXd InverseDynamics(const Model& model, Data& data, int articulation,
                                const Eigen::VectorXd& qacc);
/// 6 x dof world-frame Jacobian of a link's origin (linear; angular). Runs Kinematics.
Eigen::MatrixXd LinkJacobian(const Model& model, Data& data, int articulation, int link);

/// Pose, velocities and proper acceleration of a frame fixed on a MuJoCo body, in the world.
struct BodyFrameMotion {
  Eigen::Vector3d linear_velocity;       ///< m/s
  Eigen::Vector3d angular_velocity;      ///< rad/s
  Eigen::Vector3d linear_acceleration;   ///< proper acceleration (gravity included), m/s^2
  Eigen::Vector3d angular_acceleration;  ///< rad/s^2
};
/// Motion of the point `point` (world frame) fixed on `body` at the current state, from
/// MuJoCo's body accelerations (mj_rnePostConstraint). Runs Forward.
BodyFrameMotion FrameMotion(const Model& model, Data& data, int body, const Eigen::Vector3d& point);

}  // namespace internal
}  // namespace partsim
