// Quality checks of PartNet-Mobility objects (load, labels, rest, range, visibility) and the
// statistics table of a dataset.
#include "partsim/assets/quality.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>

#include "core/number_text.h"
#include "partsim/assets/generator.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

// The range check drives each part as a critically damped second-order system of natural
// frequency kOmega for its own inertia, with an acceleration cap (so that a jammed part cannot
// force its way through), and cancels gravity with the passive force.
constexpr double kOmega = 15.0;            // rad/s
constexpr double kMaxAcceleration = 30.0;  // m/s^2 or rad/s^2
constexpr int kControlSteps = 10;          // steps between gravity-compensation updates
constexpr double kCrossingTime = 0.25;     // s

QualityCheck Check(const std::string& name, bool passed, const std::string& detail) {
  return {name, passed, detail};
}

// Undriven, fixed base: how far does each joint move, and does anything blow up?
QualityCheck RestCheck(Scene& scene, Articulation& art, const QualityOptions& o) {
  Eigen::VectorXd q0 = art.GetQpos();
  int steps = static_cast<int>(std::lround(o.rest_seconds / scene.GetTimestep()));
  scene.Step(steps);
  Eigen::VectorXd dq = (art.GetQpos() - q0).cwiseAbs();
  if (!scene.GetWarnings().empty())
    return Check("rest", false, "numerical trouble: " + scene.GetWarnings()[0].message);
  if (!dq.allFinite()) return Check("rest", false, "joint positions became non-finite");
  if (dq.size() == 0) return Check("rest", true, "no movable joint");
  Eigen::Index worst;
  double max = dq.maxCoeff(&worst);
  std::string joint = art.GetActiveJoints()[worst].GetName();
  return Check("rest", max <= o.rest_tolerance,
               "largest motion " + internal::Significant(max, 4) + " at joint '" + joint + "' in " +
                   internal::Significant(o.rest_seconds, 4) + " s");
}

// Mass (kg) of the links that joint `joint` moves, and their centre of mass (world).
std::pair<double, Eigen::Vector3d> MovedMass(const Articulation& art, const Joint& joint) {
  std::vector<Link> links = art.GetLinks();
  const int child = joint.GetChildLink().GetIndex();
  double mass = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const Link& l : links) {
    // is `child` on the way from l to the root?
    int i = l.GetIndex();
    while (i >= 0 && i != child) i = links[i].GetParentIndex();
    if (i != child) continue;
    mass += l.GetMass();
    moment += l.GetMass() * l.GetCMassPose().p;
  }
  return {mass, mass > 0 ? Eigen::Vector3d(moment / mass) : joint.GetGlobalPose().p};
}

// The strongest drive the range check allows a part: a force of kSizedAccelerations times the
// moved part's weight (a torque at the moved centre of mass's lever arm, at least 5 cm, for a
// hinge). Twice its weight opens anything a person would call free to move, and stays well below
// what would push a part through a solid stop (contacts are soft).
constexpr double kSizedAccelerations = 2.0;
double SizedForceLimit(const Articulation& art, const Joint& joint) {
  auto [mass, com] = MovedMass(art, joint);
  double force = kSizedAccelerations * mass * 9.81;
  if (joint.GetType() == JointType::kPrismatic) return force;
  const Pose X_WJ = joint.GetGlobalPose();
  const Eigen::Vector3d axis = joint.GetGlobalAxis();
  Eigen::Vector3d r = com - X_WJ.p;
  r -= r.dot(axis) * axis;
  return force * std::max(r.norm(), 0.05);
}

// Drives dof k to both ends of its range under the gains already set on the joint; returns
// "" when it gets within range_fraction of each end, else where it stopped.
std::string DriveThroughRange(Scene& scene, Articulation& art, size_t k, double lo, double hi,
                              const std::vector<char>& state, int chunks, const QualityOptions& o) {
  std::vector<Joint> joints = art.GetActiveJoints();
  scene.Unpack(state);
  art.SetDriveTarget(art.GetQpos());  // every other joint holds its rest position
  const double span = hi - lo;
  for (double end : {hi, lo}) {
    joints[k].SetDriveTarget(end);
    for (int c = 0; c < chunks; ++c) {
      art.SetQf(art.ComputePassiveForce(true, false));
      scene.Step(kControlSteps);
    }
    double q = art.GetQpos()[k];
    if (!std::isfinite(q))
      return "became non-finite on its way to " + internal::Significant(end, 4);
    if (std::abs(q - end) > (1.0 - o.range_fraction) * span)
      return "stopped at " + internal::Significant(q, 4) + " on its way to " +
             internal::Significant(end, 4);
  }
  return "";
}

// Each movable dof, driven alone, must cover its range both ways. First with a gentle drive for
// the part's own inertia; a part that stops is driven again with force limits four times larger
// each time, up to a drive sized to its mass (SizedForceLimit): it fails only if even that
// cannot move it through its range, and otherwise the force it needed is reported.
QualityCheck RangeCheck(Scene& scene, Articulation& art, const QualityOptions& o) {
  std::vector<Joint> joints = art.GetActiveJoints();
  Eigen::MatrixX2d limits = art.GetQlimits();
  std::vector<char> state = scene.Pack();
  int chunks = std::max(
      1, static_cast<int>(std::lround(o.range_seconds / scene.GetTimestep())) / kControlSteps);
  // gains from each dof's own inertia at rest, and its own damping and friction: the drive's
  // time constant stays near 1 / kOmega, and its force cap covers the acceleration cap, the
  // damping at the speed that crosses the range in kCrossingTime, and the dry friction
  Eigen::VectorXd inertia = art.ComputeManipulatorInertiaMatrix().diagonal();
  std::vector<double> gentle(joints.size());
  for (size_t j = 0; j < joints.size(); ++j) {
    double span = std::min(limits(j, 1) - limits(j, 0), 2 * M_PI);
    double damping = joints[j].GetDamping();
    gentle[j] =
        inertia[j] * kMaxAcceleration + damping * span / kCrossingTime + joints[j].GetFriction();
    joints[j].SetDriveProperty(inertia[j] * kOmega * kOmega + damping * kOmega,
                               2 * inertia[j] * kOmega, gentle[j]);
  }
  std::vector<std::string> jammed, forced;
  for (size_t k = 0; k < joints.size(); ++k) {
    double lo = limits(k, 0), hi = limits(k, 1);
    if (!std::isfinite(lo)) lo = -M_PI;
    if (!std::isfinite(hi)) hi = M_PI;
    const double span = hi - lo;
    std::string stop = DriveThroughRange(scene, art, k, lo, hi, state, chunks, o);
    if (stop.empty()) continue;
    // stronger drives, stiff enough to reach 2% of the span from the end at their limit
    const bool prismatic = joints[k].GetType() == JointType::kPrismatic;
    const double sized = SizedForceLimit(art, joints[k]);
    const Eigen::Vector3d saved(joints[k].GetDriveStiffness(), joints[k].GetDriveDamping(),
                                joints[k].GetDriveForceLimit());
    double needed = -1;
    for (double cap = 4 * gentle[k]; needed < 0; cap *= 4) {
      cap = std::min(cap, sized);
      const double stiffness = std::max(saved[0], cap / (0.02 * span));
      joints[k].SetDriveProperty(stiffness, 2 * std::sqrt(stiffness * inertia[k]) + saved[1], cap);
      if (DriveThroughRange(scene, art, k, lo, hi, state, chunks, o).empty()) needed = cap;
      if (cap >= sized) break;
    }
    joints[k].SetDriveProperty(saved[0], saved[1], saved[2]);
    const std::string unit = prismatic ? " N" : " N m";
    if (needed < 0) {
      jammed.push_back("'" + joints[k].GetName() + "' " + stop + " (gentle drive, " +
                       internal::Significant(gentle[k], 4) + unit +
                       ") and with a drive sized to its mass (" + internal::Significant(sized, 4) +
                       unit + ")");
    } else {
      forced.push_back("'" + joints[k].GetName() + "' needed " + internal::Significant(needed, 4) +
                       unit + " (a gentle drive of " + internal::Significant(gentle[k], 4) + unit +
                       " " + stop + ")");
    }
  }
  scene.Unpack(state);
  art.SetQf(Eigen::VectorXd::Zero(art.Dof()));
  for (Joint& j : joints) j.SetDriveProperty(0, 0);
  auto list = [](const std::vector<std::string>& v) {
    std::string out = v[0];
    for (size_t i = 1; i < std::min<size_t>(v.size(), 3); ++i) out += "; " + v[i];
    return out;
  };
  if (!jammed.empty())
    return Check("range", false, std::to_string(jammed.size()) + " jammed: " + list(jammed));
  std::string detail = std::to_string(joints.size()) + " parts cover their ranges";
  if (!forced.empty()) detail += "; " + list(forced);
  return Check("range", true, detail);
}

// Each movable part must show in some view: the caller's finder of hidden parts renders them.
QualityCheck VisibilityCheck(Scene& scene, Articulation& art, const QualityOptions& o) {
  std::vector<std::string> hidden;
  try {
    hidden = o.hidden_parts(scene, art);
  } catch (const Error& e) {
    return Check("visible", false, e.what());
  }
  if (hidden.empty()) return Check("visible", true, "every movable part shows in some view");
  return Check("visible", false,
               std::to_string(hidden.size()) + " parts never show, e.g. '" + hidden[0] + "'");
}

}  // namespace

bool ObjectQualityReport::Passed() const {
  return !checks.empty() &&
         std::all_of(checks.begin(), checks.end(), [](const QualityCheck& c) { return c.passed; });
}

std::string ObjectQualityReport::ToString() const {
  std::ostringstream s;
  s << (Passed() ? "PASS " : "FAIL ") << folder << " (" << category << ", " << movable_parts
    << " movable parts)\n";
  for (const QualityCheck& c : checks)
    s << "  " << (c.passed ? "ok   " : "FAIL ") << c.name << ": " << c.detail << "\n";
  return s.str();
}

ObjectQualityReport CheckPartNetObject(const std::string& folder, const QualityOptions& o) {
  ObjectQualityReport report;
  report.folder = folder;
  PartNetMobilityObject obj;
  try {
    obj = PartNetMobilityLoader().Parse(folder);
  } catch (const Error& e) {
    report.checks.push_back(Check("load", false, e.what()));
    return report;
  }
  report.category = obj.category;
  report.model_id = obj.model_id;
  for (const PartNetLink& l : obj.links)
    report.movable_parts += l.joint == "hinge" || l.joint == "slider";
  // the reader has cross-checked URDF, mobility_v2.json and semantics.txt; what it worked
  // around fails this check (dataset QA), while the physics checks still run
  if (obj.report.Empty()) {
    report.checks.push_back(Check("labels", true,
                                  "URDF, mobility_v2.json and semantics.txt agree on " +
                                      std::to_string(obj.links.size()) + " links"));
  } else {
    std::string detail = std::to_string(obj.report.warnings.size()) + " warning" +
                         (obj.report.warnings.size() == 1 ? "" : "s") + ": " +
                         obj.report.warnings[0].ToString();
    report.checks.push_back(Check("labels", false, detail));
  }
  if (o.check_visibility && !o.hidden_parts)
    throw Error(
        "QualityOptions::hidden_parts is not set: check_visibility needs a renderer "
        "(HiddenMovingLinksFinder in partsim/render/visibility.h), or set check_visibility "
        "to false");
  try {
    Scene scene;
    Articulation art = scene.AddArticulation(obj.articulation);
    report.checks.push_back(Check("load", true, std::to_string(art.Dof()) + " dof"));
    report.checks.push_back(RestCheck(scene, art, o));
    report.checks.push_back(RangeCheck(scene, art, o));
    if (o.check_visibility) report.checks.push_back(VisibilityCheck(scene, art, o));
  } catch (const Error& e) {
    report.checks.push_back(Check("load", false, e.what()));
  }
  return report;
}

void DatasetStatistics::Add(const std::string& category, int movable_parts) {
  auto& entry = per_category[category];
  entry.first += 1;
  entry.second += movable_parts;
  models += 1;
  parts += movable_parts;
}

std::string DatasetStatistics::ToTable(bool with_paper) const {
  std::set<std::string> cats;
  for (const auto& [c, v] : per_category) cats.insert(c);
  if (with_paper)
    for (const auto& [c, v] : PaperStatistics()) cats.insert(c);
  std::ostringstream s;
  s << std::left << std::setw(16) << "category" << std::right << std::setw(8) << "#M"
    << std::setw(8) << "#P";
  if (with_paper) s << std::setw(12) << "paper #M" << std::setw(10) << "paper #P";
  s << "\n";
  auto row = [&](const std::string& name, int m, int p, int pm, int pp) {
    s << std::left << std::setw(16) << name << std::right << std::setw(8) << m << std::setw(8) << p;
    if (with_paper) s << std::setw(12) << pm << std::setw(10) << pp;
    s << "\n";
  };
  int paper_m = 0, paper_p = 0;
  for (const std::string& c : cats) {
    auto it = per_category.find(c);
    auto pit = PaperStatistics().find(c);
    int pm = pit == PaperStatistics().end() ? 0 : pit->second.first;
    int pp = pit == PaperStatistics().end() ? 0 : pit->second.second;
    paper_m += pm;
    paper_p += pp;
    row(c, it == per_category.end() ? 0 : it->second.first,
        it == per_category.end() ? 0 : it->second.second, pm, pp);
  }
  row("All", models, parts, paper_m, paper_p);
  return s.str();
}

const std::map<std::string, std::pair<int, int>>& PaperStatistics() {
  // the generator's category table holds Table 1 of the SAPIEN paper
  static const std::map<std::string, std::pair<int, int>> table = [] {
    std::map<std::string, std::pair<int, int>> t;
    for (const std::string& c : GeneratorCategories())
      t[c] = {PaperModelCount(c), PaperPartCount(c)};
    return t;
  }();
  return table;
}

}  // namespace partsim
