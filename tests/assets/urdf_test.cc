#include "partsim/assets/urdf.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>

#include "partsim/assets/generator.h"
#include "partsim/assets/mesh.h"
#include "partsim/core/error.h"
#include "partsim/core/log.h"

namespace partsim {
namespace {

const std::string kDataDir = PARTSIM_TEST_DATA_DIR;
const std::string kMeshDir = kDataDir + "/meshes";
const std::string kArmUrdf = kDataDir + "/arm/arm_description/urdf/panda.urdf";

// A robot from a body of links and joints.
std::string Robot(const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n" + body + "</robot>\n";
}

// A link with a 10 cm box collision and a 1 kg inertial.
std::string BoxLink(const std::string& name) {
  return "<link name=\"" + name +
         "\"><collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry></collision>"
         "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" "
         "ixz=\"0\" iyz=\"0\"/></inertial></link>\n";
}

std::string Joint(const std::string& name, const std::string& type, const std::string& parent,
                  const std::string& child, const std::string& extra = "") {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent +
         "\"/><child link=\"" + child + "\"/>" + extra + "</joint>\n";
}

const LinkDesc& FindLink(const ArticulationDesc& d, const std::string& name) {
  for (const LinkDesc& l : d.links) {
    if (l.name == name) return l;
  }
  throw Error("test: no link " + name);
}

int LinkIndex(const ArticulationDesc& d, const std::string& name) {
  for (size_t i = 0; i < d.links.size(); ++i) {
    if (d.links[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

// X_PC of a link at joint position q: X_PJ * joint motion along/about x * X_CJ^-1.
Pose JointMotion(const JointDesc& j, double q) {
  Pose motion;
  if (j.type == JointType::kPrismatic) {
    motion.p = Eigen::Vector3d(q, 0, 0);
  } else if (j.type != JointType::kFixed) {
    motion.q = Eigen::AngleAxisd(q, Eigen::Vector3d::UnitX());
  }
  return j.pose_in_parent * motion * j.pose_in_child.Inverse();
}

// X_RL of every link relative to the root for joint positions by name.
std::vector<Pose> ForwardKinematics(const ArticulationDesc& d,
                                    const std::map<std::string, double>& q) {
  std::vector<Pose> x(d.links.size());
  for (size_t i = 0; i < d.links.size(); ++i) {
    const LinkDesc& l = d.links[i];
    if (l.parent < 0) continue;
    EXPECT_LT(l.parent, static_cast<int>(i)) << "parents first";
    auto it = q.find(l.joint.name);
    x[i] = x[l.parent] * JointMotion(l.joint, it == q.end() ? 0.0 : it->second);
  }
  return x;
}

// A folder of its own under the system's temporary folder, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("partsim_urdf_" + name + "_" + std::to_string(getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& file) const { return (path_ / file).string(); }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

// Writes an OBJ file of vertices (m) and triangles (0-based).
void WriteObj(const std::string& path, const std::vector<Eigen::Vector3d>& vertices,
              const std::vector<Eigen::Vector3i>& faces) {
  std::ofstream out(path);
  for (const Eigen::Vector3d& v : vertices)
    out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const Eigen::Vector3i& f : faces)
    out << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
}

// A link whose collision is the mesh `file`, with a 1 kg inertial.
std::string MeshLink(const std::string& name, const std::string& file) {
  return "<link name=\"" + name + "\"><collision><geometry><mesh filename=\"" + file +
         "\"/></geometry></collision><inertial><mass value=\"1\"/><inertia ixx=\"0.01\" "
         "iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n";
}

// The warnings of a report that contain every one of `needles`.
int CountWarnings(const LoadReport& report, const std::vector<std::string>& needles) {
  int n = 0;
  for (const LoadWarning& w : report.warnings) {
    bool all = true;
    for (const std::string& needle : needles)
      all = all && w.message.find(needle) != std::string::npos;
    n += all;
  }
  return n;
}

void ExpectPoseNear(const Pose& a, const Pose& b, double tol = 1e-9) {
  EXPECT_LT((a.p - b.p).norm(), tol) << a.ToString() << " vs " << b.ToString();
  EXPECT_LT(a.q.angularDistance(b.q), tol) << a.ToString() << " vs " << b.ToString();
}

// Expects Parse to throw partsim::Error whose message holds every piece of `needles`.
void ExpectParseError(const std::string& text, const std::vector<std::string>& needles,
                      const UrdfLoader& loader = UrdfLoader()) {
  try {
    loader.Parse(text, kMeshDir, "bad.urdf");
    ADD_FAILURE() << "no exception for:\n" << text;
  } catch (const Error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("bad.urdf"), std::string::npos) << msg;
    for (const std::string& n : needles) {
      EXPECT_NE(msg.find(n), std::string::npos) << "'" << n << "' not in: " << msg;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// the Panda-like arm

class ArmTest : public ::testing::Test {
 protected:
  void SetUp() override { arm_ = UrdfLoader().ParseFile(kArmUrdf); }
  ArticulationDesc arm_;
};

TEST_F(ArmTest, LinksJointsAndTypes) {
  EXPECT_EQ(arm_.name, "panda");
  ASSERT_EQ(arm_.links.size(), 12u);
  EXPECT_EQ(arm_.links[0].name, "panda_link0");
  EXPECT_EQ(arm_.links[0].parent, -1);
  EXPECT_TRUE(arm_.fix_root);
  std::map<JointType, int> count;
  for (size_t i = 1; i < arm_.links.size(); ++i) {
    EXPECT_GE(arm_.links[i].parent, 0);
    EXPECT_LT(arm_.links[i].parent, static_cast<int>(i));
    count[arm_.links[i].joint.type]++;
  }
  EXPECT_EQ(count[JointType::kRevolute], 7);
  EXPECT_EQ(count[JointType::kFixed], 2);
  EXPECT_EQ(count[JointType::kPrismatic], 2);
  EXPECT_EQ(arm_.links[LinkIndex(arm_, "panda_leftfinger")].parent, LinkIndex(arm_, "panda_hand"));
}

TEST_F(ArmTest, LimitsDynamicsAndEffort) {
  const JointDesc& j4 = FindLink(arm_, "panda_link4").joint;
  EXPECT_EQ(j4.name, "panda_joint4");
  EXPECT_DOUBLE_EQ(j4.lower, -3.0718);
  EXPECT_DOUBLE_EQ(j4.upper, -0.0698);
  EXPECT_DOUBLE_EQ(j4.drive.force_limit, 87.0);
  EXPECT_DOUBLE_EQ(j4.drive.stiffness, 0.0);
  EXPECT_DOUBLE_EQ(j4.damping, 0.1);
  EXPECT_DOUBLE_EQ(j4.friction, 0.05);
  const JointDesc& f1 = FindLink(arm_, "panda_leftfinger").joint;
  EXPECT_EQ(f1.type, JointType::kPrismatic);
  EXPECT_DOUBLE_EQ(f1.lower, 0.0);
  EXPECT_DOUBLE_EQ(f1.upper, 0.04);
  EXPECT_DOUBLE_EQ(f1.drive.force_limit, 20.0);
}

TEST_F(ArmTest, MimicFingerBecomesCoupling) {
  ASSERT_EQ(arm_.couplings.size(), 1u);
  EXPECT_EQ(arm_.couplings[0].joint, "panda_finger_joint2");
  EXPECT_EQ(arm_.couplings[0].source, "panda_finger_joint1");
  EXPECT_DOUBLE_EQ(arm_.couplings[0].multiplier, 1.0);
  EXPECT_DOUBLE_EQ(arm_.couplings[0].offset, 0.0);
  // both fingers open outwards, along +y and -y of the hand
  const JointDesc& left = FindLink(arm_, "panda_leftfinger").joint;
  const JointDesc& right = FindLink(arm_, "panda_rightfinger").joint;
  EXPECT_TRUE(
      (left.pose_in_parent.q * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(
      (right.pose_in_parent.q * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitY()));
}

// Craig's modified Denavit-Hartenberg parameters of the Panda, as Franka publishes them.
Pose PandaDh(const Eigen::Matrix<double, 7, 1>& q) {
  const double a[7] = {0, 0, 0, 0.0825, -0.0825, 0, 0.088};
  const double d[7] = {0.333, 0, 0.316, 0, 0.384, 0, 0};
  const double alpha[7] = {0, -M_PI / 2, M_PI / 2, M_PI / 2, -M_PI / 2, M_PI / 2, M_PI / 2};
  Pose x;
  for (int i = 0; i < 7; ++i) {
    Pose t = Pose(Eigen::Vector3d::Zero(),
                  Eigen::Quaterniond(Eigen::AngleAxisd(alpha[i], Eigen::Vector3d::UnitX()))) *
             Pose(Eigen::Vector3d(a[i], 0, 0)) *
             Pose(Eigen::Vector3d::Zero(),
                  Eigen::Quaterniond(Eigen::AngleAxisd(q[i], Eigen::Vector3d::UnitZ()))) *
             Pose(Eigen::Vector3d(0, 0, d[i]));
    x = x * t;
  }
  return x * Pose(Eigen::Vector3d(0, 0, 0.107));  // flange
}

TEST_F(ArmTest, ForwardKinematicsMatchesPublishedDh) {
  // the flange at q = 0 sits at (0.088, 0, 0.926) with its z axis pointing down
  std::vector<Pose> x0 = ForwardKinematics(arm_, {});
  const Pose& flange0 = x0[LinkIndex(arm_, "panda_link8")];
  EXPECT_LT((flange0.p - Eigen::Vector3d(0.088, 0, 0.926)).norm(), 1e-9) << flange0.ToString();
  EXPECT_TRUE((flange0.q * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitZ(), 1e-9));

  // random configurations against the DH chain
  std::srand(7);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix<double, 7, 1> q = Eigen::Matrix<double, 7, 1>::Random() * 2.5;
    std::map<std::string, double> named;
    for (int i = 0; i < 7; ++i) named["panda_joint" + std::to_string(i + 1)] = q[i];
    std::vector<Pose> x = ForwardKinematics(arm_, named);
    ExpectPoseNear(x[LinkIndex(arm_, "panda_link8")], PandaDh(q), 1e-9);
  }
}

TEST_F(ArmTest, PackageMeshesVisualsAndCollisions) {
  const LinkDesc& link0 = FindLink(arm_, "panda_link0");
  // the Collada visual has two sub-meshes with their own colours; the collision is one STL
  ASSERT_EQ(link0.visuals.size(), 2u);
  EXPECT_TRUE(link0.visuals[0].material.base_color.head<3>().isApprox(
      Eigen::Vector3f(0.95f, 0.95f, 0.95f)));
  EXPECT_TRUE(
      link0.visuals[1].material.base_color.head<3>().isApprox(Eigen::Vector3f(0.1f, 0.1f, 0.1f)));
  ASSERT_EQ(link0.collisions.size(), 1u);
  EXPECT_EQ(link0.collisions[0].type, ShapeType::kConvexMesh);
  EXPECT_NE(link0.collisions[0].mesh->source.find("collision/link0.stl"), std::string::npos);
  // the hand's visual is written in millimetres and comes out in metres, z-up
  const LinkDesc& hand = FindLink(arm_, "panda_hand");
  ASSERT_EQ(hand.visuals.size(), 1u);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
  for (const Eigen::Vector3f& v : hand.visuals[0].mesh->vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  EXPECT_TRUE((hi - lo).isApprox(Eigen::Vector3f(0.04f, 0.2f, 0.06f), 1e-5f)) << (hi - lo);
  EXPECT_NEAR(lo.z(), 0.0f, 1e-6f);
  // the dummy flange link has nothing
  const LinkDesc& link8 = FindLink(arm_, "panda_link8");
  EXPECT_TRUE(link8.visuals.empty() && link8.collisions.empty() && !link8.inertial);
}

TEST_F(ArmTest, WithoutCollisionsKeepsVisualsJointsAndInertials) {
  UrdfLoader loader;
  loader.load_collisions = false;
  const ArticulationDesc visual_only = loader.ParseFile(kArmUrdf);
  ASSERT_EQ(visual_only.links.size(), arm_.links.size());
  int collisions = 0;
  for (size_t i = 0; i < arm_.links.size(); ++i) {
    const LinkDesc& a = arm_.links[i];
    const LinkDesc& b = visual_only.links[i];
    collisions += static_cast<int>(a.collisions.size());
    EXPECT_TRUE(b.collisions.empty()) << b.name;
    EXPECT_EQ(b.visuals.size(), a.visuals.size()) << b.name;
    EXPECT_EQ(b.joint.type, a.joint.type) << b.name;
    EXPECT_EQ(b.joint.lower, a.joint.lower) << b.name;
    EXPECT_EQ(b.joint.upper, a.joint.upper) << b.name;
    EXPECT_EQ(b.inertial.has_value(), a.inertial.has_value()) << b.name;
  }
  EXPECT_GT(collisions, 0);
  // a scene takes it and moves its joints
  Scene scene;
  Articulation arm = scene.AddArticulation(visual_only);
  Eigen::VectorXd q = Eigen::VectorXd::Constant(arm.Dof(), 0.1);
  arm.SetQpos(q);
  EXPECT_TRUE(arm.GetQpos().isApprox(q));
}

TEST(UrdfTest, OneMeshFileServesVisualAndCollisionAlike) {
  const std::string dir = ::testing::TempDir() + "/urdf_shared_mesh_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  WriteObj(dir + "/box.obj",
           {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
           {{0, 2, 1},
            {0, 3, 2},
            {4, 5, 6},
            {4, 6, 7},
            {0, 1, 5},
            {0, 5, 4},
            {1, 2, 6},
            {1, 6, 5},
            {2, 3, 7},
            {2, 7, 6},
            {3, 0, 4},
            {3, 4, 7}});
  const std::string urdf = Robot(
      "<link name=\"base\"><visual><geometry><mesh filename=\"box.obj\" scale=\"0.5 0.5 "
      "0.5\"/></geometry></visual><collision><geometry><mesh filename=\"box.obj\" scale=\"0.5 "
      "0.5 0.5\"/></geometry></collision></link>\n");
  const ArticulationDesc d = UrdfLoader().Parse(urdf, dir, "shared.urdf");
  ASSERT_EQ(d.links[0].visuals.size(), 1u);
  ASSERT_EQ(d.links[0].collisions.size(), 1u);
  const MeshData& visual = *d.links[0].visuals[0].mesh;
  const MeshData& collision = *d.links[0].collisions[0].mesh;
  // separate copies of the same geometry, scaled once
  EXPECT_NE(&visual, &collision);
  ASSERT_EQ(visual.vertices.size(), collision.vertices.size());
  ASSERT_EQ(visual.faces.size(), collision.faces.size());
  for (size_t k = 0; k < visual.vertices.size(); ++k)
    EXPECT_TRUE(visual.vertices[k].isApprox(collision.vertices[k])) << k;
  float top = 0;
  for (const Eigen::Vector3f& v : collision.vertices) top = std::max(top, v.z());
  EXPECT_FLOAT_EQ(top, 0.5f);
  std::filesystem::remove_all(dir);
}

TEST_F(ArmTest, InertialIsDiagonalisedProperly) {
  // panda_link1's identified inertia tensor about its centre of mass
  const LinkDesc& l1 = FindLink(arm_, "panda_link1");
  ASSERT_TRUE(l1.inertial.has_value());
  EXPECT_DOUBLE_EQ(l1.inertial->mass, 4.970684);
  EXPECT_TRUE(
      l1.inertial->cmass_local_pose.p.isApprox(Eigen::Vector3d(0.003875, 0.002081, -0.04762)));
  Eigen::Matrix3d tensor;
  tensor << 0.70337, -0.000139, 0.006772, -0.000139, 0.70661, 0.019169, 0.006772, 0.019169,
      0.009117;
  Eigen::Matrix3d r = l1.inertial->cmass_local_pose.q.toRotationMatrix();
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  Eigen::Matrix3d back = r * l1.inertial->inertia.asDiagonal() * r.transpose();
  EXPECT_LT((back - tensor).norm(), 1e-10) << back;
}

// ---------------------------------------------------------------------------------------------
// joint frames and shapes

TEST(UrdfTest, RevoluteAboutZHasJointXAlongZ) {
  std::string urdf = Robot(BoxLink("a") + BoxLink("b") +
                           Joint("j", "revolute", "a", "b",
                                 "<origin xyz=\"0.1 0.2 0.3\" rpy=\"0.3 -0.2 0.5\"/>"
                                 "<axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"2\"/>"));
  ArticulationDesc d = UrdfLoader().Parse(urdf, kMeshDir);
  ASSERT_EQ(d.links.size(), 2u);
  const JointDesc& j = d.links[1].joint;
  EXPECT_EQ(j.type, JointType::kRevolute);
  EXPECT_DOUBLE_EQ(j.lower, -1.0);
  EXPECT_DOUBLE_EQ(j.upper, 2.0);
  Eigen::Quaterniond origin_q = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX());
  Pose origin(Eigen::Vector3d(0.1, 0.2, 0.3), origin_q);
  // the joint's x axis, in the parent, is the URDF axis in the origin frame
  EXPECT_TRUE((j.pose_in_parent.q * Eigen::Vector3d::UnitX())
                  .isApprox(origin_q * Eigen::Vector3d::UnitZ(), 1e-12));
  // at q = 0 the child frame sits at the origin exactly
  ExpectPoseNear(JointMotion(j, 0.0), origin, 1e-12);
  // turning the joint turns the child about the URDF axis
  Pose turned = origin * Pose(Eigen::Vector3d::Zero(),
                              Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ())));
  ExpectPoseNear(JointMotion(j, 0.7), turned, 1e-12);
}

TEST(UrdfTest, AxesAlongMinusXAndUnnormalised) {
  for (const auto& [text, axis] : std::vector<std::pair<std::string, Eigen::Vector3d>>{
           {"-1 0 0", -Eigen::Vector3d::UnitX()},
           {"1 0 0", Eigen::Vector3d::UnitX()},
           {"0 2 0", Eigen::Vector3d::UnitY()},
           {"0 0 -3", -Eigen::Vector3d::UnitZ()},
           {"1 1 0", Eigen::Vector3d(1, 1, 0).normalized()}}) {
    std::string urdf = Robot(BoxLink("a") + BoxLink("b") +
                             Joint("j", "prismatic", "a", "b",
                                   "<origin xyz=\"0 0 1\"/><axis xyz=\"" + text +
                                       "\"/><limit lower=\"0\" upper=\"0.5\"/>"));
    ArticulationDesc d = UrdfLoader().Parse(urdf, kMeshDir);
    const JointDesc& j = d.links[1].joint;
    EXPECT_TRUE((j.pose_in_parent.q * Eigen::Vector3d::UnitX()).isApprox(axis, 1e-12)) << text;
    ExpectPoseNear(JointMotion(j, 0.0), Pose(Eigen::Vector3d(0, 0, 1)), 1e-12);
    // sliding 0.25 moves the child along the axis
    EXPECT_TRUE(JointMotion(j, 0.25).p.isApprox(Eigen::Vector3d(0, 0, 1) + 0.25 * axis, 1e-12))
        << text;
  }
}

TEST(UrdfTest, ContinuousIsUnlimitedAndDefaultAxisIsX) {
  std::string urdf = Robot(BoxLink("a") + BoxLink("b") +
                           Joint("wheel", "continuous", "a", "b",
                                 "<limit effort=\"5\" velocity=\"3\"/>"
                                 "<dynamics damping=\"0.5\"/>"));
  ArticulationDesc d = UrdfLoader().Parse(urdf, kMeshDir);
  const JointDesc& j = d.links[1].joint;
  EXPECT_EQ(j.type, JointType::kContinuous);
  EXPECT_EQ(j.lower, -kInf);
  EXPECT_EQ(j.upper, kInf);
  EXPECT_DOUBLE_EQ(j.drive.force_limit, 5.0);
  EXPECT_DOUBLE_EQ(j.damping, 0.5);
  EXPECT_DOUBLE_EQ(j.friction, 0.0);
  EXPECT_TRUE(j.pose_in_parent.q.isApprox(Eigen::Quaterniond::Identity()));
}

TEST(UrdfTest, CylinderLiesAlongUrdfZ) {
  std::string urdf = Robot(
      "<link name=\"a\"><collision><origin xyz=\"1 2 3\" rpy=\"0.4 0 0\"/><geometry>"
      "<cylinder radius=\"0.1\" length=\"0.6\"/></geometry></collision>"
      "<visual><geometry><cylinder radius=\"0.2\" length=\"1\"/></geometry></visual></link>");
  ArticulationDesc d = UrdfLoader().Parse(urdf, kMeshDir);
  const CollisionShape& c = d.links[0].collisions.at(0);
  EXPECT_EQ(c.type, ShapeType::kCylinder);
  EXPECT_DOUBLE_EQ(c.radius, 0.1);
  EXPECT_DOUBLE_EQ(c.half_length, 0.3);
  EXPECT_TRUE(c.pose.p.isApprox(Eigen::Vector3d(1, 2, 3)));
  Eigen::Quaterniond roll(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()));
  EXPECT_TRUE(
      (c.pose.q * Eigen::Vector3d::UnitX()).isApprox(roll * Eigen::Vector3d::UnitZ(), 1e-12));
  const VisualShape& v = d.links[0].visuals.at(0);
  EXPECT_EQ(v.type, ShapeType::kCylinder);
  EXPECT_DOUBLE_EQ(v.half_length, 0.5);
  EXPECT_TRUE((v.pose.q * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
}

TEST(UrdfTest, ScaleMultipliesGeometryOriginsLimitsAndMeshes) {
  std::string urdf = Robot(
      "<link name=\"a\"><collision><origin xyz=\"0 0 1\"/><geometry><box size=\"1 2 3\"/>"
      "</geometry></collision><collision><geometry><sphere radius=\"0.5\"/></geometry>"
      "</collision><inertial><origin xyz=\"0 0 0.5\"/><mass value=\"2\"/>"
      "<inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>"
      "<link name=\"b\"><collision><geometry><mesh filename=\"cube.obj\" scale=\"1 2 1\"/>"
      "</geometry></collision></link>" +
      Joint("j", "prismatic", "a", "b",
            "<origin xyz=\"1 0 0\"/><limit lower=\"-0.1\" upper=\"0.2\"/>"));
  UrdfLoader loader;
  loader.scale = 2.0;
  ArticulationDesc d = loader.Parse(urdf, kMeshDir);
  const LinkDesc& a = d.links[0];
  EXPECT_TRUE(a.collisions[0].half_size.isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(a.collisions[0].pose.p.isApprox(Eigen::Vector3d(0, 0, 2)));
  EXPECT_DOUBLE_EQ(a.collisions[1].radius, 1.0);
  // constant density: mass x s^3, inertia x s^5
  EXPECT_DOUBLE_EQ(a.inertial->mass, 16.0);
  EXPECT_TRUE(a.inertial->inertia.isApprox(Eigen::Vector3d::Constant(32.0)));
  EXPECT_TRUE(a.inertial->cmass_local_pose.p.isApprox(Eigen::Vector3d(0, 0, 1)));
  const JointDesc& j = d.links[1].joint;
  EXPECT_DOUBLE_EQ(j.lower, -0.2);
  EXPECT_DOUBLE_EQ(j.upper, 0.4);
  EXPECT_TRUE(JointMotion(j, 0).p.isApprox(Eigen::Vector3d(2, 0, 0)));
  // unit cube x (1, 2, 1) x 2
  const MeshData& m = *d.links[1].collisions.at(0).mesh;
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
  for (const Eigen::Vector3f& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  EXPECT_TRUE(lo.isApprox(Eigen::Vector3f(-1, -2, -1))) << lo;
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(1, 2, 1))) << hi;
}

TEST(UrdfTest, WorldLinkFixedBecomesRootPose) {
  std::string urdf =
      Robot("<link name=\"world\"/>" + BoxLink("base") + BoxLink("arm") +
            Joint("anchor", "fixed", "world", "base",
                  "<origin xyz=\"1 2 0.5\" rpy=\"0 0 1.5707963267948966\"/>") +
            Joint("j", "revolute", "base", "arm", "<limit lower=\"-1\" upper=\"1\"/>"));
  UrdfLoader loader;
  loader.fix_root_link = false;  // the world joint decides
  ArticulationDesc d = loader.Parse(urdf, kMeshDir);
  ASSERT_EQ(d.links.size(), 2u);
  EXPECT_EQ(d.links[0].name, "base");
  EXPECT_EQ(d.links[0].parent, -1);
  EXPECT_EQ(d.links[1].parent, 0);
  EXPECT_TRUE(d.fix_root);
  EXPECT_TRUE(d.root_pose.p.isApprox(Eigen::Vector3d(1, 2, 0.5)));
  EXPECT_TRUE((d.root_pose.q * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
}

TEST(UrdfTest, WorldLinkFloatingFreesRoot) {
  std::string urdf = Robot("<link name=\"world\"/>" + BoxLink("base") +
                           Joint("free", "floating", "world", "base", "<origin xyz=\"0 0 2\"/>"));
  ArticulationDesc d = UrdfLoader().Parse(urdf, kMeshDir);
  ASSERT_EQ(d.links.size(), 1u);
  EXPECT_EQ(d.links[0].name, "base");
  EXPECT_FALSE(d.fix_root);
  EXPECT_TRUE(d.root_pose.p.isApprox(Eigen::Vector3d(0, 0, 2)));
}

TEST(UrdfTest, FixRootLinkOption) {
  std::string urdf = Robot(BoxLink("a"));
  UrdfLoader loader;
  EXPECT_TRUE(loader.Parse(urdf, kMeshDir).fix_root);
  loader.fix_root_link = false;
  EXPECT_FALSE(loader.Parse(urdf, kMeshDir).fix_root);
}

TEST(UrdfTest, LinksComeParentsFirstWhateverTheFileOrder) {
  std::string urdf = Robot(BoxLink("c") + BoxLink("b") + BoxLink("a") +
                           Joint("jc", "fixed", "b", "c") + Joint("jb", "fixed", "a", "b"));
  ArticulationDesc d = UrdfLoader().Parse(urdf, kMeshDir);
  ASSERT_EQ(d.links.size(), 3u);
  EXPECT_EQ(d.links[0].name, "a");
  EXPECT_EQ(d.links[1].name, "b");
  EXPECT_EQ(d.links[2].name, "c");
  EXPECT_EQ(d.links[2].parent, 1);
  EXPECT_EQ(d.links[2].joint.name, "jc");
}

TEST(UrdfTest, InertialOffDiagonalAndRotatedOrigin) {
  std::string urdf = Robot(
      "<link name=\"a\"><inertial><origin xyz=\"0.1 0 0\" rpy=\"0 0 0.3\"/><mass value=\"3\"/>"
      "<inertia ixx=\"0.2\" ixy=\"0.05\" ixz=\"0.01\" iyy=\"0.3\" iyz=\"-0.02\" izz=\"0.25\"/>"
      "</inertial></link>");
  ArticulationDesc d = UrdfLoader().Parse(urdf, kMeshDir);
  const Inertial& in = *d.links[0].inertial;
  EXPECT_DOUBLE_EQ(in.mass, 3.0);
  Eigen::Matrix3d tensor;
  tensor << 0.2, 0.05, 0.01, 0.05, 0.3, -0.02, 0.01, -0.02, 0.25;
  Eigen::Matrix3d r_origin = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Matrix3d r = in.cmass_local_pose.q.toRotationMatrix();
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  // the principal frame reproduces the tensor, expressed in the link frame
  Eigen::Matrix3d in_link = r * in.inertia.asDiagonal() * r.transpose();
  EXPECT_LT((in_link - r_origin * tensor * r_origin.transpose()).norm(), 1e-12);
  EXPECT_TRUE(in.cmass_local_pose.p.isApprox(Eigen::Vector3d(0.1, 0, 0)));
}

// A zero inertia tensor once became 1e-9 kg m^2: a link whose centre of mass lies on its axis
// then spun without resistance (-283,062 rad in 0.4 s). It now gets a 5 cm solid sphere's, with
// a warning naming the link.
TEST(UrdfTest, ZeroInertiaBecomesASolidSpheresInertiaWithAWarning) {
  std::string urdf = Robot(
      "<link name=\"a\"><inertial><mass value=\"1\"/>"
      "<inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>");
  UrdfLoader loader;
  ArticulationDesc d = loader.Parse(urdf, kMeshDir);
  ASSERT_TRUE(d.links[0].inertial.has_value());
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(d.links[0].inertial->inertia[k], 0.4 * 0.05 * 0.05, 1e-12);
  ASSERT_EQ(loader.LastReport().warnings.size(), 1u);
  EXPECT_NE(loader.LastReport().warnings[0].message.find("link 'a' <inertial> has no inertia"),
            std::string::npos)
      << loader.LastReport().warnings[0].message;
  loader.strict = true;
  EXPECT_THROW(loader.Parse(urdf, kMeshDir), Error);
}

// The spinning case itself: a wheel-like link with its centre of mass on its hinge, a zero
// tensor, and a torque. With the sphere's inertia it turns at a bounded rate.
TEST(UrdfTest, ZeroInertiaLinkOnItsAxisTurnsAtABoundedRate) {
  std::string urdf = Robot(
      "<link name=\"base\"><inertial><mass value=\"1\"/>"
      "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>"
      "<link name=\"wheel\"><inertial><mass value=\"0.5\"/>"
      "<inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>" +
      Joint("spin", "continuous", "base", "wheel"));
  Scene scene;
  UrdfLoader loader(&scene);
  loader.fix_root_link = true;
  Articulation art = loader.LoadFromString(urdf, kMeshDir);
  partsim::Joint spin = art.FindJointByName("spin");
  for (int i = 0; i < 200; ++i) {  // 0.4 s of a 0.01 N m torque
    art.SetQf(Eigen::VectorXd::Constant(1, 0.01));
    scene.Step();
  }
  // I = 0.4 m r^2 = 5e-4 kg m^2: q = tau t^2 / (2 I) = 1.6 rad
  EXPECT_NEAR(spin.GetQpos(), 0.01 * 0.4 * 0.4 / (2 * 0.4 * 0.5 * 0.0025), 0.05);
}

TEST(UrdfTest, NoInertialLeavesItUnsetAndDensityApplies) {
  std::string urdf = Robot(
      "<link name=\"a\"><collision><geometry><box size=\"1 1 1\"/></geometry></collision></link>"
      "<link name=\"b\"><collision><geometry><box size=\"1 1 1\"/></geometry></collision></link>" +
      Joint("j", "fixed", "a", "b"));
  UrdfLoader loader;
  loader.density = 500;
  loader.material = PhysicalMaterial{0.9, 0.7, 0.1};
  loader.link_overrides["b"].density = 2000;
  ArticulationDesc d = loader.Parse(urdf, kMeshDir);
  EXPECT_FALSE(d.links[0].inertial.has_value());
  EXPECT_DOUBLE_EQ(d.links[0].collisions[0].density, 500.0);
  EXPECT_DOUBLE_EQ(d.links[1].collisions[0].density, 2000.0);
  ASSERT_TRUE(d.links[1].collisions[0].material.has_value());
  EXPECT_DOUBLE_EQ(d.links[1].collisions[0].material->static_friction, 0.9);
}

TEST(UrdfTest, MimicWithMultiplierAndOffset) {
  std::string urdf = Robot(BoxLink("a") + BoxLink("b") + BoxLink("c") +
                           Joint("j1", "revolute", "a", "b", "<limit lower=\"-1\" upper=\"1\"/>") +
                           Joint("j2", "revolute", "a", "c",
                                 "<limit lower=\"-2\" upper=\"2\"/>"
                                 "<mimic joint=\"j1\" multiplier=\"-2\" offset=\"0.1\"/>"));
  ArticulationDesc d = UrdfLoader().Parse(urdf, kMeshDir);
  ASSERT_EQ(d.couplings.size(), 1u);
  EXPECT_EQ(d.couplings[0].joint, "j2");
  EXPECT_EQ(d.couplings[0].source, "j1");
  EXPECT_DOUBLE_EQ(d.couplings[0].multiplier, -2.0);
  EXPECT_DOUBLE_EQ(d.couplings[0].offset, 0.1);
  EXPECT_EQ(FindLink(d, "c").joint.type, JointType::kRevolute);  // still a joint of its own
}

TEST(UrdfTest, MaterialsInlineByNameAndFromMeshFiles) {
  std::string urdf = Robot(
      "<material name=\"steel\"><color rgba=\"0.5 0.5 0.6 1\"/></material>"
      "<link name=\"a\">"
      "<visual name=\"v1\"><geometry><box size=\"1 1 1\"/></geometry>"
      "<material name=\"steel\"/></visual>"
      "<visual><geometry><sphere radius=\"1\"/></geometry>"
      "<material name=\"red\"><color rgba=\"1 0 0 0.5\"/></material></visual>"
      "<visual name=\"from_file\"><geometry><mesh filename=\"cube.obj\"/></geometry></visual>"
      "<visual name=\"overridden\"><geometry><mesh filename=\"parts.obj\"/></geometry>"
      "<material name=\"steel\"/></visual>"
      "</link>");
  ArticulationDesc d = UrdfLoader().Parse(urdf, kMeshDir);
  const std::vector<VisualShape>& v = d.links[0].visuals;
  ASSERT_EQ(v.size(), 5u);  // parts.obj has two sub-meshes
  EXPECT_EQ(v[0].name, "v1");
  EXPECT_TRUE(v[0].material.base_color.isApprox(Eigen::Vector4f(0.5f, 0.5f, 0.6f, 1)));
  EXPECT_EQ(v[1].name, "");
  EXPECT_TRUE(v[1].material.base_color.isApprox(Eigen::Vector4f(1, 0, 0, 0.5f)));
  EXPECT_EQ(v[2].type, ShapeType::kConvexMesh);
  EXPECT_TRUE(v[2].material.base_color.head<3>().isApprox(Eigen::Vector3f(0.8f, 0.2f, 0.1f)));
  EXPECT_EQ(v[3].name, "overridden");
  EXPECT_TRUE(v[3].material.base_color.isApprox(Eigen::Vector4f(0.5f, 0.5f, 0.6f, 1)));
  EXPECT_TRUE(v[4].material.base_color.isApprox(Eigen::Vector4f(0.5f, 0.5f, 0.6f, 1)));
}

TEST(UrdfTest, MultipleCollisionsFromFile) {
  std::string urdf = Robot(
      "<link name=\"a\"><collision><geometry><mesh filename=\"two_boxes.obj\"/></geometry>"
      "</collision></link>");
  UrdfLoader loader;
  EXPECT_EQ(loader.Parse(urdf, kMeshDir).links[0].collisions.size(), 1u);
  loader.load_multiple_collisions_from_file = true;
  ArticulationDesc d = loader.Parse(urdf, kMeshDir);
  ASSERT_EQ(d.links[0].collisions.size(), 2u);
  for (const CollisionShape& c : d.links[0].collisions) {
    EXPECT_EQ(c.type, ShapeType::kConvexMesh);
    EXPECT_EQ(c.mesh->faces.size(), 12u);
  }
}

TEST(UrdfTest, MeshPathResolution) {
  std::string tail = "\"/></geometry></collision></link>";
  std::string head = "<link name=\"a\"><collision><geometry><mesh filename=\"";
  UrdfLoader loader;
  // package:// through package_dirs
  loader.package_dirs["things"] = kMeshDir;
  EXPECT_NO_THROW(loader.Parse(Robot(head + "package://things/cube.obj" + tail), "/nonexistent"));
  // package:// by searching upward from the URDF's folder for a folder of that name
  std::string urdf_dir = kDataDir + "/arm/arm_description/urdf";
  EXPECT_NO_THROW(UrdfLoader().Parse(
      Robot(head + "package://arm_description/meshes/collision/hand.stl" + tail), urdf_dir));
  // a folder of that name beside one of the URDF's parent folders
  EXPECT_NO_THROW(
      UrdfLoader().Parse(Robot(head + "package://meshes/cube.obj" + tail), kDataDir + "/arm"));
  // file:// and absolute paths
  EXPECT_NO_THROW(
      UrdfLoader().Parse(Robot(head + "file://" + kMeshDir + "/box.stl" + tail), "/nonexistent"));
  // relative to base_dir
  EXPECT_NO_THROW(UrdfLoader().Parse(Robot(head + "../meshes/box.gltf" + tail), kDataDir + "/arm"));
}

// ---------------------------------------------------------------------------------------------
// files as they are found: what the loader repairs, and warns about

TEST(UrdfTest, MimicOnAFixedJointIsIgnoredWithAWarning) {
  UrdfLoader loader;
  ArticulationDesc d =
      loader.Parse(Robot(BoxLink("a") + BoxLink("b") + BoxLink("c") +
                         Joint("j1", "revolute", "a", "b", "<limit lower=\"-1\" upper=\"1\"/>") +
                         Joint("weld", "fixed", "a", "c", "<mimic joint=\"j1\"/>")),
                   kMeshDir, "gripper.urdf");
  EXPECT_TRUE(d.couplings.empty());
  ASSERT_EQ(loader.LastReport().warnings.size(), 1u);
  EXPECT_EQ(loader.LastReport().warnings[0].file, "gripper.urdf");
  EXPECT_EQ(CountWarnings(loader.LastReport(), {"joint 'weld'", "fixed", "<mimic>", "ignored"}), 1);
  // a later parse starts a new report
  loader.Parse(Robot(BoxLink("a")), kMeshDir);
  EXPECT_TRUE(loader.LastReport().Empty());
}

TEST(UrdfTest, InertiaThatBreaksTheTriangleInequalityIsBalanced) {
  // principal moments 0.001 + 0.002 < 0.01 (a rotated tensor, as exported files have them)
  const std::string urdf =
      Robot(BoxLink("base") +
            "<link name=\"hatch\"><collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry>"
            "</collision><inertial><origin rpy=\"0.3 0.2 0.1\"/><mass value=\"2\"/>"
            "<inertia ixx=\"0.001\" iyy=\"0.002\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
            "</inertial></link>" +
            Joint("hinge", "revolute", "base", "hatch", "<limit lower=\"-1\" upper=\"1\"/>"));
  UrdfLoader loader;
  ArticulationDesc d = loader.Parse(urdf, kMeshDir, "robot.urdf");
  const Inertial& in = *FindLink(d, "hatch").inertial;
  // all three set to their mean, as MuJoCo's balanceinertia does; mass unchanged
  const double mean = (0.001 + 0.002 + 0.01) / 3;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(in.inertia[k], mean, 1e-12);
  EXPECT_DOUBLE_EQ(in.mass, 2.0);
  ASSERT_EQ(loader.LastReport().warnings.size(), 1u);
  const std::string& msg = loader.LastReport().warnings[0].message;
  EXPECT_EQ(
      CountWarnings(loader.LastReport(), {"link 'hatch'", "A + B >= C", "0.01", "0.00433333"}), 1)
      << msg;
  // MuJoCo takes the result
  Scene scene;
  Articulation art = scene.AddArticulation(d);
  scene.Step(10);
  EXPECT_TRUE(art.GetQpos().allFinite());
}

TEST(UrdfTest, InertiaOnTheTriangleEqualityNeedsNoRepair) {
  // a thin disc (A + B = C) turned by its origin: rounding alone must not make MuJoCo refuse it
  UrdfLoader loader;
  ArticulationDesc d = loader.Parse(
      Robot("<link name=\"disc\"><inertial><origin rpy=\"0.7 -0.4 1.1\"/><mass value=\"1\"/>"
            "<inertia ixx=\"0.0025\" iyy=\"0.0025\" izz=\"0.005\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
            "</inertial></link>"),
      kMeshDir);
  EXPECT_TRUE(loader.LastReport().Empty()) << loader.LastReport().ToString();
  const Eigen::Vector3d m = d.links[0].inertial->inertia;
  EXPECT_NEAR(m[2], 0.005, 1e-12);
  EXPECT_GE(m[0] + m[1], m[2]);
  d.fix_root = false;
  Scene scene;
  EXPECT_NO_THROW(scene.AddArticulation(d));
}

TEST(UrdfTest, LimitWithoutLowerOrUpperLeavesTheJointUnlimited) {
  // ANYmal's joints give effort and velocity only; URDF's defaults 0, 0 would lock them
  UrdfLoader loader;
  ArticulationDesc d = loader.Parse(
      Robot(BoxLink("a") + BoxLink("b") +
            Joint("HAA", "revolute", "a", "b", "<limit effort=\"80\" velocity=\"20\"/>")),
      kMeshDir);
  const JointDesc& j = FindLink(d, "b").joint;
  EXPECT_EQ(j.lower, -kInf);
  EXPECT_EQ(j.upper, kInf);
  EXPECT_DOUBLE_EQ(j.drive.force_limit, 80.0);
  EXPECT_EQ(CountWarnings(loader.LastReport(), {"joint 'HAA'", "unlimited"}), 1);
  // one bound given: the other is URDF's default 0
  d = loader.Parse(
      Robot(BoxLink("a") + BoxLink("b") + Joint("j", "revolute", "a", "b", "<limit upper=\"1\"/>")),
      kMeshDir);
  EXPECT_EQ(FindLink(d, "b").joint.lower, 0.0);
  EXPECT_TRUE(loader.LastReport().Empty());
}

TEST(UrdfTest, StrictLoadingTurnsRepairsIntoErrors) {
  UrdfLoader loader;
  loader.strict = true;
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b") + BoxLink("c") +
                         Joint("j1", "revolute", "a", "b", "<limit lower=\"-1\" upper=\"1\"/>") +
                         Joint("weld", "fixed", "a", "c", "<mimic joint=\"j1\"/>")),
                   {"joint 'weld'", "<mimic>", "strict"}, loader);
  ExpectParseError(Robot("<link name=\"lopsided\"><inertial><mass value=\"1\"/><inertia "
                         "ixx=\"0.001\" iyy=\"0.001\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
                         "</inertial></link>"),
                   {"link 'lopsided'", "A + B >= C", "strict"}, loader);
}

TEST(UrdfErrorTest, AllMissingMeshFilesInOneError) {
  TempDir dir("missing");
  std::ofstream(dir / "empty.stl").close();
  const std::string urdf = Robot(
      MeshLink("base", "meshes/gone_0.stl") + MeshLink("arm", "package://nowhere/gone_1.obj") +
      "<link name=\"hand\"><visual><geometry><mesh filename=\"meshes/gone_2.dae\"/></geometry>"
      "</visual><collision><geometry><mesh filename=\"empty.stl\"/></geometry></collision></link>" +
      Joint("j1", "fixed", "base", "arm") + Joint("j2", "fixed", "arm", "hand"));
  try {
    UrdfLoader().Parse(urdf, dir.str(), "bad.urdf");
    FAIL() << "no exception";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("4 files"), std::string::npos) << msg;
    for (const char* needle :
         {"link 'base' <collision>", "meshes/gone_0.stl", "link 'arm' <collision>",
          "package://nowhere/gone_1.obj", "link 'hand' <visual>", "meshes/gone_2.dae",
          "link 'hand' <collision>", "'empty.stl' is empty"})
      EXPECT_NE(msg.find(needle), std::string::npos) << needle << " not in: " << msg;
  }
}

TEST(UrdfTest, NonConvexMeshWarnsOncePerFileAndConvexOnesNever) {
  // an L-shaped bracket (closed, 0.3 m), used by two links; a cube mesh beside it
  TempDir dir("nonconvex");
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector3i> f;
  {
    // the L's profile in xz, extruded 0.1 m along y
    const double p[6][2] = {{0, 0}, {0.3, 0}, {0.3, 0.05}, {0.05, 0.05}, {0.05, 0.3}, {0, 0.3}};
    for (double y : {0.0, 0.1})
      for (const auto& q : p) v.emplace_back(q[0], y, q[1]);
    // the two caps (a fan from the inner corner 3 covers the L), then the sides
    const int fan[4][2] = {{4, 5}, {5, 0}, {0, 1}, {1, 2}};
    for (const auto& t : fan) {
      f.emplace_back(3, t[1], t[0]);
      f.emplace_back(9, t[0] + 6, t[1] + 6);
    }
    for (int k = 0; k < 6; ++k) {
      const int a = k, b = (k + 1) % 6;
      f.emplace_back(a, b, b + 6);
      f.emplace_back(a, b + 6, a + 6);
    }
  }
  WriteObj(dir / "bracket.obj", v, f);
  const std::string urdf = Robot(MeshLink("a", "bracket.obj") + MeshLink("b", "bracket.obj") +
                                 MeshLink("c", kMeshDir + "/cube.obj") +
                                 Joint("j1", "fixed", "a", "b") + Joint("j2", "fixed", "a", "c"));
  UrdfLoader loader;
  loader.Parse(urdf, dir.str(), "robot.urdf");
  EXPECT_EQ(CountWarnings(loader.LastReport(), {"not convex"}), 1)
      << loader.LastReport().ToString();
  EXPECT_EQ(CountWarnings(loader.LastReport(),
                          {"link 'a'", "mesh 'bracket.obj'", "load_multiple_collisions_from_file",
                           "partsim assets decompose"}),
            1)
      << loader.LastReport().ToString();
  EXPECT_EQ(CountWarnings(loader.LastReport(), {"cube.obj"}), 0);
  // no defect of the file: a warning even when loading strictly
  loader.strict = true;
  loader.Parse(urdf, dir.str(), "robot.urdf");
  EXPECT_EQ(CountWarnings(loader.LastReport(), {"not convex"}), 1);
  loader.strict = false;
  // as connected pieces the L is still one non-convex piece: decompose it
  loader.load_multiple_collisions_from_file = true;
  loader.Parse(urdf, dir.str(), "robot.urdf");
  EXPECT_EQ(
      CountWarnings(loader.LastReport(), {"1 of 1", "not convex", "partsim assets decompose"}), 0);
  EXPECT_EQ(CountWarnings(loader.LastReport(), {"not convex", "partsim assets decompose"}), 1)
      << loader.LastReport().ToString();
  // the boxes of the test data are convex, alone or as pieces
  for (bool multiple : {false, true}) {
    loader.load_multiple_collisions_from_file = multiple;
    // parts.obj holds two boxes apart: as one hull it is not convex, as pieces it is
    for (const char* mesh : {"cube.obj", "box.stl", "box.gltf", "box_cm.dae", "parts.obj"}) {
      if (!multiple && std::string(mesh) == "parts.obj") continue;
      loader.Parse(Robot(MeshLink("a", mesh)), kMeshDir);
      EXPECT_TRUE(loader.LastReport().Empty()) << mesh << ": " << loader.LastReport().ToString();
    }
  }
}

TEST(UrdfTest, GeneratedObjectsLoadWithoutWarnings) {
  // the generator's pieces are closed convex meshes: nothing to repair, nothing non-convex,
  // whether each file is one piece or its connected parts are
  TempDir dir("generated");
  const std::vector<std::string> categories = GeneratorCategories();
  for (size_t k = 0; k < categories.size(); k += 5) {
    const std::string folder = dir / categories[k];
    WriteObject(GenerateObject(categories[k], 0, 7), folder);
    for (bool multiple : {false, true}) {
      UrdfLoader loader;
      loader.load_multiple_collisions_from_file = multiple;
      loader.ParseFile(folder + "/mobility.urdf");
      EXPECT_TRUE(loader.LastReport().Empty())
          << categories[k] << ": " << loader.LastReport().ToString();
    }
  }
}

TEST(UrdfTest, ParseFileNamesTheFileInErrors) {
  try {
    UrdfLoader().ParseFile(kDataDir + "/no_such_robot.urdf");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_robot.urdf"), std::string::npos);
  }
}

TEST(UrdfTest, LoadWithoutSceneThrows) {
  UrdfLoader loader;
  EXPECT_THROW(loader.LoadFromString(Robot(BoxLink("a"))), Error);
  EXPECT_THROW(loader.Load(kArmUrdf), Error);
}

// ---------------------------------------------------------------------------------------------
// bad input: each error names the element at fault

TEST(UrdfErrorTest, MalformedXmlNamesLine) {
  ExpectParseError("<robot name=\"r\">\n<link name=\"a\">\n</robot>\n", {"line"});
  ExpectParseError("<robot name=\"r\">\n\n<link name=\"a\"/>\n<joint name='x'\n</robot>\n",
                   {"line 4"});
}

TEST(UrdfErrorTest, NoRobot) { ExpectParseError("<robt/>", {"<robot>"}); }

TEST(UrdfErrorTest, JointMissingParentOrChild) {
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b") +
                         "<joint name=\"jx\" type=\"fixed\"><child link=\"b\"/></joint>"),
                   {"jx", "parent"});
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b") +
                         "<joint name=\"jy\" type=\"fixed\"><parent link=\"a\"/></joint>"),
                   {"jy", "child"});
}

TEST(UrdfErrorTest, ParentThatDoesNotExist) {
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b") + Joint("j3", "fixed", "link_9", "b")),
                   {"j3", "link_9", "does not exist"});
}

TEST(UrdfErrorTest, CycleTwoRootsAndTwoParents) {
  // a cycle b -> c -> b beside root a
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b") + BoxLink("c") +
                         Joint("j1", "fixed", "b", "c") + Joint("j2", "fixed", "c", "b")),
                   {"cycle"});
  // a full cycle leaves no root
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b") + Joint("j1", "fixed", "a", "b") +
                         Joint("j2", "fixed", "b", "a")),
                   {"cycle"});
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b")), {"root", "'a'", "'b'"});
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b") + BoxLink("c") +
                         Joint("j1", "fixed", "a", "c") + Joint("j2", "fixed", "b", "c")),
                   {"'c'", "two parent", "j1", "j2"});
}

TEST(UrdfErrorTest, DuplicateNames) {
  ExpectParseError(Robot(BoxLink("a") + BoxLink("a")), {"link 'a'", "twice"});
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b") + BoxLink("c") +
                         Joint("j", "fixed", "a", "b") + Joint("j", "fixed", "a", "c")),
                   {"joint 'j'", "twice"});
}

TEST(UrdfErrorTest, BadNumbers) {
  std::string links = BoxLink("a") + BoxLink("b");
  ExpectParseError(Robot(links + Joint("jn", "fixed", "a", "b", "<origin xyz=\"nan 0 0\"/>")),
                   {"jn", "origin", "nan"});
  ExpectParseError(Robot(links + Joint("ji", "fixed", "a", "b", "<origin rpy=\"0 inf 0\"/>")),
                   {"ji", "rpy", "inf"});
  ExpectParseError(Robot(links + Joint("jt", "fixed", "a", "b", "<origin xyz=\"0 zero 0\"/>")),
                   {"jt", "zero", "not a number"});
  ExpectParseError(Robot(links + Joint("jc", "fixed", "a", "b", "<origin xyz=\"0 0\"/>")),
                   {"jc", "expected 3"});
  ExpectParseError(
      Robot(links + Joint("jl", "revolute", "a", "b", "<limit lower=\"-1rad\" upper=\"1\"/>")),
      {"jl", "lower", "-1rad"});
  ExpectParseError(Robot("<link name=\"bx\"><collision><geometry><box size=\"1 1\"/>"
                         "</geometry></collision></link>"),
                   {"bx", "box size", "expected 3"});
}

TEST(UrdfErrorTest, MissingMeshFile) {
  ExpectParseError(Robot("<link name=\"handle\"><visual><geometry>"
                         "<mesh filename=\"package://nowhere/handle.obj\"/></geometry></visual>"
                         "</link>"),
                   {"handle", "package://nowhere/handle.obj", "not found"});
  ExpectParseError(Robot("<link name=\"lid\"><collision><geometry>"
                         "<mesh filename=\"missing.stl\"/></geometry></collision></link>"),
                   {"lid", "missing.stl"});
}

TEST(UrdfErrorTest, UnsupportedJointTypes) {
  std::string links = BoxLink("a") + BoxLink("b");
  ExpectParseError(Robot(links + Joint("jw", "wobbly", "a", "b")),
                   {"jw", "unknown type", "wobbly"});
  ExpectParseError(Robot(links + Joint("j3", "planar", "a", "b")),
                   {"joint 'j3' has type 'planar', which partsim does not support"});
  ExpectParseError(Robot(links + Joint("jf", "floating", "a", "b")), {"jf", "floating"});
  ExpectParseError(
      Robot(links + "<joint name=\"jt\"><parent link=\"a\"/><child link=\"b\"/></joint>"),
      {"jt", "no type"});
}

TEST(UrdfErrorTest, LimitsAndAxis) {
  std::string links = BoxLink("a") + BoxLink("b");
  ExpectParseError(Robot(links + Joint("jr", "revolute", "a", "b")), {"jr", "<limit>"});
  ExpectParseError(Robot(links + Joint("jp", "prismatic", "a", "b")), {"jp", "<limit>"});
  ExpectParseError(
      Robot(links + Joint("jo", "revolute", "a", "b", "<limit lower=\"1\" upper=\"-1\"/>")),
      {"jo", "lower"});
  ExpectParseError(Robot(links + Joint("jz", "revolute", "a", "b",
                                       "<axis xyz=\"0 0 0\"/><limit lower=\"-1\" upper=\"1\"/>")),
                   {"jz", "axis"});
}

TEST(UrdfErrorTest, NegativeMassAndBadInertia) {
  ExpectParseError(Robot("<link name=\"heavy\"><inertial><mass value=\"-1\"/></inertial></link>"),
                   {"heavy", "negative mass"});
  ExpectParseError(Robot("<link name=\"odd\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" "
                         "iyy=\"1\" izz=\"-1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>"),
                   {"odd", "positive semi-definite"});
}

TEST(UrdfErrorTest, UnknownMimicSource) {
  ExpectParseError(Robot(BoxLink("a") + BoxLink("b") +
                         Joint("jm", "revolute", "a", "b",
                               "<limit lower=\"-1\" upper=\"1\"/><mimic joint=\"ghost\"/>")),
                   {"jm", "ghost", "does not exist"});
}

TEST(UrdfErrorTest, BadGeometry) {
  ExpectParseError(Robot("<link name=\"g\"><collision><geometry><cone radius=\"1\"/></geometry>"
                         "</collision></link>"),
                   {"g", "cone"});
  ExpectParseError(Robot("<link name=\"e\"><collision><origin xyz=\"0 0 0\"/></collision></link>"),
                   {"e", "<geometry>"});
  ExpectParseError(Robot("<link name=\"s\"><collision><geometry><sphere radius=\"-1\"/>"
                         "</geometry></collision></link>"),
                   {"s", "radius"});
}

TEST(UrdfErrorTest, SourceDefaultsToString) {
  try {
    UrdfLoader().Parse("<robot/>", ".");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("<string>"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace partsim

namespace partsim {
namespace {

// ---------------------------------------------------------------------------------------------
// loading into a scene

TEST(UrdfSceneTest, ArmLoadsWithItsDofsAndKinematics) {
  Scene scene;
  UrdfLoader loader = CreateUrdfLoader(scene);
  Articulation arm = loader.Load(kArmUrdf);
  EXPECT_EQ(arm.GetName(), "panda");
  EXPECT_TRUE(arm.HasFixedRoot());
  EXPECT_EQ(arm.GetLinks().size(), 12u);
  // 7 arm joints and two fingers; the mimicking finger keeps a dof of its own
  ASSERT_EQ(arm.Dof(), 9);
  EXPECT_EQ(arm.GetActiveJoints()[8].GetName(), "panda_finger_joint2");
  Eigen::MatrixX2d lim = arm.GetQlimits();
  EXPECT_NEAR(lim(3, 0), -3.0718, 1e-12);
  EXPECT_NEAR(lim(3, 1), -0.0698, 1e-12);
  EXPECT_NEAR(lim(7, 1), 0.04, 1e-12);
  EXPECT_NEAR(arm.FindLinkByName("panda_link1").GetMass(), 4.970684, 1e-9);

  // the scene's forward kinematics agree with the published DH chain
  std::srand(11);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(9);
    for (int i = 0; i < 7; ++i) {
      q[i] = lim(i, 0) + (lim(i, 1) - lim(i, 0)) * (0.5 + 0.4 * Eigen::VectorXd::Random(1)[0]);
    }
    q[7] = 0.02;
    arm.SetQpos(q);
    Pose flange = arm.FindLinkByName("panda_link8").GetPose();
    ExpectPoseNear(flange, PandaDh(q.head<7>()), 1e-6);
    // the mimicking finger mirrors the driven one about the hand
    Pose hand = arm.FindLinkByName("panda_hand").GetPose();
    Pose left = hand.Inverse() * arm.FindLinkByName("panda_leftfinger").GetPose();
    Pose right = hand.Inverse() * arm.FindLinkByName("panda_rightfinger").GetPose();
    EXPECT_NEAR(left.p.y(), 0.02, 1e-6);
    EXPECT_NEAR(right.p.y(), -0.02, 1e-6);
  }
}

TEST(UrdfSceneTest, FloatingWorldJointFallsUnderGravity) {
  Scene scene;
  UrdfLoader loader = CreateUrdfLoader(scene);
  Articulation a = loader.LoadFromString(
      Robot("<link name=\"world\"/>" + BoxLink("base") +
            Joint("free", "floating", "world", "base", "<origin xyz=\"0 0 2\"/>")),
      kMeshDir);
  EXPECT_FALSE(a.HasFixedRoot());
  EXPECT_NEAR(a.GetRootPose().p.z(), 2.0, 1e-9);
  const double t = 0.2;
  scene.Step(static_cast<int>(std::lround(t / scene.GetTimestep())));
  EXPECT_NEAR(a.GetRootPose().p.z(), 2.0 - 0.5 * 9.81 * t * t, 0.01);
}

TEST(UrdfSceneTest, FlatAndTinyCollisionPiecesStillSimulate) {
  // a 0.2 m square (4 points, no volume) and a speck 10 micrometres across, in one file and as
  // separate pieces
  TempDir dir("flat");
  WriteObj(dir / "quad.obj", {{-0.1, -0.1, 0}, {0.1, -0.1, 0}, {0.1, 0.1, 0}, {-0.1, 0.1, 0}},
           {{0, 1, 2}, {0, 2, 3}});
  WriteObj(dir / "speck.obj", {{0, 0, 0}, {1e-5, 0, 0}, {0, 1e-5, 0}, {0, 0, 1e-5}},
           {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
  for (bool multiple : {false, true}) {
    Scene scene;
    scene.AddGround(0.0);
    UrdfLoader loader = CreateUrdfLoader(scene);
    loader.fix_root_link = false;
    loader.load_multiple_collisions_from_file = multiple;
    Articulation plate = loader.LoadFromString(
        Robot(MeshLink("plate", "quad.obj") + MeshLink("dust", "speck.obj") +
              Joint("glue", "fixed", "plate", "dust", "<origin xyz=\"0 0 0.05\"/>")),
        dir.str());
    const LoadReport& report = loader.LastReport();
    EXPECT_EQ(CountWarnings(report, {"link 'plate'", "mesh 'quad.obj'", "flat", "thick"}), 1)
        << report.ToString();
    EXPECT_EQ(CountWarnings(report, {"link 'dust'", "mesh 'speck.obj'", "dropped"}), 1)
        << report.ToString();
    // the plate keeps a thin hull, the speck is gone
    EXPECT_EQ(plate.FindLinkByName("plate").GetDesc().collisions.size(), 1u);
    EXPECT_TRUE(plate.FindLinkByName("dust").GetDesc().collisions.empty());
    // dropped from 0.2 m beside its twin made of a box as thick as its hull (3% of 0.2 m, at
    // most 5 mm), the plate comes to rest on the ground at the twin's height
    const std::string inertial =
        "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" "
        "ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
    Articulation twin = loader.LoadFromString(
        Robot("<link name=\"plate\"><collision><geometry><box size=\"0.2 0.2 0.005\"/>"
              "</geometry></collision>" +
              inertial + "</link><link name=\"dust\">" + inertial + "</link>" +
              Joint("glue", "fixed", "plate", "dust", "<origin xyz=\"0 0 0.05\"/>")),
        dir.str());
    plate.SetRootPose(Pose(Eigen::Vector3d(0, 0, 0.2)));
    twin.SetRootPose(Pose(Eigen::Vector3d(1, 0, 0.2)));
    scene.Step(1000);
    EXPECT_NEAR(plate.GetRootPose().p.z(), twin.GetRootPose().p.z(), 5e-4);
    EXPECT_NEAR(plate.GetRootPose().p.z(), 0.0025, 1e-3);
    EXPECT_LT(plate.GetRootVelocity().norm(), 1e-2);
  }
}

TEST(UrdfSceneTest, MimicJointIsADofThatFollowsItsSource) {
  // a two-finger gripper: the right finger mimics the left
  const std::string urdf =
      Robot(BoxLink("palm") + BoxLink("left") + BoxLink("right") +
            Joint("left_joint", "prismatic", "palm", "left",
                  "<origin xyz=\"0 0.05 0.1\"/><axis xyz=\"0 1 0\"/>"
                  "<limit lower=\"0\" upper=\"0.04\" effort=\"50\" velocity=\"1\"/>") +
            Joint("right_joint", "prismatic", "palm", "right",
                  "<origin xyz=\"0 -0.05 0.1\"/><axis xyz=\"0 -1 0\"/>"
                  "<limit lower=\"0\" upper=\"0.04\" effort=\"50\" velocity=\"1\"/>"
                  "<mimic joint=\"left_joint\" multiplier=\"1\" offset=\"0\"/>"));
  Scene scene;
  UrdfLoader loader = CreateUrdfLoader(scene);
  Articulation g = loader.LoadFromString(urdf, kMeshDir);
  // dof counts every non-fixed joint, as SAPIEN does
  ASSERT_EQ(g.Dof(), 2);
  std::vector<partsim::Joint> active = g.GetActiveJoints();
  ASSERT_EQ(active.size(), 2u);
  EXPECT_EQ(active[0].GetName(), "left_joint");
  EXPECT_EQ(active[1].GetName(), "right_joint");
  EXPECT_EQ(g.GetQlimits()(1, 1), 0.04);
  // only the source is driven; gravity pulls both fingers along -z, not along their axes
  active[0].SetDriveProperty(2000, 100);
  active[0].SetDriveTarget(0.03);
  scene.Step(500);  // 1 s
  Eigen::VectorXd q = g.GetQpos();
  EXPECT_NEAR(q[0], 0.03, 1e-3);
  EXPECT_NEAR(q[1], q[0], 1e-3);
  const double gap =
      (g.FindLinkByName("left").GetPose().p - g.FindLinkByName("right").GetPose().p).norm();
  EXPECT_NEAR(gap, 0.1 + 2 * 0.03, 2e-3);
  // each finger carries its own rows in the dynamics queries
  EXPECT_EQ(g.ComputeManipulatorInertiaMatrix().rows(), 2);
  EXPECT_EQ(g.ComputeLinkJacobian(2).cols(), 2);
}

TEST(UrdfSceneTest, MuJoCoErrorsNameTheUrdfsJoints) {
  // a revolute joint whose limits coincide: MuJoCo refuses it; the message names the URDF joint
  Scene scene;
  UrdfLoader loader = CreateUrdfLoader(scene);
  loader.LoadFromString(Robot(BoxLink("a")), kMeshDir);  // so the robot is not the first one
  try {
    loader.LoadFromString(
        Robot(BoxLink("base") + BoxLink("lid") +
              Joint("stuck", "revolute", "base", "lid", "<limit lower=\"0.3\" upper=\"0.3\"/>")),
        kMeshDir);
    FAIL() << "no exception";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("joint 'stuck'"), std::string::npos) << msg;
    EXPECT_FALSE(std::regex_search(msg, std::regex("\\br[0-9]+_[a-z]"))) << msg;
    EXPECT_EQ(msg.find("line ="), std::string::npos) << msg;
  }
  // an inertia that breaks A + B >= C given directly, past the URDF loader's repair
  ArticulationDesc d = loader.Parse(
      Robot(BoxLink("base") + BoxLink("lid") +
            Joint("hinge", "revolute", "base", "lid", "<limit lower=\"0\" upper=\"1\"/>")),
      kMeshDir);
  d.links[1].inertial->inertia = Eigen::Vector3d(0.001, 0.001, 0.01);
  try {
    scene.AddArticulation(d);
    FAIL() << "no exception";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("A + B >= C"), std::string::npos) << msg;
    EXPECT_NE(msg.find("link 'lid'"), std::string::npos) << msg;
    EXPECT_FALSE(std::regex_search(msg, std::regex("\\br[0-9]+_[a-z]"))) << msg;
  }
  EXPECT_EQ(scene.GetArticulations().size(), 1u);
}

TEST(UrdfSceneTest, ErrorsLeaveTheSceneUsable) {
  Scene scene;
  UrdfLoader loader = CreateUrdfLoader(scene);
  EXPECT_THROW(loader.LoadFromString(Robot(BoxLink("a") + BoxLink("a"))), Error);
  EXPECT_TRUE(scene.GetArticulations().empty());
  loader.LoadFromString(Robot(BoxLink("a")));
  EXPECT_EQ(scene.GetArticulations().size(), 1u);
}

// ---------------------------------------------------------------------------------------------
// size bounds

// A robot of `joints` revolute links below a root link "root": all on the root (wide), or in one
// chain (deep). Links without geometry; with `missing_mesh` the first has a visual mesh file that
// does not exist.
std::string GeneratedRobot(int joints, bool deep, bool missing_mesh = true) {
  std::string body = "<link name=\"root\"/>\n";
  for (int i = 0; i < joints; ++i) {
    const std::string name = "l" + std::to_string(i);
    body += i == 0 && missing_mesh
                ? "<link name=\"l0\"><visual><geometry><mesh filename=\"missing.obj\"/>"
                  "</geometry></visual></link>\n"
                : "<link name=\"" + name + "\"/>\n";
    body += Joint("j" + std::to_string(i), "revolute",
                  deep && i > 0 ? "l" + std::to_string(i - 1) : "root", name,
                  "<axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\"/>");
  }
  return Robot(body);
}

TEST(UrdfBoundsTest, RobotOfTooManyLinksIsRefusedBeforeItsLinksAreRead) {
  // kMaxUrdfLinks + 1 links: refused by count, not for the missing mesh of its first link
  ExpectParseError(GeneratedRobot(kMaxUrdfLinks, false),
                   {"robot has " + std::to_string(kMaxUrdfLinks + 1) + " links",
                    "more than the " + std::to_string(kMaxUrdfLinks), "split it"});
  // at the limit the file is read (and its missing mesh reported)
  ExpectParseError(GeneratedRobot(kMaxUrdfLinks - 1, false), {"missing.obj"});
}

TEST(UrdfBoundsTest, ChainDeeperThanTheLimitIsRefusedNamingItsLink) {
  const std::string last = "l" + std::to_string(kMaxUrdfChainDepth);
  ExpectParseError(GeneratedRobot(kMaxUrdfChainDepth + 1, true),
                   {"link '" + last + "'", std::to_string(kMaxUrdfChainDepth + 1) + " joints below",
                    "deeper than the " + std::to_string(kMaxUrdfChainDepth)});
  ExpectParseError(GeneratedRobot(kMaxUrdfChainDepth, true), {"missing.obj"});
}

TEST(UrdfBoundsTest, ChainAtTheDepthLimitCompiles) {
  // MuJoCo refuses bodies about 1023 below the world: the limit leaves room for a world link
  Scene scene;
  UrdfLoader loader = CreateUrdfLoader(scene);
  loader.fix_root_link = false;
  Articulation chain = loader.LoadFromString(GeneratedRobot(kMaxUrdfChainDepth, true, false));
  EXPECT_EQ(chain.Dof(), kMaxUrdfChainDepth);
}

TEST(UrdfBoundsTest, CylinderOfManySegmentsLoadsAsABoundedHullWithAWarning) {
  // the side of a 5,000-segment cylinder (10,000 points on two planes): qhull's merging of them
  // took 10 s; the piece keeps kMaxConvexPieceVertices, which a strict load only warns about
  TempDir dir("many_segments");
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector3i> f;
  const int n = 5000;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    v.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.0);
    v.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.3);
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i, b = 2 * ((i + 1) % n);
    f.emplace_back(a, b, b + 1);
    f.emplace_back(a, b + 1, a + 1);
  }
  WriteObj(dir / "drum.obj", v, f);
  UrdfLoader loader;
  loader.strict = true;
  ArticulationDesc d = loader.Parse(Robot(MeshLink("drum", "drum.obj")), dir.str(), "drum.urdf");
  ASSERT_EQ(d.links[0].collisions.size(), 1u);
  EXPECT_LE(d.links[0].collisions[0].mesh->vertices.size(),
            static_cast<size_t>(kMaxConvexPieceVertices));
  EXPECT_EQ(
      CountWarnings(loader.LastReport(), {"drum.obj", "collides as the hull of", "m outside"}), 1);
}

}  // namespace
}  // namespace partsim
