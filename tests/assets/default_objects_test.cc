#include "partsim/assets/default_objects.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

ArticulationDesc ParseCabinet(const CabinetOptions& opts = CabinetOptions()) {
  return UrdfLoader().Parse(MakeCabinetUrdf(opts), ".", "cabinet.urdf");
}

const LinkDesc& FindLink(const ArticulationDesc& d, const std::string& name) {
  for (const LinkDesc& l : d.links) {
    if (l.name == name) return l;
  }
  throw Error("test: no link " + name);
}

// X_PC of a link at joint position q (joints act along or about x of the joint frame).
Pose ChildInParent(const JointDesc& j, double q) {
  Pose motion;
  if (j.type == JointType::kPrismatic) {
    motion.p = Eigen::Vector3d(q, 0, 0);
  } else {
    motion.q = Eigen::AngleAxisd(q, Eigen::Vector3d::UnitX());
  }
  return j.pose_in_parent * motion * j.pose_in_child.Inverse();
}

// Volume of a collision shape (m^3).
double Volume(const CollisionShape& s) {
  switch (s.type) {
    case ShapeType::kBox:
      return 8.0 * s.half_size.prod();
    case ShapeType::kCylinder:
      return M_PI * s.radius * s.radius * 2.0 * s.half_length;
    default:
      ADD_FAILURE() << "unexpected shape " << ShapeTypeName(s.type);
      return 0.0;
  }
}

TEST(DefaultObjectsTest, CabinetHasABodyADrawerAndADoor) {
  ArticulationDesc d = ParseCabinet();
  ASSERT_EQ(d.links.size(), 3u);
  EXPECT_EQ(d.name, "cabinet");
  const LinkDesc& body = FindLink(d, "body");
  const LinkDesc& drawer = FindLink(d, "drawer_0");
  const LinkDesc& door = FindLink(d, "door_0");
  EXPECT_EQ(body.parent, -1);
  EXPECT_EQ(d.links[drawer.parent].name, "body");
  EXPECT_EQ(d.links[door.parent].name, "body");

  EXPECT_EQ(drawer.joint.name, "drawer_0_joint");
  EXPECT_EQ(drawer.joint.type, JointType::kPrismatic);
  EXPECT_DOUBLE_EQ(drawer.joint.lower, 0.0);
  EXPECT_DOUBLE_EQ(drawer.joint.upper, 0.4);
  EXPECT_EQ(door.joint.name, "door_0_joint");
  EXPECT_EQ(door.joint.type, JointType::kRevolute);
  EXPECT_DOUBLE_EQ(door.joint.lower, 0.0);
  EXPECT_DOUBLE_EQ(door.joint.upper, 1.6);
  for (const LinkDesc* l : {&drawer, &door}) {
    EXPECT_GT(l->joint.friction, 0.0);
    EXPECT_LT(l->joint.friction, 1.0);
    EXPECT_GT(l->joint.damping, 0.0);
    EXPECT_LT(l->joint.damping, 5.0);
  }
  // walls: back, sides, top, bottom, divider; the drawer is an open box with a 3-piece handle
  EXPECT_EQ(body.collisions.size(), 6u);
  EXPECT_EQ(drawer.collisions.size(), 8u);
  EXPECT_EQ(door.collisions.size(), 4u);
}

TEST(DefaultObjectsTest, MassesFollowShapeVolumesAndDensities) {
  CabinetOptions opts;
  ArticulationDesc d = ParseCabinet(opts);
  double total = 0.0;
  for (const LinkDesc& l : d.links) {
    ASSERT_TRUE(l.inertial.has_value()) << l.name;
    double expected = 0.0;
    for (const CollisionShape& s : l.collisions) {
      bool handle = s.name.rfind("handle-", 0) == 0;
      expected += Volume(s) * (handle ? opts.handle_density : opts.wood_density);
    }
    EXPECT_NEAR(l.inertial->mass, expected, 1e-6 * expected) << l.name;
    EXPECT_TRUE((l.inertial->inertia.array() > 0).all()) << l.name;
    total += l.inertial->mass;
  }
  // a wooden kitchen cabinet of 0.8 x 0.6 x 0.5 m weighs a few tens of kilograms
  EXPECT_GT(total, 15.0);
  EXPECT_LT(total, 60.0);
  EXPECT_LT(FindLink(d, "drawer_0").inertial->mass, 10.0);
  EXPECT_LT(FindLink(d, "door_0").inertial->mass, 6.0);
}

TEST(DefaultObjectsTest, PartsAreNamedLikePartNetMobility) {
  ArticulationDesc d = ParseCabinet();
  auto count = [](const LinkDesc& l, const std::string& name) {
    int n = 0;
    for (const VisualShape& v : l.visuals) n += v.name == name;
    return n;
  };
  EXPECT_EQ(count(FindLink(d, "drawer_0"), "handle-drawer_0"), 3);  // bar and two posts
  EXPECT_EQ(count(FindLink(d, "door_0"), "handle-door_0"), 3);
  EXPECT_EQ(count(FindLink(d, "door_0"), "panel-door_0"), 1);
  EXPECT_EQ(count(FindLink(d, "drawer_0"), "front-drawer_0"), 1);
}

TEST(DefaultObjectsTest, DrawerSlidesOutOfTheFrontAndDoorSwingsOutwards) {
  for (bool left : {false, true}) {
    CabinetOptions opts;
    opts.door_hinge_left = left;
    ArticulationDesc d = ParseCabinet(opts);
    const LinkDesc& drawer = FindLink(d, "drawer_0");
    const LinkDesc& door = FindLink(d, "door_0");
    // the drawer's axis is the cabinet's +x, out of the front face at x = depth / 2
    Eigen::Vector3d axis = drawer.joint.pose_in_parent.q * Eigen::Vector3d::UnitX();
    EXPECT_NEAR(axis.x(), 1.0, 1e-9);
    Eigen::Vector3d handle_closed =
        ChildInParent(drawer.joint, 0.0).Transform(Eigen::Vector3d::Zero());
    Eigen::Vector3d handle_open =
        ChildInParent(drawer.joint, 0.3).Transform(Eigen::Vector3d::Zero());
    EXPECT_NEAR(handle_closed.x(), opts.depth / 2, 1e-9);
    EXPECT_NEAR(handle_open.x() - handle_closed.x(), 0.3, 1e-9);
    // the door turns about a vertical axis on the hinge side
    Eigen::Vector3d hinge = door.joint.pose_in_parent.q * Eigen::Vector3d::UnitX();
    EXPECT_NEAR(std::abs(hinge.z()), 1.0, 1e-9);
    EXPECT_EQ(door.joint.pose_in_parent.p.y() > 0, left);
    // the panel's centre moves out of the front when the door opens
    const CollisionShape& panel = door.collisions[0];
    ASSERT_EQ(panel.name, "panel-door_0");
    Eigen::Vector3d closed = ChildInParent(door.joint, 0.0).Transform(panel.pose.p);
    Eigen::Vector3d open = ChildInParent(door.joint, 1.2).Transform(panel.pose.p);
    EXPECT_NEAR(closed.x(), opts.depth / 2 + opts.wall_thickness / 2, 1e-9);
    EXPECT_GT(open.x(), closed.x() + 0.2) << (left ? "left" : "right") << " hinge";
  }
}

TEST(DefaultObjectsTest, SeedVariesSizesDeterministically) {
  CabinetOptions a, b, c;
  a.seed = 7;
  b.seed = 7;
  c.seed = 8;
  EXPECT_EQ(MakeCabinetUrdf(a), MakeCabinetUrdf(b));
  EXPECT_NE(MakeCabinetUrdf(a), MakeCabinetUrdf(c));
  EXPECT_NE(MakeCabinetUrdf(a), MakeCabinetUrdf(CabinetOptions()));
  // every seeded cabinet is still a valid three-link cabinet
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    CabinetOptions o;
    o.seed = seed;
    ArticulationDesc d = ParseCabinet(o);
    EXPECT_EQ(d.links.size(), 3u) << "seed " << seed;
    EXPECT_NO_THROW(Validate(d)) << "seed " << seed;
  }
}

TEST(DefaultObjectsTest, BadOptionsAreNamed) {
  CabinetOptions o;
  o.height = -1.0;
  try {
    MakeCabinetUrdf(o);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("height"), std::string::npos) << e.what();
  }
  o = CabinetOptions();
  o.drawer_travel = 2.0;  // deeper than the cabinet
  try {
    MakeCabinetUrdf(o);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("drawer_travel"), std::string::npos) << e.what();
  }
}

// Closed, the cabinet rests without contacts between its parts; fully open, too; PD drives open
// the drawer and the door.
TEST(DefaultObjectsTest, CabinetSimulatesWithoutSelfContactAndOpensUnderDrives) {
  Scene scene;
  UrdfLoader loader = CreateUrdfLoader(scene);
  loader.fix_root_link = true;
  Articulation cabinet = loader.LoadFromString(MakeCabinetUrdf());
  ASSERT_EQ(cabinet.Dof(), 2);
  Joint drawer = cabinet.FindJointByName("drawer_0_joint");
  Joint door = cabinet.FindJointByName("door_0_joint");

  // closed: gravity alone moves nothing
  scene.Step(500);
  EXPECT_NEAR(drawer.GetQpos(), 0.0, 1e-4);
  EXPECT_NEAR(door.GetQpos(), 0.0, 1e-4);
  EXPECT_TRUE(scene.GetContacts().empty());

  // fully open: still no part touches another
  Eigen::VectorXd open(2);
  open[drawer.GetDofIndex()] = 0.4;
  open[door.GetDofIndex()] = 1.6;
  cabinet.SetQpos(open);
  scene.Step();
  EXPECT_TRUE(scene.GetContacts().empty());

  // drives from closed
  cabinet.SetQpos(Eigen::VectorXd::Zero(2));
  cabinet.SetQvel(Eigen::VectorXd::Zero(2));
  drawer.SetDriveProperty(200.0, 80.0);
  door.SetDriveProperty(20.0, 8.0);
  drawer.SetDriveTarget(0.3);
  door.SetDriveTarget(1.2);
  scene.Step(1500);
  EXPECT_NEAR(drawer.GetQpos(), 0.3, 0.01);
  EXPECT_NEAR(door.GetQpos(), 1.2, 0.03);
}

}  // namespace
}  // namespace partsim
