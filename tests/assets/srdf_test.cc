#include "partsim/assets/srdf.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "partsim/assets/urdf.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

// A fresh, empty folder for one test.
fs::path TempFolder(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("partsim_srdf_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void Write(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

std::string LinkXml(const std::string& name, const std::string& size, const std::string& xyz) {
  return "<link name=\"" + name + "\"><collision><origin xyz=\"" + xyz +
         "\"/><geometry><box size=\"" + size +
         "\"/></geometry></collision><inertial><mass value=\"1\"/><inertia ixx=\"0.01\" "
         "iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n";
}

std::string JointXml(const std::string& name, const std::string& type, const std::string& parent,
                     const std::string& child, const std::string& xyz) {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent +
         "\"/><child link=\"" + child + "\"/><origin xyz=\"" + xyz +
         "\"/><axis xyz=\"0 1 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"100\" "
         "velocity=\"1\"/></joint>\n";
}

// A Panda-like arm folded so that its hand reaches back into link1, as a real Panda's hand
// overlaps its link 5 at the zero pose: base, link1, link2, link3 on revolute joints about y,
// then link8 and the hand on fixed joints. The hand's box overlaps link1's by 1 cm, and two
// moving joints (j2, j3) separate them, so only an SRDF (or disable_collision) keeps them apart.
const std::string kArm =
    "<?xml version=\"1.0\"?>\n<robot name=\"arm\">\n" + LinkXml("base", "0.2 0.2 0.1", "0 0 0") +
    LinkXml("link1", "0.06 0.06 0.2", "0 0 0.1") + LinkXml("link2", "0.04 0.04 0.1", "0 0 0.05") +
    LinkXml("link3", "0.04 0.04 0.04", "0 0 0.02") + "<link name=\"link8\"/>\n" +
    LinkXml("hand", "0.06 0.06 0.06", "0.05 0 -0.2") +
    JointXml("j1", "revolute", "base", "link1", "0 0 0.1") +
    JointXml("j2", "revolute", "link1", "link2", "0 0 0.2") +
    JointXml("j3", "revolute", "link2", "link3", "0 0 0.1") +
    JointXml("j8", "fixed", "link3", "link8", "0 0 0.05") +
    JointXml("hand_joint", "fixed", "link8", "hand", "0 0 0") + "</robot>\n";

std::string Srdf(const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<robot name=\"arm\">\n" + body + "</robot>\n";
}

const std::string kHandLink1 = Srdf(
    "  <group name=\"arm\"><chain base_link=\"base\" tip_link=\"hand\"/></group>\n"
    "  <disable_collisions link1=\"hand\" link2=\"link1\" reason=\"Never\"/>\n");

// Loads an arm file (with `srdf_file`) into a weightless scene, drives it at 0 and returns the
// largest |q| over 1 s.
double Drift(const std::string& path, const std::string& srdf_file = "") {
  SceneConfig config;
  config.gravity.setZero();
  Scene scene(config);
  UrdfLoader loader(&scene);
  loader.srdf_file = srdf_file;
  Articulation arm = loader.Load(path);
  for (Joint j : arm.GetActiveJoints()) j.SetDriveProperty(200, 20);
  double drift = 0;
  for (int i = 0; i < 500; ++i) {
    scene.Step();
    drift = std::max(drift, arm.GetQpos().cwiseAbs().maxCoeff());
  }
  return drift;
}

TEST(SrdfTest, ReadsDisabledCollisionPairs) {
  LoadReport report;
  SrdfDesc srdf =
      ParseSrdf(Srdf("  <disable_collisions link1=\"a\" link2=\"b\" reason=\"Adjacent\"/>\n"
                     "  <virtual_joint name=\"v\" type=\"fixed\" parent_frame=\"w\" "
                     "child_link=\"a\"/>\n"
                     "  <disable_collisions link1=\"a\"/>\n"
                     "  <disable_collisions link1=\"b\" link2=\"c\"/>\n"),
                "arm.srdf", &report);
  EXPECT_EQ(srdf.robot_name, "arm");
  ASSERT_EQ(srdf.disabled_collisions.size(), 2u);
  EXPECT_EQ(srdf.disabled_collisions[0].link1, "a");
  EXPECT_EQ(srdf.disabled_collisions[0].link2, "b");
  EXPECT_EQ(srdf.disabled_collisions[0].reason, "Adjacent");
  EXPECT_EQ(srdf.disabled_collisions[0].line, 3);
  EXPECT_EQ(srdf.disabled_collisions[1].link2, "c");
  EXPECT_EQ(srdf.disabled_collisions[1].reason, "");
  // the entry without link2 is skipped with a warning naming its line
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(report.warnings[0].file, "arm.srdf");
  EXPECT_NE(report.warnings[0].message.find("line 5"), std::string::npos);
}

TEST(SrdfTest, MalformedXmlNamesTheFileAndLine) {
  try {
    ParseSrdf("<?xml version=\"1.0\"?>\n<robot name=\"arm\">\n  <disable_collisions link1=\"a\n",
              "bad.srdf", nullptr);
    FAIL() << "no error";
  } catch (const Error& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("SRDF bad.srdf"), std::string::npos) << what;
    EXPECT_NE(what.find("line 3"), std::string::npos) << what;
  }
  EXPECT_THROW(ParseSrdf("<srdf/>", "x.srdf", nullptr), Error);
  EXPECT_THROW(ReadSrdfFile("/nonexistent/arm.srdf", nullptr), Error);
}

TEST(SrdfTest, SrdfBesideTheUrdfKeepsTheHandOffLink1) {
  fs::path with = TempFolder("beside"), without = TempFolder("none");
  Write(with / "arm.urdf", kArm);
  Write(with / "arm.srdf", kHandLink1);
  Write(without / "arm.urdf", kArm);

  UrdfLoader loader;
  ArticulationDesc desc = loader.ParseFile((with / "arm.urdf").string());
  ASSERT_EQ(desc.disabled_collisions.size(), 1u);
  EXPECT_EQ(desc.disabled_collisions[0], std::make_pair(std::string("hand"), std::string("link1")));
  EXPECT_TRUE(loader.LastReport().Empty());
  EXPECT_TRUE(loader.ParseFile((without / "arm.urdf").string()).disabled_collisions.empty());

  // the arm holds still with the SRDF; without it the hand pushes off link1
  EXPECT_LT(Drift((with / "arm.urdf").string()), 1e-6);
  EXPECT_GT(Drift((without / "arm.urdf").string()), 0.01);
}

TEST(SrdfTest, PandaLikeArmHoldsItsZeroPoseWithItsSrdf) {
  // the test arm's hand and link 7 overlap link 5 at the zero pose, two moving joints away: held
  // by drives and gravity compensation, it is pushed off unless an SRDF disables the pairs
  const std::string arm =
      std::string(PARTSIM_TEST_DATA_DIR) + "/arm/arm_description/urdf/panda.urdf";
  fs::path dir = TempFolder("panda");
  Write(
      dir / "panda.srdf",
      Srdf(
          "  <disable_collisions link1=\"panda_link5\" link2=\"panda_link7\" reason=\"Default\"/>\n"
          "  <disable_collisions link1=\"panda_hand\" link2=\"panda_link5\" "
          "reason=\"Default\"/>\n"));
  auto drift = [&](const std::string& srdf_file) {
    Scene scene;
    UrdfLoader loader(&scene);
    loader.srdf_file = srdf_file;
    Articulation panda = loader.Load(arm);
    Eigen::VectorXd q0 = panda.GetQpos();  // 0 clamped into the limits
    for (Joint j : panda.GetActiveJoints()) j.SetDriveProperty(2000, 200);
    panda.SetDriveTarget(q0);
    double out = 0;
    for (int i = 0; i < 1000; ++i) {
      panda.SetQf(panda.ComputePassiveForce());
      scene.Step();
      out = std::max(out, (panda.GetQpos() - q0).cwiseAbs().maxCoeff());
    }
    return out;
  };
  EXPECT_LT(drift((dir / "panda.srdf").string()), 1e-3);
  EXPECT_GT(drift(""), 0.05);
}

TEST(SrdfTest, SrdfByPathAppliesToFilesAndStrings) {
  fs::path dir = TempFolder("by_path");
  Write(dir / "arm.urdf", kArm);
  Write(dir / "arm.srdf", Srdf(""));  // the named file wins over the one beside
  Write(dir / "moveit.srdf", kHandLink1);
  UrdfLoader loader;
  loader.srdf_file = (dir / "moveit.srdf").string();
  EXPECT_EQ(loader.ParseFile((dir / "arm.urdf").string()).disabled_collisions.size(), 1u);
  EXPECT_EQ(loader.Parse(kArm, dir.string()).disabled_collisions.size(), 1u);
  EXPECT_LT(Drift((dir / "arm.urdf").string(), loader.srdf_file), 1e-6);

  loader.srdf_file = (dir / "missing.srdf").string();
  EXPECT_THROW(loader.Parse(kArm, dir.string()), Error);
}

TEST(SrdfTest, PairNamingALinkTheUrdfLacksIsAWarning) {
  fs::path dir = TempFolder("unknown");
  Write(dir / "arm.urdf", kArm);
  Write(dir / "arm.srdf", Srdf("  <disable_collisions link1=\"hand\" link2=\"link9\"/>\n"
                               "  <disable_collisions link1=\"hand\" link2=\"link1\"/>\n"));
  UrdfLoader loader;
  ArticulationDesc desc = loader.ParseFile((dir / "arm.urdf").string());
  EXPECT_EQ(desc.disabled_collisions.size(), 1u);  // the known pair still applies
  ASSERT_EQ(loader.LastReport().warnings.size(), 1u);
  const LoadWarning& w = loader.LastReport().warnings[0];
  EXPECT_NE(w.file.find("arm.srdf"), std::string::npos);
  EXPECT_NE(w.message.find("'link9'"), std::string::npos) << w.message;
  EXPECT_NE(w.message.find("line 3"), std::string::npos) << w.message;

  loader.strict = true;
  EXPECT_THROW(loader.ParseFile((dir / "arm.urdf").string()), Error);
}

}  // namespace
}  // namespace partsim
