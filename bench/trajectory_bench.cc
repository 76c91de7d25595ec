// Following a trajectory given by positions only (as many ROS clients send them): samples per
// second of JointTrajectory::Sample, which fits the clamped spline through every waypoint at each
// call, against TrajectorySampler, which fits it once; and the simulation's steps per second with
// a JointTrajectoryController updating at every step on the Panda, for a trajectory of positions
// only against the same trajectory with its velocities and accelerations given (where sampling
// never depended on the number of waypoints). The configurations take turns in each repetition.
//
// Usage: partsim_trajectory_bench [--reps R]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "partsim/physics/scene.h"
#include "partsim/robot/controllers.h"
#include "partsim/robot/robots.h"
#include "partsim/robot/trajectory.h"

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A smooth joint-space wave through `n` waypoints over `duration` seconds around `home`.
partsim::JointTrajectory Wave(const Eigen::VectorXd& home, int n, double duration) {
  partsim::JointTrajectory t;
  for (int w = 0; w < n; ++w) {
    const double s = static_cast<double>(w) / (n - 1);
    t.times.push_back(s * duration);
    Eigen::VectorXd q = home;
    for (Eigen::Index k = 0; k < q.size(); ++k)
      q[k] += 0.3 * std::sin(2.0 * M_PI * s + 0.5 * static_cast<double>(k)) *
              std::sin(M_PI * s);  // starts and ends at home
    t.positions.push_back(q);
  }
  return t;
}

// Samples per second over at least 0.3 s, at times spread over the trajectory.
template <typename F>
double SampleRate(double duration, F sample) {
  Eigen::VectorXd q, qd, qdd;
  long count = 0;
  const auto t0 = Clock::now();
  double elapsed = 0.0;
  while ((elapsed = Seconds(t0)) < 0.3) {
    for (int k = 0; k < 64; ++k, ++count)
      sample(duration * static_cast<double>((count * 7919) % 1000) / 1000.0, &q, &qd, &qdd);
  }
  return static_cast<double>(count) / elapsed;
}

// Steps per second of the Panda following `t` with the controller updating at every step.
double StepRate(const partsim::JointTrajectory& t) {
  partsim::SceneConfig cfg;
  partsim::Scene scene(cfg);
  const partsim::RobotModel panda = partsim::BuildPanda();
  partsim::Articulation arm = scene.AddArticulation(panda.articulation);
  Eigen::VectorXd q = arm.GetQpos();
  for (size_t i = 0; i < panda.arm_joints.size(); ++i)
    q[static_cast<Eigen::Index>(i)] = panda.home[i];
  arm.SetQpos(q);
  partsim::JointControllerOptions options;
  options.control_rate = 1.0 / cfg.timestep;
  auto c = std::make_shared<partsim::JointTrajectoryController>(arm, panda.arm_joints, options);
  partsim::ControlLoop loop(&scene);
  loop.Add(c);
  c->SetTrajectory(t);
  const int steps = static_cast<int>(t.Duration() / cfg.timestep);
  const auto t0 = Clock::now();
  loop.Step(steps);
  const double rate = steps / Seconds(t0);
  if (c->GetStatus().state == partsim::ControllerState::kFailed) {
    std::fprintf(stderr, "the controller failed: %s\n", c->GetStatus().message.c_str());
    std::exit(1);
  }
  return rate;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) {
      reps = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: %s [--reps R]\n", argv[0]);
      return 2;
    }
  }
  if (reps < 1) return 2;
  const partsim::RobotModel panda = partsim::BuildPanda();
  Eigen::VectorXd home(static_cast<Eigen::Index>(panda.home.size()));
  for (size_t i = 0; i < panda.home.size(); ++i) home[static_cast<Eigen::Index>(i)] = panda.home[i];

  std::printf("samples/s, 7 joints, positions only: JointTrajectory::Sample | TrajectorySampler\n");
  for (int n : {10, 100, 1000, 10000}) {
    const partsim::JointTrajectory t = Wave(home, n, 10.0);
    const partsim::TrajectorySampler sampler(t);
    std::vector<double> refit, once;
    for (int r = 0; r < reps; ++r) {
      auto a = [&](double x, Eigen::VectorXd* q, Eigen::VectorXd* qd, Eigen::VectorXd* qdd) {
        t.Sample(x, q, qd, qdd);
      };
      auto b = [&](double x, Eigen::VectorXd* q, Eigen::VectorXd* qd, Eigen::VectorXd* qdd) {
        sampler.Sample(x, q, qd, qdd);
      };
      if (r % 2 == 0) {
        refit.push_back(SampleRate(t.Duration(), a));
        once.push_back(SampleRate(t.Duration(), b));
      } else {
        once.push_back(SampleRate(t.Duration(), b));
        refit.push_back(SampleRate(t.Duration(), a));
      }
    }
    std::printf("  %5d waypoints: %12.0f | %12.0f  (x%.0f)\n", n, Median(refit), Median(once),
                Median(once) / Median(refit));
  }

  std::printf("steps/s, Panda, JointTrajectoryController at every step, 4 s wave:\n");
  std::printf("  waypoints | positions only | with velocities and accelerations | ratio\n");
  for (int n : {10, 1000, 4000}) {
    const partsim::JointTrajectory positions = Wave(home, n, 4.0);
    const partsim::TrajectorySampler sampler(positions);
    partsim::JointTrajectory full = positions;  // the same curve, derivatives given
    for (double x : full.times) {
      Eigen::VectorXd q, qd, qdd;
      sampler.Sample(x, &q, &qd, &qdd);
      full.velocities.push_back(qd);
      full.accelerations.push_back(qdd);
    }
    std::vector<double> a, b, ratio;
    for (int r = 0; r < reps; ++r) {
      double x = 0, y = 0;
      if (r % 2 == 0) {
        x = StepRate(positions);
        y = StepRate(full);
      } else {
        y = StepRate(full);
        x = StepRate(positions);
      }
      a.push_back(x);
      b.push_back(y);
      ratio.push_back(x / y);
    }
    std::printf("  %9d | %14.0f | %33.0f | %.2f\n", n, Median(a), Median(b), Median(ratio));
  }
  return 0;
}
