// The IMU against physics: gravity at rest (on an actor and on a link), the spin rate and the
// centripetal acceleration of a turning body, nothing in free fall.
#include "partsim/robot/imu.h"

#include <gtest/gtest.h>

#include <cmath>

#include "robot/test_robots.h"

namespace partsim {
namespace {

TEST(Imu, ReadsGravityAtRest) {
  Scene scene;
  scene.AddGround(0);
  Actor box = scene.CreateActorBuilder()
                  .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1))
                  .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 0.1)))
                  .Build();
  scene.Step(500);
  // sensor tilted by 90 degrees about x: world up is its -y... its y axis points down
  Imu imu(box, Pose(Eigen::Vector3d(0.05, 0, 0),
                    Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()))));
  ImuReading r = imu.Read();
  EXPECT_LT((r.linear_acceleration - Eigen::Vector3d(0, 9.81, 0)).norm(), 0.05)
      << r.linear_acceleration.transpose();
  EXPECT_LT(r.angular_velocity.norm(), 1e-3);
  EXPECT_NEAR(r.time, 1.0, 1e-9);
  EXPECT_NEAR(std::abs(r.orientation[0]), std::cos(M_PI / 4), 1e-3);
  // on a link of a fixed robot at rest too
  Articulation arm = testing::AddArm7(scene, Pose(Eigen::Vector3d(1, 0, 0)));
  arm.SetDriveProperty(1e4, 1e3);
  arm.SetDriveTarget(Eigen::VectorXd::Zero(7));
  arm.SetQf(arm.ComputePassiveForce());
  ImuReading l = Imu(arm.FindLinkByName("link3")).Read();
  EXPECT_LT((l.linear_acceleration - Eigen::Vector3d(0, 0, 9.81)).norm(), 0.05);
}

TEST(Imu, ReadsSpinRateAndCentripetalAcceleration) {
  SceneConfig cfg;
  cfg.gravity.setZero();
  Scene scene(cfg);
  Actor ball = scene.CreateActorBuilder()
                   .AddSphereCollision(Pose(), 0.1)
                   .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 1)))
                   .Build();
  ball.SetAngularVelocity(Eigen::Vector3d(0, 0, 2.0));
  scene.Step(100);
  const double r = 0.05;
  Imu imu(ball, Pose(Eigen::Vector3d(r, 0, 0)));
  ImuReading reading = imu.Read();
  // the sensor turns with the ball: the rate about its own z is the same
  EXPECT_LT((reading.angular_velocity - Eigen::Vector3d(0, 0, 2.0)).norm(), 1e-6);
  // proper acceleration points to the axis: -w^2 r along the sensor's x
  EXPECT_LT((reading.linear_acceleration - Eigen::Vector3d(-4.0 * r, 0, 0)).norm(), 1e-3)
      << reading.linear_acceleration.transpose();
}

TEST(Imu, FreeFallReadsZero) {
  Scene scene;
  Actor box = scene.CreateActorBuilder()
                  .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1))
                  .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 10)))
                  .Build();
  scene.Step(100);
  ImuReading r = Imu(box).Read();
  EXPECT_LT(r.linear_acceleration.norm(), 0.05) << r.linear_acceleration.transpose();
  EXPECT_LT(box.GetPose().p.z(), 9.9);  // it does fall
}

}  // namespace
}  // namespace partsim
