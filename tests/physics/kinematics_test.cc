// KinematicModel against MuJoCo: one tree with every joint type and a coupling, built with a free
// root, a fixed root and as a kinematic articulation, placed at random joint positions. The
// scene places a kinematic articulation's links with KinematicModel, so its twin with a free
// root, placed by MuJoCo, checks that placement too.
#include "partsim/physics/kinematics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "partsim/physics/scene.h"

namespace partsim {
namespace {

enum class Root { kFree, kFixed, kKinematic };

// base -revolute-> a -prismatic-> b -fixed-> c -screw-> d -continuous-> e, and
// base -revolute-> f, coupled to the first joint (f = -0.5 * q0 + 0.2). Joint frames are
// neither at nor aligned with the link frames.
Articulation AddTree(Scene& scene, Root root, const Pose& X_WR) {
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.SetName("tree");
  b.SetInitialPose(X_WR);
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(0.4, Eigen::Vector3d(0, 1, 1).normalized()));
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(-1.1, Eigen::Vector3d(1, 0, 1).normalized()));
  struct J {
    const char* name;
    JointType type;
    int parent;
  };
  const J joints[] = {{"ja", JointType::kRevolute, 0},   {"jb", JointType::kPrismatic, 1},
                      {"jc", JointType::kFixed, 2},      {"jd", JointType::kScrew, 3},
                      {"je", JointType::kContinuous, 4}, {"jf", JointType::kRevolute, 0}};
  std::vector<LinkBuilder*> links = {b.CreateLinkBuilder()};
  links[0]->SetName("base").AddBoxCollision(Pose(), Eigen::Vector3d(0.1, 0.1, 0.05));
  for (int i = 0; i < 6; ++i) {
    const J& j = joints[i];
    LinkBuilder* l = b.CreateLinkBuilder(links[j.parent]);
    l->SetName(std::string("link_") + j.name)
        .SetJointName(j.name)
        .SetJointProperties(j.type, Eigen::Vector2d(-0.8, 0.9),
                            Pose(Eigen::Vector3d(0.1, 0.02 * i, 0.2), tilt),
                            Pose(Eigen::Vector3d(0.01, -0.03, 0.02 * i), turn))
        .AddBoxCollision(Pose(), Eigen::Vector3d(0.02, 0.03, 0.04));
    if (j.type == JointType::kScrew) l->SetScrewPitch(0.02);
    links.push_back(l);
  }
  b.GetDesc().couplings.push_back({"jf", "ja", -0.5, 0.2});
  switch (root) {
    case Root::kFree:
      return b.Build(/*fix_root_link=*/false);
    case Root::kFixed:
      return b.Build(/*fix_root_link=*/true);
    case Root::kKinematic:
      return b.BuildKinematic();
  }
  return Articulation();
}

Eigen::VectorXd RandomQ(const Eigen::MatrixX2d& limits, std::mt19937& rng) {
  Eigen::VectorXd q(limits.rows());
  for (Eigen::Index k = 0; k < q.size(); ++k) {
    const double lo = std::isfinite(limits(k, 0)) ? limits(k, 0) : -M_PI;
    const double hi = std::isfinite(limits(k, 1)) ? limits(k, 1) : M_PI;
    q[k] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

void ExpectNear(const Pose& a, const Pose& b, double tolerance, const std::string& what) {
  EXPECT_LT((a.p - b.p).norm(), tolerance) << what;
  EXPECT_LT(a.q.angularDistance(b.q), tolerance) << what;
}

TEST(KinematicModel, NumbersDofsAndLimitsAsTheArticulation) {
  Scene scene;
  Articulation art = AddTree(scene, Root::kFixed, Pose());
  const ArticulationDesc& desc = art.GetDesc();
  // one dof per joint that is not fixed, the coupled one included, in link order
  const std::vector<int> dof_links = DofLinks(desc);
  ASSERT_EQ(dof_links, (std::vector<int>{1, 2, 4, 5, 6}));
  const std::vector<Joint> active = art.GetActiveJoints();
  ASSERT_EQ(active.size(), dof_links.size());
  for (size_t k = 0; k < active.size(); ++k)
    EXPECT_EQ(active[k].GetName(), desc.links[dof_links[k]].joint.name);
  KinematicModel model(desc);
  EXPECT_EQ(model.Dof(), art.Dof());
  EXPECT_EQ(model.DofIndex("jc"), -1);
  EXPECT_EQ(model.DofIndex("je"), 3);
  // the continuous joint is unlimited
  const Eigen::MatrixX2d limits = DofLimits(desc);
  EXPECT_EQ(limits, art.GetQlimits());
  EXPECT_EQ(limits, model.Limits());
  EXPECT_EQ(limits(3, 0), -kInf);
  EXPECT_EQ(limits(3, 1), kInf);
  EXPECT_EQ(limits(0, 0), -0.8);
  EXPECT_EQ(limits(0, 1), 0.9);
}

TEST(KinematicModel, MatchesMuJoCoForEveryJointTypeWithFreeFixedAndKinematicRoots) {
  Scene scene;
  const Pose X_WR(
      Eigen::Vector3d(0.3, -0.2, 1.1),
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())));
  Articulation free = AddTree(scene, Root::kFree, X_WR);
  Articulation fixed = AddTree(scene, Root::kFixed, X_WR);
  Articulation kinematic = AddTree(scene, Root::kKinematic, X_WR);
  const int n = static_cast<int>(free.GetLinks().size());
  std::mt19937 rng(11);
  for (int s = 0; s < 30; ++s) {
    // a new root pose for the free root, kept for the others
    const Pose X_WR2(Eigen::Vector3d(0.1 * s, 0.2, 0.5),
                     Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * s, Eigen::Vector3d::UnitY())));
    free.SetRootPose(X_WR2);
    const Eigen::VectorXd q = RandomQ(DofLimits(free.GetDesc()), rng);
    for (Articulation* art : {&free, &fixed, &kinematic}) art->SetQpos(q);
    for (Articulation* art : {&free, &fixed, &kinematic}) {
      const KinematicModel model = KinematicModel::FromArticulation(*art);
      ASSERT_EQ(model.NumLinks(), n);
      const std::vector<Pose> fk = model.ForwardKinematics(q);
      for (int i = 0; i < n; ++i)
        ExpectNear(fk[i], art->GetLink(i).GetPose(), 1e-9,
                   art->GetName() + " sample " + std::to_string(s) + " link " + std::to_string(i));
    }
    // the kinematic articulation is placed where MuJoCo places its fixed-root twin
    for (int i = 0; i < n; ++i)
      ExpectNear(kinematic.GetLink(i).GetPose(), fixed.GetLink(i).GetPose(), 1e-9,
                 "kinematic vs fixed, link " + std::to_string(i));
  }
}

TEST(KinematicModel, CoupledJointMovesWithItsSourceInTheJacobian) {
  Scene scene;
  KinematicModel model(AddTree(scene, Root::kKinematic, Pose()).GetDesc());
  const int f = model.LinkIndex("link_jf");
  std::mt19937 rng(5);
  const Eigen::VectorXd q = RandomQ(model.Limits(), rng);
  // the source's column carries the coupled motion (multiplier -0.5); the coupled dof's is zero
  const Eigen::MatrixXd J = model.Jacobian(q, f);
  const double h = 1e-6;
  Eigen::VectorXd qp = q, qm = q;
  qp[0] += h;
  qm[0] -= h;
  const Eigen::Vector3d v = (model.LinkPose(qp, f).p - model.LinkPose(qm, f).p) / (2 * h);
  EXPECT_LT((J.block<3, 1>(0, 0) - v).norm(), 1e-6);
  EXPECT_GT(v.norm(), 1e-3);
  EXPECT_EQ(J.col(4).norm(), 0.0);
}

}  // namespace
}  // namespace partsim

namespace partsim {
namespace {

// A quaternion of norm 1.5 in a joint frame (Validate accepts any non-zero one) means the same
// rotation as its unit version: the compiled links, the kinematic model and the stored
// description agree with the unit description, and no position is scaled.
TEST(KinematicModel, NonUnitQuaternionsMeanTheirRotation) {
  auto build = [](double scale) {
    ArticulationDesc d;
    d.name = "bent";
    d.fix_root = true;
    d.root_pose = Pose(Eigen::Vector3d(0.3, 0, 0.2));
    d.root_pose.q.coeffs() *= scale;
    LinkDesc base;
    base.name = "base";
    base.inertial = Inertial{1.0, Pose(), Eigen::Vector3d::Constant(0.01)};
    LinkDesc arm = base;
    arm.name = "arm";
    arm.parent = 0;
    arm.joint.type = JointType::kRevolute;
    arm.joint.lower = -1;
    arm.joint.upper = 1;
    arm.joint.pose_in_parent =
        Pose(Eigen::Vector3d(0.4, 0.1, 0.0),
             Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())));
    arm.joint.pose_in_parent.q.coeffs() *= scale;
    arm.joint.pose_in_child =
        Pose(Eigen::Vector3d(-0.2, 0, 0),
             Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())));
    arm.joint.pose_in_child.q.coeffs() *= scale;
    d.links = {base, arm};
    return d;
  };
  Scene unit_scene, scaled_scene;
  Articulation unit = unit_scene.AddArticulation(build(1.0));
  Articulation scaled = scaled_scene.AddArticulation(build(1.5));
  Eigen::VectorXd q = Eigen::VectorXd::Constant(1, 0.4);
  unit.SetQpos(q);
  scaled.SetQpos(q);
  for (int i = 0; i < 2; ++i) {
    Pose a = unit.GetLink(i).GetPose(), b = scaled.GetLink(i).GetPose();
    EXPECT_LT((a.p - b.p).norm(), 1e-12) << i;
    EXPECT_LT(a.q.angularDistance(b.q), 1e-12) << i;
  }
  EXPECT_NEAR(scaled.GetDesc().links[1].joint.pose_in_parent.q.norm(), 1.0, 1e-15);
  std::vector<Pose> fk = KinematicModel(scaled.GetDesc()).ForwardKinematics(q);
  EXPECT_LT((fk[1].p - unit.GetLink(1).GetPose().p).norm(), 1e-12);
}

}  // namespace
}  // namespace partsim
