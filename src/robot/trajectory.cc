// Joint trajectories: validation, interpolation (quintic or cubic Hermite, clamped cubic spline)
// and time parameterisation under velocity and acceleration limits.
#include "partsim/robot/trajectory.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "partsim/core/check.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

std::string Where(size_t i) { return "JointTrajectory: waypoint " + std::to_string(i); }

void CheckEntries(const std::vector<Eigen::VectorXd>& v, int dof, const char* what) {
  for (size_t i = 0; i < v.size(); ++i) {
    if (v[i].size() != dof)
      throw Error(Where(i) + ": " + what + " has " + std::to_string(v[i].size()) +
                  " entries, expected " + std::to_string(dof));
    for (Eigen::Index k = 0; k < v[i].size(); ++k)
      if (!std::isfinite(v[i][k]))
        throw Error(Where(i) + ": " + what + "[" + std::to_string(k) + "] is not finite");
  }
}

// Velocities and accelerations at the knots of the cubic spline through `positions` at `times`
// with zero velocity at both ends (clamped; C2). Needs at least two knots.
void ClampedSpline(const std::vector<double>& times, const std::vector<Eigen::VectorXd>& positions,
                   std::vector<Eigen::VectorXd>* velocities,
                   std::vector<Eigen::VectorXd>* accelerations) {
  const size_t n = times.size();
  const Eigen::Index dof = positions[0].size();
  std::vector<double> h(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) h[i] = times[i + 1] - times[i];
  // tridiagonal system for the knot accelerations M: sub a, diagonal b, super c, right side r
  std::vector<double> a(n, 0.0), b(n, 0.0), c(n, 0.0);
  std::vector<Eigen::VectorXd> r(n, Eigen::VectorXd::Zero(dof));
  auto slope = [&](size_t i) -> Eigen::VectorXd {
    return (positions[i + 1] - positions[i]) / h[i];
  };
  b[0] = 2 * h[0];
  c[0] = h[0];
  r[0] = 6 * slope(0);
  for (size_t i = 1; i + 1 < n; ++i) {
    a[i] = h[i - 1];
    b[i] = 2 * (h[i - 1] + h[i]);
    c[i] = h[i];
    r[i] = 6 * (slope(i) - slope(i - 1));
  }
  a[n - 1] = h[n - 2];
  b[n - 1] = 2 * h[n - 2];
  r[n - 1] = -6 * slope(n - 2);
  // Thomas algorithm (diagonally dominant)
  for (size_t i = 1; i < n; ++i) {
    double w = a[i] / b[i - 1];
    b[i] -= w * c[i - 1];
    r[i] -= w * r[i - 1];
  }
  std::vector<Eigen::VectorXd> M(n);
  M[n - 1] = r[n - 1] / b[n - 1];
  for (size_t i = n - 1; i-- > 0;) M[i] = (r[i] - c[i] * M[i + 1]) / b[i];
  velocities->assign(n, Eigen::VectorXd::Zero(dof));
  for (size_t i = 0; i + 1 < n; ++i) (*velocities)[i] = slope(i) - h[i] * (2 * M[i] + M[i + 1]) / 6;
  *accelerations = std::move(M);
}

// Polynomial coefficients (ascending powers of the time since the segment's start) of a
// segment of duration h: quintic when accelerations are given, else cubic Hermite.
using Segment = std::array<Eigen::VectorXd, 6>;

Segment MakeSegment(double h, const Eigen::VectorXd& p0, const Eigen::VectorXd& p1,
                    const Eigen::VectorXd& v0, const Eigen::VectorXd& v1, const Eigen::VectorXd* a0,
                    const Eigen::VectorXd* a1) {
  Segment s;
  const Eigen::Index dof = p0.size();
  for (auto& c : s) c = Eigen::VectorXd::Zero(dof);
  s[0] = p0;
  s[1] = v0;
  if (a0 && a1) {
    double h2 = h * h, h3 = h2 * h;
    s[2] = *a0 / 2;
    s[3] = (20 * (p1 - p0) - (8 * v1 + 12 * v0) * h - (3 * *a0 - *a1) * h2) / (2 * h3);
    s[4] = (30 * (p0 - p1) + (14 * v1 + 16 * v0) * h + (3 * *a0 - 2 * *a1) * h2) / (2 * h3 * h);
    s[5] = (12 * (p1 - p0) - 6 * (v1 + v0) * h - (*a0 - *a1) * h2) / (2 * h3 * h2);
  } else {
    s[2] = (3 * (p1 - p0) / h - 2 * v0 - v1) / h;
    s[3] = (2 * (p0 - p1) / h + v0 + v1) / (h * h);
  }
  return s;
}

void Evaluate(const Segment& s, double t, Eigen::VectorXd* q, Eigen::VectorXd* qd,
              Eigen::VectorXd* qdd) {
  if (q) *q = s[0] + t * (s[1] + t * (s[2] + t * (s[3] + t * (s[4] + t * s[5]))));
  if (qd) *qd = s[1] + t * (2 * s[2] + t * (3 * s[3] + t * (4 * s[4] + t * 5 * s[5])));
  if (qdd) *qdd = 2 * s[2] + t * (6 * s[3] + t * (12 * s[4] + t * 20 * s[5]));
}

}  // namespace

void JointTrajectory::Validate(int dof) const {
  if (times.empty()) throw Error("JointTrajectory: no waypoints");
  if (positions.size() != times.size())
    throw Error("JointTrajectory: " + std::to_string(positions.size()) + " positions for " +
                std::to_string(times.size()) + " times");
  if (!velocities.empty() && velocities.size() != times.size())
    throw Error("JointTrajectory: " + std::to_string(velocities.size()) + " velocities for " +
                std::to_string(times.size()) + " times (give none or one per waypoint)");
  if (!accelerations.empty() && accelerations.size() != times.size())
    throw Error("JointTrajectory: " + std::to_string(accelerations.size()) + " accelerations for " +
                std::to_string(times.size()) + " times (give none or one per waypoint)");
  if (!accelerations.empty() && velocities.empty())
    throw Error("JointTrajectory: accelerations given without velocities");
  for (size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i])) throw Error(Where(i) + ": time is not finite");
    if (i == 0 && times[0] < 0)
      throw Error(Where(0) + ": time " + FormatNumber(times[0]) + " is negative");
    if (i > 0 && !(times[i] > times[i - 1]))
      throw Error(Where(i) + ": time " + FormatNumber(times[i]) +
                  " does not come after the previous one (" + FormatNumber(times[i - 1]) + ")");
  }
  CheckEntries(positions, dof, "position");
  CheckEntries(velocities, dof, "velocity");
  CheckEntries(accelerations, dof, "acceleration");
}

double JointTrajectory::Duration() const { return times.empty() ? 0.0 : times.back(); }

namespace {

// Sampling outside the segments: t at or before the first waypoint, at or after the last, or a
// single waypoint: the hold (with the given end velocity and acceleration at the waypoint's own
// time). Returns false, with the segment that holds t in *segment, otherwise.
bool SampleEnds(const JointTrajectory& tr, double t, Eigen::VectorXd* q, Eigen::VectorXd* qd,
                Eigen::VectorXd* qdd, size_t* segment) {
  const std::vector<double>& times = tr.times;
  if (times.empty() || tr.positions.size() != times.size())
    throw Error("JointTrajectory::Sample: the trajectory has no valid waypoints");
  if (std::isnan(t)) throw Error("JointTrajectory::Sample: t is NaN");
  const Eigen::Index dof = tr.positions[0].size();
  const size_t n = times.size();
  const bool has_vel = tr.velocities.size() == n, has_acc = has_vel && tr.accelerations.size() == n;
  if (n == 1 || t <= times[0] || t >= times.back()) {
    size_t i = (n == 1 || t <= times[0]) ? 0 : n - 1;
    bool inside = t == times[i];
    if (q) *q = tr.positions[i];
    if (qd) *qd = inside && has_vel ? tr.velocities[i] : Eigen::VectorXd::Zero(dof);
    if (qdd) *qdd = inside && has_acc ? tr.accelerations[i] : Eigen::VectorXd::Zero(dof);
    return true;
  }
  size_t i = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  *segment = std::min(std::max<size_t>(i, 1), n - 1) - 1;
  return false;
}

// The polynomials of all segments: the given velocities (and accelerations), else the clamped
// spline's.
std::vector<Segment> Segments(const JointTrajectory& tr) {
  const size_t n = tr.times.size();
  const bool has_vel = tr.velocities.size() == n, has_acc = has_vel && tr.accelerations.size() == n;
  std::vector<Eigen::VectorXd> spline_v, spline_a;
  if (!has_vel && n > 1) ClampedSpline(tr.times, tr.positions, &spline_v, &spline_a);
  const std::vector<Eigen::VectorXd>& v = has_vel ? tr.velocities : spline_v;
  const std::vector<Eigen::VectorXd>& a = has_vel ? tr.accelerations : spline_a;
  const bool quintic = has_acc || !has_vel;
  std::vector<Segment> out;
  out.reserve(n > 0 ? n - 1 : 0);
  for (size_t i = 0; i + 1 < n; ++i)
    out.push_back(MakeSegment(tr.times[i + 1] - tr.times[i], tr.positions[i], tr.positions[i + 1],
                              v[i], v[i + 1], quintic ? &a[i] : nullptr,
                              quintic ? &a[i + 1] : nullptr));
  return out;
}

}  // namespace

void JointTrajectory::Sample(double t, Eigen::VectorXd* q, Eigen::VectorXd* qd,
                             Eigen::VectorXd* qdd) const {
  size_t i = 0;
  if (SampleEnds(*this, t, q, qd, qdd, &i)) return;
  const size_t n = times.size();
  // positions only: the spline through all of them, fitted for this one call
  if (velocities.size() != n) return TrajectorySampler(*this).Sample(t, q, qd, qdd);
  const bool has_acc = accelerations.size() == n;
  Evaluate(MakeSegment(times[i + 1] - times[i], positions[i], positions[i + 1], velocities[i],
                       velocities[i + 1], has_acc ? &accelerations[i] : nullptr,
                       has_acc ? &accelerations[i + 1] : nullptr),
           t - times[i], q, qd, qdd);
}

TrajectorySampler::TrajectorySampler(JointTrajectory trajectory)
    : trajectory_(std::move(trajectory)) {
  if (trajectory_.times.empty() || trajectory_.positions.size() != trajectory_.times.size())
    throw Error("TrajectorySampler: the trajectory has no valid waypoints");
  segments_ = Segments(trajectory_);
}

void TrajectorySampler::Sample(double t, Eigen::VectorXd* q, Eigen::VectorXd* qd,
                               Eigen::VectorXd* qdd) const {
  size_t i = 0;
  if (SampleEnds(trajectory_, t, q, qd, qdd, &i)) return;
  Evaluate(segments_[i], t - trajectory_.times[i], q, qd, qdd);
}

JointTrajectory TimeParameterize(const std::vector<Eigen::VectorXd>& path,
                                 const Eigen::VectorXd& velocity_limits,
                                 const Eigen::VectorXd& acceleration_limits) {
  if (path.empty()) throw Error("TimeParameterize: the path has no waypoints");
  const Eigen::Index dof = path[0].size();
  if (velocity_limits.size() != dof || acceleration_limits.size() != dof)
    throw Error("TimeParameterize: velocity_limits has " + std::to_string(velocity_limits.size()) +
                " and acceleration_limits " + std::to_string(acceleration_limits.size()) +
                " entries, the path has " + std::to_string(dof) + " joints");
  for (Eigen::Index k = 0; k < dof; ++k)
    if (!(velocity_limits[k] > 0) || !std::isfinite(velocity_limits[k]) ||
        !(acceleration_limits[k] > 0) || !std::isfinite(acceleration_limits[k]))
      throw Error("TimeParameterize: limits of joint " + std::to_string(k) +
                  " must be finite and > 0");
  for (size_t i = 0; i < path.size(); ++i) {
    if (path[i].size() != dof)
      throw Error("TimeParameterize: waypoint " + std::to_string(i) + " has " +
                  std::to_string(path[i].size()) + " entries, expected " + std::to_string(dof));
    if (!path[i].allFinite())
      throw Error("TimeParameterize: waypoint " + std::to_string(i) + " is not finite");
  }
  JointTrajectory out;
  out.positions = path;
  const size_t n = path.size();
  if (n == 1) {
    out.times = {0.0};
    out.velocities = {Eigen::VectorXd::Zero(dof)};
    out.accelerations = {Eigen::VectorXd::Zero(dof)};
    return out;
  }
  // first guess: each segment as a rest-to-rest trapezoid of its slowest joint
  std::vector<double> h(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) {
    double t = 1e-3;
    for (Eigen::Index k = 0; k < dof; ++k) {
      double d = std::abs(path[i + 1][k] - path[i][k]);
      double v = velocity_limits[k], a = acceleration_limits[k];
      t = std::max(t, d <= v * v / a ? 2 * std::sqrt(d / a) : d / v + v / a);
    }
    h[i] = t;
  }
  // how far each segment of the spline exceeds the limits: max of |v|/vmax and sqrt(|a|/amax)
  // (speeding a segment up by s scales velocities by s and accelerations by s^2)
  std::vector<double> ratio(n - 1);
  auto fit = [&]() {
    out.times.assign(n, 0.0);
    for (size_t i = 0; i + 1 < n; ++i) out.times[i + 1] = out.times[i] + h[i];
    ClampedSpline(out.times, path, &out.velocities, &out.accelerations);
    double worst = 0.0;
    for (size_t i = 0; i + 1 < n; ++i) {
      Segment s = MakeSegment(h[i], path[i], path[i + 1], out.velocities[i], out.velocities[i + 1],
                              nullptr, nullptr);
      double r = 0.0;
      for (Eigen::Index k = 0; k < dof; ++k) {
        // velocity is quadratic in time: extremes at the ends or at its vertex
        double c1 = s[1][k], c2 = s[2][k], c3 = s[3][k];
        double vmax = std::max(std::abs(c1), std::abs(c1 + 2 * c2 * h[i] + 3 * c3 * h[i] * h[i]));
        if (c3 != 0) {
          double tv = -c2 / (3 * c3);
          if (tv > 0 && tv < h[i])
            vmax = std::max(vmax, std::abs(c1 + 2 * c2 * tv + 3 * c3 * tv * tv));
        }
        // acceleration is linear: extremes at the ends
        double amax =
            std::max(std::abs(out.accelerations[i][k]), std::abs(out.accelerations[i + 1][k]));
        r = std::max({r, vmax / velocity_limits[k], std::sqrt(amax / acceleration_limits[k])});
      }
      ratio[i] = r;
      worst = std::max(worst, r);
    }
    return worst;
  };
  // stretch the segments that exceed the limits until none does
  double worst = fit();
  for (int it = 0; it < 100 && worst > 1.0 + 1e-9; ++it) {
    for (size_t i = 0; i + 1 < n; ++i)
      if (ratio[i] > 1.0) h[i] *= std::min(ratio[i], 2.0);
    worst = fit();
  }
  // what remains goes by scaling the whole trajectory, which scales every ratio alike
  if (worst > 1.0) {
    for (double& hi : h) hi *= worst * (1 + 1e-9);
    fit();
  }
  return out;
}

}  // namespace partsim
