// An IMU on a link or an actor: orientation, proper linear acceleration and angular velocity in
// the sensor frame, from MuJoCo's body accelerations (mj_rnePostConstraint), the way MuJoCo's own
// accelerometer and gyro sensors read them.
#include "partsim/robot/imu.h"

#include <mujoco/mujoco.h>

#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "physics/scene_internal.h"

namespace partsim {

Imu::Imu(const Link& link, const Pose& local_pose)
    : scene_(link.GetScene()),
      is_link_(true),
      articulation_id_(link.GetArticulationId()),
      link_index_(link.GetIndex()),
      local_pose_(local_pose) {
  if (!scene_) throw Error("Imu: the link handle is empty");
  CheckPose("Imu: local_pose", local_pose);
  local_pose_.q.normalize();
  link.GetPose();  // throws for a removed articulation or a bad index
}

Imu::Imu(const Actor& actor, const Pose& local_pose)
    : scene_(actor.GetScene()), is_link_(false), actor_id_(actor.GetId()), local_pose_(local_pose) {
  if (!scene_) throw Error("Imu: the actor handle is empty");
  CheckPose("Imu: local_pose", local_pose);
  local_pose_.q.normalize();
  actor.GetPose();  // throws for a removed actor
}

ImuReading Imu::Read() const {
  Scene::Impl& s = scene_->impl();
  // the mounting body, and the body's pose from the handle (throws if it was removed)
  int body = -1;
  Pose X_WB;
  if (is_link_) {
    Link link(scene_, articulation_id_, link_index_);
    X_WB = link.GetPose();
    const auto& c = s.Compiled(s.GetArticulation(articulation_id_));
    body = c.link_body.at(static_cast<size_t>(link_index_));
  } else {
    X_WB = Actor(scene_, actor_id_).GetPose();
    body = s.Compiled(s.GetActor(actor_id_)).body;
  }
  // accelerations at the current state: forward dynamics, then the bodies' accelerations
  s.EnsureForward();
  const mjModel* m = s.m;
  mjData* d = s.d;
  mj_rnePostConstraint(m, d);
  // cvel and cacc are spatial (angular; linear) at the subtree centre of mass of the root,
  // in world orientation; cacc of the world is -gravity, so this is proper acceleration
  const Pose X_WS = X_WB * local_pose_;
  Eigen::Map<const Eigen::Matrix<double, 6, 1>> cvel(d->cvel + 6 * body), cacc(d->cacc + 6 * body);
  Eigen::Map<const Eigen::Vector3d> c(d->subtree_com + 3 * m->body_rootid[body]);
  const Eigen::Vector3d r = X_WS.p - c;
  const Eigen::Vector3d w = cvel.head<3>();
  const Eigen::Vector3d v = cvel.tail<3>() + w.cross(r);
  const Eigen::Vector3d a = cacc.tail<3>() + cacc.head<3>().cross(r) + w.cross(v);
  ImuReading out;
  const Eigen::Quaterniond q = X_WS.q.normalized();
  out.orientation = Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
  out.linear_acceleration = q.conjugate() * a;
  out.angular_velocity = q.conjugate() * w;
  out.time = d->time;
  return out;
}

}  // namespace partsim
