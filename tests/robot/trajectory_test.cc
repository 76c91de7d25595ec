// Joint trajectories: interpolation at and between waypoints, time parameterisation within
// velocity and acceleration limits, bad input.
#include "partsim/robot/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "partsim/core/error.h"
#include "robot/test_robots.h"

namespace partsim {
namespace {

using testing::V;

TEST(TrajectorySample, QuinticMatchesWaypointsAndIsSmooth) {
  JointTrajectory t;
  t.times = {0.0, 1.0, 2.5};
  t.positions = {V({0, 1}), V({1, 0}), V({2, -1})};
  t.velocities = {V({0, 0}), V({0.5, -1}), V({0, 0})};
  t.accelerations = {V({0, 0}), V({0.2, 0.3}), V({0, 0})};
  t.Validate(2);
  EXPECT_DOUBLE_EQ(t.Duration(), 2.5);
  for (size_t i = 0; i < 3; ++i) {
    // just after each waypoint's time and exactly at it
    for (double dt : {0.0, 1e-9}) {
      double ti = std::min(t.times[i] + dt, 2.5);
      Eigen::VectorXd q, qd, qdd;
      t.Sample(ti, &q, &qd, &qdd);
      EXPECT_LT((q - t.positions[i]).norm(), 1e-7) << i;
      EXPECT_LT((qd - t.velocities[i]).norm(), 1e-6) << i;
      EXPECT_LT((qdd - t.accelerations[i]).norm(), 1e-5) << i;
    }
  }
  // the sampled velocity is the derivative of the sampled position
  Eigen::VectorXd a, b, qd;
  t.Sample(1.7 + 1e-6, &a);
  t.Sample(1.7 - 1e-6, &b);
  t.Sample(1.7, nullptr, &qd);
  EXPECT_LT(((a - b) / 2e-6 - qd).norm(), 1e-6);
  // clamped outside [0, duration]
  Eigen::VectorXd q;
  t.Sample(10.0, &q, &qd);
  EXPECT_LT((q - t.positions[2]).norm(), 1e-12);
  t.Sample(-1.0, &q);
  EXPECT_LT((q - t.positions[0]).norm(), 1e-12);
}

TEST(TrajectorySample, CubicWithVelocitiesAndSplineWithPositionsOnly) {
  JointTrajectory t;
  t.times = {0.5, 1.0, 2.0, 3.0};
  t.positions = {V({0}), V({1}), V({-1}), V({0.5})};
  // positions only: a C2 spline through the waypoints, at rest at both ends
  Eigen::VectorXd q, qd, qdd, qdd2;
  for (size_t i = 0; i < 4; ++i) {
    t.Sample(t.times[i], &q);
    EXPECT_NEAR(q[0], t.positions[i][0], 1e-12);
  }
  t.Sample(0.5, &q, &qd);
  EXPECT_NEAR(qd[0], 0.0, 1e-12);
  t.Sample(3.0 - 1e-9, &q, &qd);
  EXPECT_NEAR(qd[0], 0.0, 1e-6);
  t.Sample(2.0 - 1e-9, nullptr, nullptr, &qdd);
  t.Sample(2.0 + 1e-9, nullptr, nullptr, &qdd2);
  EXPECT_NEAR(qdd[0], qdd2[0], 1e-5);  // continuous acceleration
  // with velocities: Hermite cubic through positions and velocities
  t.velocities = {V({0}), V({2}), V({-1}), V({0})};
  for (size_t i = 0; i + 1 < 4; ++i) {
    t.Sample(t.times[i] + 1e-9, &q, &qd);
    EXPECT_NEAR(q[0], t.positions[i][0], 1e-8);
    EXPECT_NEAR(qd[0], t.velocities[i][0], 1e-6);
  }
}

// A TrajectorySampler gives JointTrajectory::Sample's values to the last bit, for positions
// only (the clamped spline), with velocities (cubic) and with accelerations too (quintic): before
// the first waypoint, at each waypoint, between them, at the end and after it.
TEST(TrajectorySampler, GivesJointTrajectorySampleExactly) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random = [&](int dof) {
    Eigen::VectorXd v(dof);
    for (int k = 0; k < dof; ++k) v[k] = u(rng);
    return v;
  };
  for (int kind = 0; kind < 3; ++kind) {
    JointTrajectory t;
    double time = 0.3;  // the first waypoint after 0: the trajectory holds before it
    for (int w = 0; w < 40; ++w) {
      t.times.push_back(time);
      time += 0.05 + 0.1 * (u(rng) + 1.0);
      t.positions.push_back(random(3));
      if (kind >= 1) t.velocities.push_back(random(3));
      if (kind == 2) t.accelerations.push_back(random(3));
    }
    t.Validate(3);
    const TrajectorySampler sampler(t);
    std::vector<double> at = {-1.0, 0.0, t.times.back(), t.Duration() + 1.0};
    for (size_t w = 0; w + 1 < t.times.size(); ++w) {
      at.push_back(t.times[w]);
      at.push_back(0.5 * (t.times[w] + t.times[w + 1]));
      at.push_back(std::nextafter(t.times[w + 1], 0.0));
    }
    for (double x : at) {
      Eigen::VectorXd q0, qd0, qdd0, q1, qd1, qdd1;
      t.Sample(x, &q0, &qd0, &qdd0);
      sampler.Sample(x, &q1, &qd1, &qdd1);
      ASSERT_EQ(q0, q1) << "kind " << kind << ", t " << x;
      ASSERT_EQ(qd0, qd1) << "kind " << kind << ", t " << x;
      ASSERT_EQ(qdd0, qdd1) << "kind " << kind << ", t " << x;
    }
  }
  // one waypoint, and what cannot be sampled
  JointTrajectory one;
  one.times = {0.0};
  one.positions = {V({0.5})};
  Eigen::VectorXd q;
  TrajectorySampler(one).Sample(3.0, &q);
  EXPECT_EQ(q, V({0.5}));
  EXPECT_THROW(TrajectorySampler().Sample(0.0, &q), Error);
  JointTrajectory bad = one;
  bad.positions.clear();
  EXPECT_THROW(TrajectorySampler{bad}, Error);
  EXPECT_THROW(TrajectorySampler(one).Sample(std::nan(""), &q), Error);
}

TEST(TrajectoryValidate, BadInputNamesTheWaypoint) {
  JointTrajectory t;
  EXPECT_THROW(t.Validate(1), Error);
  t.times = {0.0, 1.0, 1.0};
  t.positions = {V({0}), V({1}), V({2})};
  try {
    t.Validate(1);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("waypoint 2"), std::string::npos) << e.what();
  }
  t.times = {0.0, 1.0, 2.0};
  EXPECT_NO_THROW(t.Validate(1));
  EXPECT_THROW(t.Validate(2), Error);
  t.positions[1] = V({NAN});
  EXPECT_THROW(t.Validate(1), Error);
  t.positions[1] = V({1});
  t.times[0] = -0.1;
  EXPECT_THROW(t.Validate(1), Error);
  t.times[0] = 0;
  t.velocities = {V({0})};
  EXPECT_THROW(t.Validate(1), Error);
  t.velocities = {};
  t.accelerations = {V({0}), V({0}), V({0})};
  EXPECT_THROW(t.Validate(1), Error);
}

// Checks the limits by dense sampling, waypoints at their times and rest at both ends.
void CheckParameterized(const JointTrajectory& t, const std::vector<Eigen::VectorXd>& path,
                        const Eigen::VectorXd& vmax, const Eigen::VectorXd& amax) {
  t.Validate(static_cast<int>(vmax.size()));
  ASSERT_EQ(t.positions.size(), path.size());
  for (size_t i = 0; i < path.size(); ++i) {
    Eigen::VectorXd q;
    t.Sample(t.times[i], &q);
    EXPECT_LT((q - path[i]).norm(), 1e-9) << "waypoint " << i;
  }
  Eigen::VectorXd q, qd, qdd;
  t.Sample(0.0, &q, &qd, &qdd);
  EXPECT_LT(qd.norm(), 1e-12);
  t.Sample(t.Duration(), &q, &qd);
  EXPECT_LT(qd.norm(), 1e-12);
  const int n = 20000;
  double worst_v = 0, worst_a = 0;
  for (int s = 0; s <= n; ++s) {
    t.Sample(t.Duration() * s / n, &q, &qd, &qdd);
    worst_v = std::max(worst_v, (qd.cwiseAbs() - vmax).maxCoeff());
    worst_a = std::max(worst_a, (qdd.cwiseAbs() - amax).maxCoeff());
  }
  EXPECT_LE(worst_v, 1e-6);
  EXPECT_LE(worst_a, 1e-6);
}

TEST(TrajectoryTimeParameterize, RespectsLimitsAndPassesThroughWaypoints) {
  std::vector<Eigen::VectorXd> path = {V({0, 0, 0}), V({1, 0.5, -0.2}), V({1.2, -1, 0.3}),
                                       V({0.3, -1, 0.3}), V({0, 0, 1})};
  Eigen::VectorXd vmax = V({1.0, 2.0, 0.5}), amax = V({2.0, 1.0, 3.0});
  JointTrajectory t = TimeParameterize(path, vmax, amax);
  CheckParameterized(t, path, vmax, amax);
  std::printf("5-waypoint path: duration %.3f s\n", t.Duration());
  // random paths
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::VectorXd> p(2 + trial % 7, Eigen::VectorXd(4));
    for (auto& w : p)
      for (int k = 0; k < 4; ++k) w[k] = u(rng);
    Eigen::VectorXd v = Eigen::VectorXd::Constant(4, 0.5 + trial * 0.1);
    Eigen::VectorXd a = Eigen::VectorXd::Constant(4, 1.0 + trial * 0.2);
    CheckParameterized(TimeParameterize(p, v, a), p, v, a);
  }
}

TEST(TrajectoryTimeParameterize, TwoWaypointsNearTrapezoidTime) {
  // rest to rest over 1 rad: a cubic needs 1.5 d / v (velocity-bound) or sqrt(6 d / a)
  JointTrajectory t = TimeParameterize({V({0}), V({1})}, V({1}), V({100}));
  EXPECT_NEAR(t.Duration(), 1.5, 1e-6);
  t = TimeParameterize({V({0}), V({1})}, V({100}), V({1}));
  EXPECT_NEAR(t.Duration(), std::sqrt(6.0), 1e-6);
}

TEST(TrajectoryTimeParameterize, SingleAndRepeatedWaypoints) {
  JointTrajectory t = TimeParameterize({V({1, 2})}, V({1, 1}), V({1, 1}));
  EXPECT_EQ(t.Duration(), 0.0);
  Eigen::VectorXd q;
  t.Sample(0.3, &q);
  EXPECT_EQ(q, V({1, 2}));
  std::vector<Eigen::VectorXd> path = {V({0}), V({0.5}), V({0.5}), V({1})};
  CheckParameterized(TimeParameterize(path, V({1}), V({1})), path, V({1}), V({1}));
}

TEST(TrajectoryTimeParameterize, BadInputThrows) {
  EXPECT_THROW(TimeParameterize({}, V({1}), V({1})), Error);
  EXPECT_THROW(TimeParameterize({V({0}), V({1, 2})}, V({1}), V({1})), Error);
  EXPECT_THROW(TimeParameterize({V({0}), V({1})}, V({0}), V({1})), Error);
  EXPECT_THROW(TimeParameterize({V({0}), V({1})}, V({1}), V({-1})), Error);
  EXPECT_THROW(TimeParameterize({V({0}), V({1})}, V({1, 1}), V({1})), Error);
  EXPECT_THROW(TimeParameterize({V({0}), V({NAN})}, V({1}), V({1})), Error);
}

}  // namespace
}  // namespace partsim
