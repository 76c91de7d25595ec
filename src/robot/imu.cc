// An IMU on a link or an actor: orientation, proper linear acceleration and angular velocity in
// the sensor frame, from the motion of the sensor frame (partsim/physics/frame_motion.h: the
// engine's body accelerations, as MuJoCo's own accelerometer and gyro sensors read them).
#include "partsim/robot/imu.h"

#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "partsim/physics/frame_motion.h"

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
  const FrameMotion motion =
      is_link_ ? ComputeFrameMotion(Link(scene_, articulation_id_, link_index_), local_pose_)
               : ComputeFrameMotion(Actor(scene_, actor_id_), local_pose_);
  ImuReading out;
  const Eigen::Quaterniond q = motion.pose.q.normalized();
  out.orientation = Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
  out.linear_acceleration = q.conjugate() * motion.linear_acceleration;
  out.angular_velocity = q.conjugate() * motion.angular_velocity;
  out.time = motion.time;
  return out;
}

}  // namespace partsim
