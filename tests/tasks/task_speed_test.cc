// The task's speed-ups (issue 18) change nothing that matters: the gravity compensation from
// the forward kinematics equals ComputePassiveForce's.
#include <gtest/gtest.h>

#include "partsim/tasks/tasks.h"
#include "tasks/task_internal.h"

namespace partsim {
namespace {

TaskOptions Options(TaskType type) {
  TaskOptions o;
  o.type = type;
  o.object_index = FindTaskObjects(type, 1).front();
  o.cameras = false;
  return o;
}

TEST(TaskSpeedTest, GravityCompensationIsThePassiveForce) {
  ArticulationTask task(Options(TaskType::kPullDrawer));
  task.Reset(2);
  Eigen::Matrix<double, 6, 1> twist;
  twist << 0.1, -0.2, 0.05, 0.4, -0.7, 1.1;
  task.SetTcpVelocity(twist);
  for (int i = 0; i < 12; ++i) {
    task.Step();
    const Eigen::VectorXd fast = task.impl().GravityCompensation();
    const Eigen::VectorXd slow = task.GetRobot().ComputePassiveForce(true, false, false);
    ASSERT_EQ(fast.size(), slow.size());
    for (Eigen::Index k = 0; k < fast.size(); ++k)
      EXPECT_NEAR(fast[k], slow[k], 1e-9 * (1.0 + std::abs(slow[k]))) << "dof " << k;
  }
}

}  // namespace
}  // namespace partsim
