// Collision filtering: links joined by a joint, pairs an articulation disables, and SAPIEN's
// collision groups on shapes.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <tuple>

#include "partsim/core/error.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

const Eigen::Quaterniond kXToY(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));

SceneConfig WeightlessConfig() {
  SceneConfig c;
  c.gravity.setZero();  // only contacts can move what the drives hold
  return c;
}

// A fixed base (box, top at z = 0.05) and a column on a revolute joint about y at z = 0.1. With
// `gap_link`, a second revolute joint at the column's top carries a short link, and the
// overlapping piece hangs from that link instead (two moving joints below the base). The piece,
// fixed below, reaches 5 cm down into the base: "tip" hangs from the column through a fixed
// joint (two joints below the base). Drives hold every moving joint at 0.
Articulation AddOverlappingChain(Scene& scene, bool gap_link = false) {
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  b.SetName("chain");
  LinkBuilder* base = b.CreateLinkBuilder();
  base->SetName("base").AddBoxCollision(Pose(), Eigen::Vector3d(0.2, 0.2, 0.05));
  LinkBuilder* column = b.CreateLinkBuilder(base);
  column->SetName("column")
      .SetJointName("j1")
      .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-1, 1),
                          Pose(Eigen::Vector3d(0, 0, 0.1), kXToY),
                          Pose(Eigen::Vector3d::Zero(), kXToY))
      .AddBoxCollision(Pose(Eigen::Vector3d(0, 0, 0.1)), Eigen::Vector3d(0.02, 0.02, 0.1));
  LinkBuilder* holder = column;
  Eigen::Vector3d tip_at(0.1, 0, 0);  // in the holder
  if (gap_link) {
    holder = b.CreateLinkBuilder(column);
    holder->SetName("upper")
        .SetJointName("j2")
        .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-1, 1),
                            Pose(Eigen::Vector3d(0, 0, 0.2), kXToY),
                            Pose(Eigen::Vector3d::Zero(), kXToY))
        .AddBoxCollision(Pose(Eigen::Vector3d(0, 0, 0.05)), Eigen::Vector3d(0.02, 0.02, 0.05));
    tip_at = Eigen::Vector3d(0.1, 0, -0.2);
  }
  LinkBuilder* tip = b.CreateLinkBuilder(holder);
  // world z of the tip's centre: 0.1 + 0.2 * gap_link + tip_at.z - 0.04 = 0.06, half height 0.06
  tip->SetName("tip")
      .SetJointName("tip_joint")
      .SetJointProperties(JointType::kFixed, Eigen::Vector2d::Zero(), Pose(tip_at), Pose())
      .AddBoxCollision(Pose(Eigen::Vector3d(0, 0, -0.04)), Eigen::Vector3d(0.03, 0.03, 0.06));
  Articulation art = b.Build(/*fix_root_link=*/true);
  for (Joint j : art.GetActiveJoints()) j.SetDriveProperty(200, 20);
  art.SetDriveTarget(Eigen::VectorXd::Zero(art.Dof()));
  return art;
}

// Largest |q| over 1 s of simulation.
double Drift(Scene& scene, const Articulation& art) {
  double drift = 0;
  for (int i = 0; i < 500; ++i) {
    scene.Step();
    drift = std::max(drift, art.GetQpos().cwiseAbs().maxCoeff());
  }
  return drift;
}

// Contacts between two named bodies in the last step.
int ContactsBetween(const Scene& scene, const std::string& a, const std::string& b) {
  int n = 0;
  for (const Contact& c : scene.GetContacts())
    if ((c.body0.name == a && c.body1.name == b) || (c.body0.name == b && c.body1.name == a)) ++n;
  return n;
}

TEST(CollisionFilterTest, LinkBelowAFixedJointDoesNotTouchTheLinkAboveItsParent) {
  // the tip hangs (through a fixed joint) from the column and reaches into the fixed base: the
  // base and the column's rigid group are joined by a joint, so nothing pushes the column
  Scene scene(WeightlessConfig());
  Articulation chain = AddOverlappingChain(scene);
  EXPECT_LT(Drift(scene, chain), 1e-6);
  EXPECT_EQ(ContactsBetween(scene, "base", "tip"), 0);

  // the same overlap with a body that is not part of the chain pushes the column well off 0:
  // what the filter takes away is a real, strong contact
  Scene control(WeightlessConfig());
  Articulation chain2 = AddOverlappingChain(control);
  control.CreateActorBuilder()
      .SetName("slab")
      .AddBoxCollision(Pose(), Eigen::Vector3d(0.2, 0.2, 0.05))
      .BuildStatic();
  EXPECT_GT(Drift(control, chain2), 0.05);
  EXPECT_GT(ContactsBetween(control, "slab", "tip"), 0);
}

TEST(CollisionFilterTest, DisableCollisionAtRunTimeStopsContactsAndKeepsTheState) {
  // two moving joints separate the tip from the base: they collide until disabled
  Scene scene(WeightlessConfig());
  Articulation chain = AddOverlappingChain(scene, /*gap_link=*/true);
  scene.Step(50);
  EXPECT_GT(ContactsBetween(scene, "base", "tip"), 0);
  Eigen::VectorXd q = chain.GetQpos(), qd = chain.GetQvel();
  EXPECT_GT(q.cwiseAbs().maxCoeff(), 1e-3);  // pushed

  chain.DisableCollision(chain.FindLinkByName("tip"), chain.FindLinkByName("base"));
  EXPECT_EQ(chain.GetQpos(), q);  // recompiled, state kept
  EXPECT_EQ(chain.GetQvel(), qd);
  ASSERT_EQ(chain.GetDesc().disabled_collisions.size(), 1u);
  EXPECT_NE(scene.GetMjcf().find("<exclude"), std::string::npos);
  scene.Step(500);
  EXPECT_EQ(ContactsBetween(scene, "base", "tip"), 0);
  EXPECT_LT(chain.GetQpos().cwiseAbs().maxCoeff(), 1e-3);  // the drives bring it back
  // disabling the same pair again (either order) changes nothing
  chain.DisableCollision(chain.FindLinkByName("base"), chain.FindLinkByName("tip"));
  EXPECT_EQ(chain.GetDesc().disabled_collisions.size(), 1u);

  // a disabled pair in the description has the same effect from the start
  Scene scene2(WeightlessConfig());
  ArticulationDesc desc = AddOverlappingChain(scene2, true).GetDesc();
  scene2.RemoveArticulation(scene2.GetArticulations()[0]);
  desc.disabled_collisions = {{"tip", "base"}};
  Articulation again = scene2.AddArticulation(desc);
  for (Joint j : again.GetActiveJoints()) j.SetDriveProperty(200, 20);
  EXPECT_LT(Drift(scene2, again), 1e-6);
}

TEST(CollisionFilterTest, DisabledPairNamingAnUnknownLinkIsAnError) {
  Scene scene;
  ArticulationDesc desc = AddOverlappingChain(scene).GetDesc();
  desc.disabled_collisions = {{"tip", "hand"}};
  try {
    Validate(desc);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("articulation 'chain'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'hand'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(scene.AddArticulation(desc), Error);

  // links of another articulation cannot be disabled
  Articulation a = scene.GetArticulations()[0];
  Scene other;
  Articulation b = AddOverlappingChain(other);
  EXPECT_THROW(a.DisableCollision(a.GetLink(0), b.GetLink(1)), Error);
}

// A box of half-size 0.1 resting on the ground (centre z = 0.1) and another dropped on it from
// z = 0.35, with the given groups; returns the upper box's height after 1 s.
double UpperBoxHeight(const std::array<uint32_t, 4>& lower, const std::array<uint32_t, 4>& upper) {
  Scene scene;
  scene.AddGround(0);
  for (auto [name, z, groups] :
       {std::make_tuple("lower", 0.1, lower), std::make_tuple("upper", 0.35, upper)}) {
    scene.CreateActorBuilder()
        .SetName(name)
        .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1))
        .SetCollisionGroups(groups)
        .SetInitialPose(Pose(Eigen::Vector3d(0, 0, z)))
        .Build();
  }
  scene.Step(500);
  return scene.FindActorByName("upper").GetPose().p.z();
}

TEST(CollisionFilterTest, CollisionGroupsFollowSapiensRule) {
  const uint32_t all = 0xFFFFFFFFu;
  const double rests = 0.3, falls_through = 0.1;
  // default groups collide
  EXPECT_NEAR(UpperBoxHeight({1, all, 0, 0}, {1, all, 0, 0}), rests, 0.01);
  // g0 / g1 disjoint both ways: no contact (each still lands on the ground)
  EXPECT_NEAR(UpperBoxHeight({1, 1, 0, 0}, {2, 2, 0, 0}), falls_through, 0.01);
  // one way is enough to collide
  EXPECT_NEAR(UpperBoxHeight({1, 1, 0, 0}, {2, 3, 0, 0}), rests, 0.01);
  // the high bit survives MuJoCo's signed integers
  EXPECT_NEAR(UpperBoxHeight({0x80000000u, 1, 0, 0}, {2, 0x80000000u, 0, 0}), rests, 0.01);
  EXPECT_NEAR(UpperBoxHeight({0x80000000u, 1, 0, 0}, {2, 0x40000000u, 0, 0}), falls_through, 0.01);
  // g2 sharing a bit and g3 equal: ignored
  EXPECT_NEAR(UpperBoxHeight({1, all, 5, 7}, {1, all, 4, 7}), falls_through, 0.01);
  // g3 different, or no shared g2 bit: collide
  EXPECT_NEAR(UpperBoxHeight({1, all, 4, 7}, {1, all, 4, 8}), rests, 0.01);
  EXPECT_NEAR(UpperBoxHeight({1, all, 1, 7}, {1, all, 2, 7}), rests, 0.01);
}

TEST(CollisionFilterTest, ShapeGroupsChangeAtRunTimeAndKeepTheState) {
  Scene scene;
  scene.AddGround(0);
  Actor lower = scene.CreateActorBuilder()
                    .SetName("lower")
                    .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1))
                    .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 0.1)))
                    .Build();
  Actor upper = scene.CreateActorBuilder()
                    .SetName("upper")
                    .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1))
                    .SetInitialPose(Pose(Eigen::Vector3d(0, 0, 0.3)))
                    .Build();
  scene.Step(200);
  EXPECT_NEAR(upper.GetPose().p.z(), 0.3, 0.01);
  ASSERT_EQ(upper.GetCollisionShapes().size(), 1u);
  Shape shape = upper.GetCollisionShapes()[0];
  EXPECT_EQ(shape.GetCollisionGroups(), (std::array<uint32_t, 4>{1, 0xFFFFFFFFu, 0, 0}));

  // g2 / g3 (a recompile): the upper box now sinks through
  Pose before = upper.GetPose();
  for (Actor a : {lower, upper}) a.GetCollisionShapes()[0].SetCollisionGroups({1, 1, 2, 9});
  EXPECT_EQ(upper.GetPose().p, before.p);
  EXPECT_EQ(upper.GetDesc().collisions[0].collision_groups[3], 9u);
  scene.Step(300);
  EXPECT_NEAR(upper.GetPose().p.z(), 0.1, 0.01);

  // g0 / g1 only (patched in place): lift it back above the lower box, it rests there again
  for (Actor a : {lower, upper}) a.GetCollisionShapes()[0].SetCollisionGroups({1, 1, 0, 0});
  upper.SetPose(Pose(Eigen::Vector3d(0, 0, 0.31)));
  upper.SetVelocity(Eigen::Vector3d::Zero());
  scene.Step(300);
  EXPECT_NEAR(upper.GetPose().p.z(), 0.3, 0.01);
  // ... and falls through when g0 / g1 no longer meet
  upper.GetCollisionShapes()[0].SetCollisionGroups({2, 2, 0, 0});
  scene.Step(300);
  EXPECT_NEAR(upper.GetPose().p.z(), 0.1, 0.01);
  // a clone compiles the same groups
  auto clone = scene.Clone();
  EXPECT_EQ(clone->FindActorByName("upper").GetCollisionShapes()[0].GetCollisionGroups()[0], 2u);

  EXPECT_THROW(Shape(&scene, upper.GetId(), -1, -1, 3).GetCollisionGroups(), Error);
}

TEST(CollisionFilterTest, LinkShapesTakeGroupsFromTheLinkBuilder) {
  // groups set on a link builder reach the shapes added before and after the call
  Scene scene;
  scene.AddGround(0);
  ArticulationBuilder b = scene.CreateArticulationBuilder();
  LinkBuilder* root = b.CreateLinkBuilder();
  root->SetName("root").AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.1));
  root->SetCollisionGroups({1, 1, 1, 5});
  LinkBuilder* flap = b.CreateLinkBuilder(root);
  flap->SetName("flap")
      .SetJointProperties(JointType::kRevolute, Eigen::Vector2d(-3, 3), Pose(), Pose())
      .SetCollisionGroups({1, 1, 1, 5})
      .AddBoxCollision(Pose(), Eigen::Vector3d::Constant(0.05));
  Articulation art = b.Build(false);
  for (Link l : art.GetLinks())
    EXPECT_EQ(l.GetCollisionShapes()[0].GetCollisionGroups(),
              (std::array<uint32_t, 4>{1, 1, 1, 5}));
  EXPECT_EQ(b.GetDesc().links[1].collisions[0].collision_groups[2], 0u);  // builder untouched
}

}  // namespace
}  // namespace partsim
