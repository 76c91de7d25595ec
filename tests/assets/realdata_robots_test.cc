// Robot URDFs as users find them (../shared/realdata, see its README.md): KUKA iiwa variants, one
// of which names meshes that are not there; the Shadow hand (24 dof, many small links); ANYmal C
// (inertias that break the triangle inequality, joint limits without bounds). Each loads with the
// file's joints, or fails with one error that lists every missing file; and each, its root fixed
// and held by PD drives, stays where it is put or goes where it is driven.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

const fs::path kRealData = fs::path(PARTSIM_SOURCE_DIR) / ".." / "shared" / "realdata";

#define SKIP_WITHOUT_REALDATA(folder)                    \
  if (!fs::is_directory(kRealData / folder))             \
  GTEST_SKIP() << "no " << (kRealData / folder).string() \
               << " (the shared real-data folder, ../shared/realdata/" << folder << ")"

// A joint as the URDF file states it, read with tinyxml2 apart from partsim's loader.
struct FileJoint {
  std::string type;
  bool has_lower = false, has_upper = false;
  double lower = 0.0, upper = 0.0;
};

std::map<std::string, FileJoint> JointsOfFile(const fs::path& path) {
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.LoadFile(path.c_str()), tinyxml2::XML_SUCCESS) << path;
  std::map<std::string, FileJoint> out;
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) return out;
  for (const tinyxml2::XMLElement* j = robot->FirstChildElement("joint"); j != nullptr;
       j = j->NextSiblingElement("joint")) {
    FileJoint f;
    f.type = j->Attribute("type");
    if (const tinyxml2::XMLElement* l = j->FirstChildElement("limit")) {
      f.has_lower = l->QueryDoubleAttribute("lower", &f.lower) == tinyxml2::XML_SUCCESS;
      f.has_upper = l->QueryDoubleAttribute("upper", &f.upper) == tinyxml2::XML_SUCCESS;
    }
    out[j->Attribute("name")] = f;
  }
  return out;
}

// The articulation's joints are the file's: the same names and types, every non-fixed joint a
// dof (mimic joints included), and the file's limits (unlimited where the file gives no bound).
void ExpectJointsOfFile(const Articulation& art, const fs::path& path) {
  const std::map<std::string, FileJoint> file = JointsOfFile(path);
  int moving = 0;
  for (const auto& [name, f] : file) {
    if (f.type == "floating") continue;  // the root's joint to the world, not a joint
    moving += f.type != "fixed";
    Joint j = art.FindJointByName(name);
    EXPECT_EQ(JointTypeName(j.GetType()), f.type) << name;
    EXPECT_EQ(j.GetDof(), f.type == "fixed" ? 0 : 1) << name;
    if (f.type == "revolute" || f.type == "prismatic") {
      const Eigen::Vector2d lim = j.GetLimits();
      if (f.has_lower || f.has_upper) {
        EXPECT_DOUBLE_EQ(lim[0], f.lower) << name;
        EXPECT_DOUBLE_EQ(lim[1], f.upper) << name;
      } else {
        EXPECT_EQ(lim[0], -kInf) << name;
        EXPECT_EQ(lim[1], kInf) << name;
      }
    }
  }
  EXPECT_EQ(art.Dof(), moving);
  EXPECT_EQ(static_cast<int>(art.GetActiveJoints().size()), moving);
}

// No message of the report uses a name partsim generates for MuJoCo (r1_l3, r1_j3, mesh4).
void ExpectOnlyFileNames(const LoadReport& report) {
  for (const LoadWarning& w : report.warnings) {
    EXPECT_FALSE(std::regex_search(w.message, std::regex("\\br[0-9]+_[a-z]"))) << w.message;
    EXPECT_EQ(w.message.find("mesh0"), std::string::npos) << w.message;
  }
}

// How many warnings of a report name `what`.
int CountWarningsNaming(const LoadReport& report, const std::string& what) {
  int n = 0;
  for (const LoadWarning& w : report.warnings) n += w.message.find(what) != std::string::npos;
  return n;
}

// Largest joint motion (rad or m) of a fixed-root robot held by PD drives at `q0` with targets
// `target`, over `seconds` of simulation under gravity, and the joint error at the end.
struct Held {
  double drift = 0.0;      ///< largest |q - q0| seen
  double final_error = 0;  ///< largest |q - target| at the end
};

Held HoldWithDrives(Scene& scene, Articulation& art, const Eigen::VectorXd& q0,
                    const Eigen::VectorXd& target, double stiffness, double damping,
                    double seconds) {
  art.SetQpos(q0);
  art.SetQvel(Eigen::VectorXd::Zero(art.Dof()));
  for (Joint& j : art.GetActiveJoints()) j.SetDriveProperty(stiffness, damping);
  art.SetDriveTarget(target);
  Held out;
  const int steps = static_cast<int>(std::lround(seconds / scene.GetTimestep()));
  for (int k = 0; k < steps; ++k) {
    scene.Step(1);
    out.drift = std::max(out.drift, (art.GetQpos() - q0).cwiseAbs().maxCoeff());
  }
  out.final_error = (art.GetQpos() - target).cwiseAbs().maxCoeff();
  return out;
}

TEST(RealDataRobots, KukaVariantsLoadWithTheFilesJoints) {
  SKIP_WITHOUT_REALDATA("kuka_iiwa");
  for (const char* variant : {"model.urdf", "model_free_base.urdf", "model_vr_limits.urdf"}) {
    SCOPED_TRACE(variant);
    Scene scene;
    UrdfLoader loader = CreateUrdfLoader(scene);
    Articulation arm = loader.Load((kRealData / "kuka_iiwa" / variant).string());
    EXPECT_EQ(arm.Dof(), 7);
    ExpectJointsOfFile(arm, kRealData / "kuka_iiwa" / variant);
    ExpectOnlyFileNames(loader.LastReport());
    // the link meshes collide as hulls; the loader says which are not convex, naming the link.
    // The base's <inertial> has mass 0 beside a collision mesh: its mass comes from the mesh,
    // and the loader says so.
    int massless = 0;
    for (const LoadWarning& w : loader.LastReport().warnings) {
      EXPECT_NE(w.message.find("link 'lbr_iiwa_link_"), std::string::npos) << w.message;
      if (w.message.find("link 'lbr_iiwa_link_0' <inertial> has mass 0") != std::string::npos)
        ++massless;
      else
        EXPECT_NE(w.message.find("not convex"), std::string::npos) << w.message;
    }
    EXPECT_LE(massless, 1);
  }
}

TEST(RealDataRobots, KukaVariantsWithMissingMeshesFailListingThemAll) {
  SKIP_WITHOUT_REALDATA("kuka_iiwa");
  // model_for_sdf.urdf names eight meshes/coarse/link_N.stl, none of which exists
  try {
    UrdfLoader().ParseFile((kRealData / "kuka_iiwa" / "model_for_sdf.urdf").string());
    ADD_FAILURE() << "no exception";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("model_for_sdf.urdf"), std::string::npos) << msg;
    EXPECT_NE(msg.find("8 files"), std::string::npos) << msg;
    for (int k = 0; k < 8; ++k) {
      const std::string n = std::to_string(k);
      EXPECT_NE(msg.find("link 'lbr_iiwa_link_" + n + "' <collision>"), std::string::npos) << msg;
      EXPECT_NE(msg.find("'meshes/coarse/link_" + n + ".stl' not found"), std::string::npos) << msg;
    }
  }
  // model_mobile.urdf names package://meshes/base_link.dae, an empty file
  try {
    UrdfLoader().ParseFile((kRealData / "kuka_iiwa" / "model_mobile.urdf").string());
    ADD_FAILURE() << "no exception";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("1 file"), std::string::npos) << msg;
    EXPECT_NE(msg.find("link 'base' <visual>"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'package://meshes/base_link.dae' is empty"), std::string::npos) << msg;
  }
}

TEST(RealDataRobots, KukaHeldByDrivesStaysAndReachesTargets) {
  SKIP_WITHOUT_REALDATA("kuka_iiwa");
  Scene scene;
  scene.AddGround(0.0);
  Articulation arm =
      CreateUrdfLoader(scene).Load((kRealData / "kuka_iiwa" / "model.urdf").string());
  Eigen::VectorXd home(7);
  home << 0.0, 0.5, 0.0, -1.2, 0.0, 0.8, 0.0;
  // at its home pose under gravity (the file's 300 N m effort limits stay as force limits)
  Held held = HoldWithDrives(scene, arm, home, home, 5000, 500, 1.0);
  EXPECT_LT(held.drift, 0.02);
  EXPECT_LT(held.final_error, 0.01);
  EXPECT_LT(arm.GetQvel().norm(), 1e-2);
  // to targets 0.2 rad away
  const Eigen::VectorXd target = home + Eigen::VectorXd::Constant(7, 0.2);
  held = HoldWithDrives(scene, arm, home, target, 5000, 500, 1.5);
  EXPECT_LT(held.final_error, 0.01);
  ::testing::Test::RecordProperty("kuka_final_error", testing::PrintToString(held.final_error));
}

TEST(RealDataRobots, ShadowHandHasADofPerMovingJointAndHoldsItsPose) {
  SKIP_WITHOUT_REALDATA("shadow_hand");
  Scene scene;
  UrdfLoader loader = CreateUrdfLoader(scene);
  const fs::path path = kRealData / "shadow_hand" / "shadow_hand.urdf";
  ArticulationDesc desc = loader.ParseFile(path.string());
  Articulation hand = scene.AddArticulation(desc);
  EXPECT_EQ(hand.Dof(), 24);
  ExpectJointsOfFile(hand, path);
  ExpectOnlyFileNames(loader.LastReport());
  // the palm's mesh is not convex (the loader says so): its hull reaches the proximal
  // phalanges, which it pushes away at the starting pose (q = 0 clamped into the limits)
  const Eigen::VectorXd q0 = hand.GetQpos();
  scene.Step(1);
  const size_t touching = scene.GetContacts().size();
  for (const Contact& c : scene.GetContacts()) {
    EXPECT_EQ(c.body0.kind, ContactBody::Kind::kLink);
    EXPECT_EQ(c.body1.kind, ContactBody::Kind::kLink);
    desc.disabled_collisions.emplace_back(c.body0.name, c.body1.name);
  }
  EXPECT_EQ(CountWarningsNaming(loader.LastReport(), "link 'palm'"), 1);
  Held pushed = HoldWithDrives(scene, hand, q0, q0, 20, 1, 0.5);
  // those pairs left out (as an SRDF would), the hand held by its drives stays still against
  // gravity (one recompile: MuJoCo takes a good part of a second over the hand's meshes)
  scene.RemoveArticulation(hand);
  hand = scene.AddArticulation(desc);
  Held held = HoldWithDrives(scene, hand, q0, q0, 20, 1, 1.0);
  EXPECT_LT(held.drift, 0.005);
  EXPECT_LT(held.drift, pushed.drift);
  ::testing::Test::RecordProperty("shadow_hand_self_contacts", static_cast<int>(touching));
  ::testing::Test::RecordProperty("shadow_hand_drift_pushed",
                                  ::testing::PrintToString(pushed.drift));
  ::testing::Test::RecordProperty("shadow_hand_drift", ::testing::PrintToString(held.drift));
}

TEST(RealDataRobots, AnymalLoadsWithBalancedInertiasNamedByLink) {
  SKIP_WITHOUT_REALDATA("anymal_c");
  Scene scene;
  UrdfLoader loader = CreateUrdfLoader(scene);
  const fs::path path = kRealData / "anymal_c" / "urdf" / "anymal_c.urdf";
  Articulation robot = loader.Load(path.string());
  EXPECT_EQ(robot.Dof(), 12);
  ExpectJointsOfFile(robot, path);
  const LoadReport& report = loader.LastReport();
  ExpectOnlyFileNames(report);
  // the inertias MuJoCo would refuse, repaired and named by their URDF links
  int balanced = 0, unlimited = 0;
  for (const LoadWarning& w : report.warnings) {
    EXPECT_EQ(w.file, "anymal_c.urdf");
    if (w.message.find("A + B >= C") != std::string::npos) {
      ++balanced;
      EXPECT_EQ(w.message.rfind("link '", 0), 0u) << w.message;
    }
    unlimited += w.message.find("left unlimited") != std::string::npos;
  }
  EXPECT_GE(balanced, 1) << report.ToString();
  EXPECT_EQ(unlimited, 12) << report.ToString();
  bool hatch = false;
  for (const LoadWarning& w : report.warnings)
    hatch = hatch || w.message.find("link 'hatch' <inertial>") != std::string::npos;
  EXPECT_TRUE(hatch) << report.ToString();
  // with strict loading the same file is an error naming the first such link
  UrdfLoader strict;
  strict.strict = true;
  EXPECT_THROW(strict.ParseFile(path.string()), Error);

  // its base fixed, legs straight, held by the drives (the file's 80 N m limits)
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(12);
  Held held = HoldWithDrives(scene, robot, q0, q0, 300, 10, 1.0);
  EXPECT_LT(held.drift, 0.02);
  // and driven to a crouch
  Eigen::VectorXd crouch(12);
  const std::vector<Joint> joints = robot.GetActiveJoints();
  for (size_t k = 0; k < joints.size(); ++k) {
    const std::string& n = joints[k].GetName();
    const bool front = n[1] == 'F';
    crouch[k] = n.find("HFE") != std::string::npos   ? (front ? 0.6 : -0.6)
                : n.find("KFE") != std::string::npos ? (front ? -1.0 : 1.0)
                                                     : 0.0;
  }
  held = HoldWithDrives(scene, robot, q0, crouch, 300, 10, 1.5);
  EXPECT_LT(held.final_error, 0.02);
}

}  // namespace
}  // namespace partsim
