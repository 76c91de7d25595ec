// The task's speed-ups (issue 18) change nothing that matters: the gravity compensation from
// the robot's forward kinematics equals ComputePassiveForce's; box meshes become the same boxes;
// the cabinet's links do not collide with each other, the gripper with all of them.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "partsim/core/error.h"
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

CollisionShape MeshShape(const std::vector<Eigen::Vector3f>& vertices) {
  auto mesh = std::make_shared<MeshData>();
  mesh->vertices = vertices;
  CollisionShape s;
  s.type = ShapeType::kConvexMesh;
  s.mesh = mesh;
  s.pose = Pose(Eigen::Vector3d(1, 2, 3), Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5));
  s.density = 321.0;
  s.name = "panel";
  return s;
}

TEST(TaskSpeedTest, BoxMeshesBecomeTheSameBoxes) {
  // a box mesh as the generator writes it: each corner repeated on its three faces
  std::vector<Eigen::Vector3f> v;
  for (int rep = 0; rep < 3; ++rep)
    for (int c = 0; c < 8; ++c)
      v.emplace_back(c & 1 ? 0.5f : 0.1f, c & 2 ? 0.3f : -0.2f, c & 4 ? 0.02f : 0.01f);
  std::optional<CollisionShape> box = internal::BoxOfMesh(MeshShape(v));
  ASSERT_TRUE(box.has_value());
  EXPECT_EQ(box->type, ShapeType::kBox);
  EXPECT_EQ(box->mesh, nullptr);
  EXPECT_EQ(box->name, "panel");
  EXPECT_EQ(box->density, 321.0);
  EXPECT_TRUE(box->half_size.isApprox(Eigen::Vector3d(0.2, 0.25, 0.005), 1e-6));
  // the box's centre, in the body, is where the mesh's was
  const Eigen::Vector3d centre(0.3, 0.05, 0.015);
  EXPECT_TRUE(box->pose.p.isApprox(MeshShape(v).pose.Transform(centre), 1e-6));
  EXPECT_TRUE(box->pose.q.isApprox(MeshShape(v).pose.q));

  // a corner missing (a wedge), a vertex inside, a flat box: stay meshes
  std::vector<Eigen::Vector3f> wedge(v.begin(), v.begin() + 7);
  EXPECT_FALSE(internal::BoxOfMesh(MeshShape(wedge)).has_value());
  std::vector<Eigen::Vector3f> inner = v;
  inner.emplace_back(0.3f, 0.0f, 0.015f);
  EXPECT_FALSE(internal::BoxOfMesh(MeshShape(inner)).has_value());
  std::vector<Eigen::Vector3f> flat = v;
  for (Eigen::Vector3f& p : flat) p.z() = 0.01f;
  EXPECT_FALSE(internal::BoxOfMesh(MeshShape(flat)).has_value());
}

TEST(TaskSpeedTest, TheCabinetsLinksDoNotCollideWithEachOther) {
  TaskOptions o = Options(TaskType::kPullDrawer);
  ArticulationTask fast(o);
  o.filter_collisions = false;
  o.box_primitives = false;
  ArticulationTask slow(o);
  const std::string fast_mjcf = fast.GetScene().GetMjcf(), slow_mjcf = slow.GetScene().GetMjcf();
  EXPECT_NE(fast_mjcf.find("type=\"box\""), std::string::npos);
  const ArticulationDesc& cabinet = fast.GetObject().GetDesc();
  int with_shapes = 0;
  for (const LinkDesc& l : cabinet.links) with_shapes += l.collisions.empty() ? 0 : 1;
  EXPECT_EQ(cabinet.disabled_collisions.size(),
            static_cast<size_t>(with_shapes * (with_shapes - 1) / 2));
  EXPECT_TRUE(slow.GetObject().GetDesc().disabled_collisions.empty());
  for (const LinkDesc& l : slow.GetObject().GetDesc().links)
    for (const CollisionShape& s : l.collisions) EXPECT_NE(s.type, ShapeType::kBox);
  // the gripper still grasps: the episode starts with it on the handle
  o = Options(TaskType::kPullDrawer);
  o.init_on_handle = true;
  ArticulationTask grasped(o);
  grasped.Reset(0);
  EXPECT_TRUE(grasped.GripperTouchesTarget());
}

TEST(TaskSpeedTest, StepTasksEqualsSteppingOneByOne) {
  TaskOptions o = Options(TaskType::kPullDrawer);
  o.control_rate = 25.0;
  ArticulationTask a(o), b(o), c(o), d(o);
  for (ArticulationTask* t : {&a, &b, &c, &d}) t->Reset(4);
  Eigen::MatrixXd actions(2, 7);
  actions << 0.2, -0.1, 0.05, 0.3, 0.0, -0.4, 0.5, -0.1, 0.2, 0.0, 0.0, 0.6, 0.1, -1.0;
  for (int k = 0; k < 5; ++k) {
    StepTasks({&a, &b}, actions);
    c.ApplyAction(actions.row(0).transpose());
    c.Step();
    d.ApplyAction(actions.row(1).transpose());
    d.Step();
  }
  EXPECT_EQ(a.GetMobilityObservation(), c.GetMobilityObservation());
  EXPECT_EQ(b.GetMobilityObservation(), d.GetMobilityObservation());
  EXPECT_EQ(a.GetReward(), c.GetReward());

  // bad input moves nothing
  const Eigen::VectorXd before = a.GetMobilityObservation();
  EXPECT_THROW(StepTasks({&a}, actions), Error);
  Eigen::MatrixXd nan = actions.topRows(1);
  nan(0, 3) = std::nan("");
  EXPECT_THROW(StepTasks({&a}, nan), Error);
  EXPECT_THROW(StepTasks({&a, &a}, actions), Error);
  EXPECT_EQ(a.GetMobilityObservation(), before);
  StepTasks({}, Eigen::MatrixXd(0, 7));
}

// StepTasks' threads stay between calls and grow to the most tasks seen: calls with 2, then 4,
// then 3 and 1 tasks (fewer than the pool's workers) step each task as stepping it alone does
TEST(TaskSpeedTest, StepTasksOnChangingNumbersOfTasksEqualsSteppingOneByOne) {
  TaskOptions o = Options(TaskType::kPullDrawer);
  o.control_rate = 25.0;
  std::vector<std::unique_ptr<ArticulationTask>> together, alone;
  for (int i = 0; i < 4; ++i) {
    together.push_back(std::make_unique<ArticulationTask>(o));
    alone.push_back(std::make_unique<ArticulationTask>(o));
    together.back()->Reset(i);
    alone.back()->Reset(i);
  }
  int k = 0;
  for (int n : {2, 4, 3, 1, 4}) {
    Eigen::MatrixXd actions(n, 7);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < 7; ++j) actions(i, j) = 0.1 * std::sin(1.3 * (++k));
    std::vector<ArticulationTask*> tasks;
    for (int i = 0; i < n; ++i) tasks.push_back(together[i].get());
    StepTasks(tasks, actions);
    for (int i = 0; i < n; ++i) {
      alone[i]->ApplyAction(actions.row(i).transpose());
      alone[i]->Step();
    }
  }
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(together[i]->GetMobilityObservation(), alone[i]->GetMobilityObservation())
        << "task " << i;
    EXPECT_EQ(together[i]->GetReward(), alone[i]->GetReward()) << "task " << i;
  }
}

// two threads that call StepTasks at the same time on tasks of their own share the one pool:
// each call waits for the other's and both step their tasks as stepping them alone does
TEST(TaskSpeedTest, StepTasksFromTwoThreadsAtOnce) {
  TaskOptions o = Options(TaskType::kPullDrawer);
  o.control_rate = 25.0;
  std::vector<std::unique_ptr<ArticulationTask>> tasks;
  for (int i = 0; i < 6; ++i) {
    tasks.push_back(std::make_unique<ArticulationTask>(o));
    tasks.back()->Reset(7);
  }
  Eigen::MatrixXd actions(2, 7);
  actions << 0.2, -0.1, 0.05, 0.3, 0.0, -0.4, 0.5, -0.1, 0.2, 0.0, 0.0, 0.6, 0.1, -1.0;
  auto steps = [&](ArticulationTask* a, ArticulationTask* b) {
    for (int k = 0; k < 8; ++k) StepTasks({a, b}, actions);
  };
  std::thread other(steps, tasks[2].get(), tasks[3].get());
  steps(tasks[0].get(), tasks[1].get());
  other.join();
  for (int k = 0; k < 8; ++k)
    for (int i = 0; i < 2; ++i) {
      tasks[4 + i]->ApplyAction(actions.row(i).transpose());
      tasks[4 + i]->Step();
    }
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(tasks[i]->GetMobilityObservation(), tasks[4 + i % 2]->GetMobilityObservation())
        << "task " << i;
}

}  // namespace
}  // namespace partsim
