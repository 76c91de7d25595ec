// A hand-written PartNet-Mobility folder laid out as the real dataset is (z-up root joint, y-up
// annotations, two label vocabularies), read, cross-checked and loaded; what the reader works
// around (warnings, errors when strict); each kind of bad folder; and the real object in
// ../shared/realdata.
#include "partsim/assets/partnet_mobility.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "assets/partnet_test_folder.h"
#include "partsim/core/log.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using testing::Folder;
using testing::Write;

// Warnings are what these tests check; keep the test log quiet.
class PartNetMobilityTest : public ::testing::Test {
 protected:
  void SetUp() override { SetLogLevel(LogLevel::kError); }
  void TearDown() override { SetLogLevel(LogLevel::kWarning); }
};

void ExpectErrorMentions(const std::string& folder, std::vector<std::string> words,
                         bool strict = false) {
  try {
    PartNetMobilityLoader loader;
    loader.strict = strict;
    loader.Parse(folder);
    FAIL() << "no error";
  } catch (const Error& e) {
    for (const std::string& w : words)
      EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what() << " lacks " << w;
  }
}

// The one warning of `report` that mentions every word; fails the test unless exactly one does.
void ExpectOneWarning(const LoadReport& report, std::vector<std::string> words) {
  int found = 0;
  for (const LoadWarning& w : report.warnings) {
    const std::string text = w.ToString();
    bool all = true;
    for (const std::string& word : words) all = all && text.find(word) != std::string::npos;
    found += all;
  }
  EXPECT_EQ(found, 1) << "warnings:\n" << report.ToString();
}

TEST_F(PartNetMobilityTest, ReadsBothVocabulariesJointsLimitsAndParts) {
  Folder f("good");
  PartNetMobilityLoader loader;
  PartNetMobilityObject obj = loader.Parse(f.Path());
  EXPECT_TRUE(obj.report.Empty()) << obj.report.ToString();
  EXPECT_TRUE(loader.LastReport().Empty());
  EXPECT_EQ(obj.category, "StorageFurniture");
  EXPECT_EQ(obj.model_id, "9001");
  EXPECT_EQ(obj.articulation.name, "StorageFurniture_9001");
  ASSERT_EQ(obj.links.size(), 3u);
  const LinkDesc& door = obj.articulation.links[obj.LinkIndex(0)];
  // semantics.txt's label and mobility_v2.json's PartNet name, both kept
  EXPECT_EQ(door.semantic_label, "rotation_door");
  EXPECT_EQ(door.partnet_name, "cabinet_door");
  EXPECT_EQ(obj.Link(0).semantic_joint, "hinge");
  EXPECT_EQ(door.joint.type, JointType::kRevolute);
  EXPECT_NEAR(door.joint.lower, -M_PI / 2, 1e-9);
  EXPECT_NEAR(door.joint.upper, 0.0, 1e-12);
  EXPECT_EQ(obj.articulation.links[obj.LinkIndex(1)].joint.type, JointType::kPrismatic);
  EXPECT_EQ(obj.articulation.links[obj.LinkIndex(2)].semantic_label, "furniture_body");
  EXPECT_EQ(obj.articulation.links[obj.LinkIndex(2)].partnet_name, "cabinet_frame");
  EXPECT_EQ(obj.Link(2).joint, "heavy");
  EXPECT_EQ(obj.LinksWithLabel("drawer"), std::vector<int>{1});
  EXPECT_EQ(PartNetMobilityObject::MotionJointType(obj.Link(0)), JointType::kRevolute);
  // the part-to-visual map: the handle of the door on link_0
  std::vector<int> handle = obj.PartVisuals(0, "handle");
  ASSERT_EQ(handle.size(), 1u);
  EXPECT_EQ(door.visuals[handle[0]].name, "handle-3");
  ASSERT_EQ(obj.Link(0).parts.size(), 2u);
  EXPECT_EQ(obj.Link(0).parts[1].visuals, handle);
  EXPECT_NEAR(obj.bbox_max.z(), 0.22, 1e-12);
  // the annotation frame: y-up meshes turned z-up at the root joint
  EXPECT_LT((obj.X_BF.q * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 1e-9);
}

TEST_F(PartNetMobilityTest, LoadsAsMobilityUrdfSaysWithTheFrontFacingMinusX) {
  Folder f("zup");
  Scene scene(SceneConfig{1.0 / 500, Eigen::Vector3d::Zero()});
  PartNetMobilityLoader loader(&scene);
  Articulation art = loader.Load(f.Path());
  EXPECT_EQ(art.Dof(), 2);
  // the meshes' vertical y axis is the world's z; their front (+z) is the world's -x
  Joint door = art.FindJointByName("joint_0");
  Joint drawer = art.FindJointByName("joint_1");
  EXPECT_LT((door.GetGlobalAxis() - Eigen::Vector3d::UnitZ()).norm(), 1e-9);
  EXPECT_LT((drawer.GetGlobalAxis() - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-9);
  // the hinge sits at mesh (-0.3, *, 0.21) -> world x = -0.21, y = 0.3
  Pose hinge = door.GetGlobalPose();
  EXPECT_NEAR(hinge.p.x(), -0.21, 1e-9);
  EXPECT_NEAR(hinge.p.y(), 0.3, 1e-9);
  door.SetDriveProperty(200, 20);
  door.SetDriveTarget(-1.0);
  drawer.SetDriveProperty(500, 50);
  drawer.SetDriveTarget(0.2);
  scene.Step(1000);
  EXPECT_NEAR(door.GetQpos(), -1.0, 0.02);
  EXPECT_NEAR(drawer.GetQpos(), 0.2, 0.01);
  Pose drawer_pose = art.GetLink(art.FindLinkByName("link_1").GetIndex()).GetPose();
  EXPECT_NEAR(drawer_pose.p.x(), -0.2, 0.01);  // slid out to the front (world -x)
}

TEST_F(PartNetMobilityTest, ScaledFolderPassesItsChecksWithScaledAxesAndSliderLimits) {
  Folder f("scaled");
  PartNetMobilityObject one = PartNetMobilityLoader().Parse(f.Path());
  PartNetMobilityLoader loader;
  loader.strict = true;     // any disagreement found would throw
  loader.urdf.scale = 2.0;  // checked against mobility_v2.json's unscaled axis origins
  PartNetMobilityObject two = loader.Parse(f.Path());
  const LinkDesc &door1 = one.articulation.links[one.LinkIndex(0)],
                 &door2 = two.articulation.links[two.LinkIndex(0)];
  EXPECT_LT((door2.joint.pose_in_parent.p - 2.0 * door1.joint.pose_in_parent.p).norm(), 1e-12);
  EXPECT_NEAR(door2.joint.lower, door1.joint.lower, 1e-12);  // angles do not scale
  const LinkDesc &drawer1 = one.articulation.links[one.LinkIndex(1)],
                 &drawer2 = two.articulation.links[two.LinkIndex(1)];
  EXPECT_NEAR(drawer2.joint.upper, 2.0 * drawer1.joint.upper, 1e-12);  // lengths do
  EXPECT_GT(drawer1.joint.upper, 0.0);
  EXPECT_NEAR(two.bbox_max.z(), 0.44, 1e-12);
}

TEST_F(PartNetMobilityTest, MissingFilesWarnAndStrictLoadingRefuses) {
  Folder f("missing");
  fs::remove(f.dir / "semantics.txt");
  fs::remove(f.dir / "bounding_box.json");
  PartNetMobilityLoader loader;
  PartNetMobilityObject obj = loader.Parse(f.Path());
  ExpectOneWarning(obj.report, {"semantics.txt", "missing"});
  ExpectOneWarning(obj.report, {"bounding_box.json", "missing"});
  EXPECT_EQ(loader.LastReport().warnings.size(), obj.report.warnings.size());
  // labels fall back to the PartNet names; bounds come from the meshes
  EXPECT_EQ(obj.articulation.links[obj.LinkIndex(0)].semantic_label, "cabinet_door");
  EXPECT_NEAR(obj.bbox_min.x(), -0.3, 1e-6);
  EXPECT_NEAR(obj.bbox_min.y(), -0.4, 1e-6);
  ExpectErrorMentions(f.Path(), {"semantics.txt", "missing"}, /*strict=*/true);

  Folder g("no_urdf");
  fs::remove(g.dir / "mobility.urdf");
  ExpectErrorMentions(g.Path(), {"mobility.urdf", "missing"});
}

TEST_F(PartNetMobilityTest, JsonThatDisagreesWithTheUrdfWarnsAndTheUrdfWins) {
  Folder f("limits");
  f.json.replace(f.json.find("\"a\": -90"), 8, "\"a\": -60");
  f.WriteAll();
  PartNetMobilityObject obj = PartNetMobilityLoader().Parse(f.Path());
  ExpectOneWarning(obj.report, {"mobility_v2.json", "link_0", "limits"});
  EXPECT_NEAR(obj.articulation.links[obj.LinkIndex(0)].joint.lower, -M_PI / 2, 1e-9);
  ExpectErrorMentions(f.Path(), {"mobility_v2.json", "link_0", "limits"}, true);

  Folder g("type");
  g.json.replace(g.json.find("\"joint\": \"slider\""), 17, "\"joint\": \"hinge\" ");
  g.semantics = "link_0 hinge rotation_door\nlink_1 hinge drawer\nlink_2 heavy furniture_body\n";
  g.WriteAll();
  ExpectOneWarning(PartNetMobilityLoader().Parse(g.Path()).report, {"link_1", "prismatic"});
  ExpectErrorMentions(g.Path(), {"link_1", "prismatic"}, true);

  Folder h("axis");
  h.json.replace(h.json.find("[0, 1, 0]"), 9, "[1, 0, 0]");
  h.WriteAll();
  ExpectOneWarning(PartNetMobilityLoader().Parse(h.Path()).report, {"link_0", "axis"});
  ExpectErrorMentions(h.Path(), {"link_0", "axis"}, true);

  // semantics.txt's kind must match the JSON's motion; its label may differ from the JSON name
  Folder s("semantics");
  s.semantics = "link_0 slider rotation_door\nlink_1 slider drawer\nlink_2 heavy furniture_body\n";
  s.WriteAll();
  ExpectOneWarning(PartNetMobilityLoader().Parse(s.Path()).report,
                   {"semantics.txt", "link_0", "'slider'", "'hinge'"});
  ExpectErrorMentions(s.Path(), {"semantics.txt", "link_0"}, true);

  Folder p("part");
  p.urdf.replace(p.urdf.find("handle-3"), 8, "handle-9");
  p.WriteAll();
  ExpectOneWarning(PartNetMobilityLoader().Parse(p.Path()).report,
                   {"mobility.urdf", "link_0", "'*-3'", "handle"});
}

TEST_F(PartNetMobilityTest, UnknownJointTypeIsNamed) {
  Folder f("unknown");
  f.json.replace(f.json.find("\"joint\": \"heavy\""), 16, "\"joint\": \"bolted\"");
  f.WriteAll();
  ExpectErrorMentions(f.Path(), {"mobility_v2.json", "link_2", "bolted"});
}

TEST_F(PartNetMobilityTest, BrokenFilesAreNamedAndTheBatchGoesOn) {
  Folder good("batch/a_good");
  Folder bad("batch/b_broken");
  Write(bad.dir / "textured_objs/original-2.obj", "v 0 0 0\nf 1 2 3\nthis is not an obj\n");
  ExpectErrorMentions(bad.Path(), {"original-2.obj"});
  Folder malformed("batch/c_malformed");
  Write(malformed.dir / "mobility_v2.json", "[{\"id\": 0,");
  Folder meta("batch/d_meta");
  Write(meta.dir / "meta.json", "{\"model_cat\": ");
  ExpectErrorMentions(meta.Path(), {"meta.json", "malformed JSON"});
  std::vector<PartNetBatchEntry> batch = ParsePartNetMobilityBatch(
      (fs::temp_directory_path() / "partsim_pm/batch").string(), PartNetMobilityLoader());
  ASSERT_EQ(batch.size(), 4u);
  EXPECT_TRUE(batch[0].ok) << batch[0].error;
  EXPECT_FALSE(batch[1].ok);
  EXPECT_NE(batch[1].error.find("original-2.obj"), std::string::npos) << batch[1].error;
  EXPECT_FALSE(batch[2].ok);
  EXPECT_NE(batch[2].error.find("mobility_v2.json: malformed JSON"), std::string::npos)
      << batch[2].error;
  EXPECT_FALSE(batch[3].ok);
}

// A subset of a dataset as a folder of symbolic links to object folders (and to a category
// folder of objects): every object is found, by the path through its link.
TEST_F(PartNetMobilityTest, DatasetSearchFollowsLinksToFolders) {
  const fs::path base = fs::temp_directory_path() / "partsim_pm/links";
  fs::remove_all(base);
  Folder a("links/data/a");
  Folder b("links/data/cat/b");
  Folder c("links/data/cat/c");
  const fs::path subset = base / "subset";
  fs::create_directories(subset / "plain");
  fs::create_directory_symlink(a.dir, subset / "link_a");
  fs::create_directory_symlink("../data/cat", subset / "link_cat");  // relative link
  Write(subset / "plain/readme.txt", "not an object");
  fs::create_symlink(subset / "plain/readme.txt", subset / "link_to_file");  // not followed
  const std::vector<std::string> found = FindPartNetMobilityFolders(subset.string());
  const std::vector<std::string> expected = {(subset / "link_a").string(),
                                             (subset / "link_cat/b").string(),
                                             (subset / "link_cat/c").string()};
  EXPECT_EQ(found, expected);
  // the batch reads them too
  std::vector<PartNetBatchEntry> batch =
      ParsePartNetMobilityBatch(subset.string(), PartNetMobilityLoader());
  ASSERT_EQ(batch.size(), 3u);
  for (const PartNetBatchEntry& e : batch) EXPECT_TRUE(e.ok) << e.folder << ": " << e.error;
}

// Links that would make the search go round forever are refused by the link's name: a link to a
// folder above it, and two links that lead to one another. A link to nothing is named too.
TEST_F(PartNetMobilityTest, DatasetSearchRefusesLinkLoopsByName) {
  const fs::path base = fs::temp_directory_path() / "partsim_pm/loops";
  fs::remove_all(base);
  Folder a("loops/up/a");
  fs::create_directories(base / "up/deeper");
  fs::create_directory_symlink("..", base / "up/deeper/to_parent");
  fs::create_directories(base / "pair");
  fs::create_symlink("second", base / "pair/first");
  fs::create_symlink("first", base / "pair/second");
  fs::create_directories(base / "above/inner");
  fs::create_directory_symlink("../..", base / "above/inner/to_above_the_root");
  fs::create_directories(base / "dangling");
  fs::create_symlink("no_such_folder", base / "dangling/gone");

  auto expect_refused = [](const fs::path& root, const fs::path& link) {
    try {
      FindPartNetMobilityFolders(root.string());
      ADD_FAILURE() << "no error for " << link;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(link.string()), std::string::npos) << e.what();
    }
  };
  expect_refused(base / "up", base / "up/deeper/to_parent");
  expect_refused(base / "above", base / "above/inner/to_above_the_root");
  expect_refused(base / "pair", base / "pair/first");  // the first in path order
  expect_refused(base / "dangling", base / "dangling/gone");

  // with a list for what cannot be searched, the rest is still found
  std::vector<UnreadableFolder> unreadable;
  const std::vector<std::string> found = FindPartNetMobilityFolders(base.string(), &unreadable);
  EXPECT_EQ(found, std::vector<std::string>{a.Path()});
  std::vector<std::string> named;
  for (const UnreadableFolder& u : unreadable) named.push_back(u.folder);
  std::sort(named.begin(), named.end());
  EXPECT_EQ(named, (std::vector<std::string>{
                       (base / "above/inner/to_above_the_root").string(),
                       (base / "dangling/gone").string(), (base / "pair/first").string(),
                       (base / "pair/second").string(), (base / "up/deeper/to_parent").string()}));
  for (const UnreadableFolder& u : unreadable)
    EXPECT_NE(u.reason.find(u.folder.find("gone") != std::string::npos ? "does not exist" : "loop"),
              std::string::npos)
        << u.folder << ": " << u.reason;
}

TEST_F(PartNetMobilityTest, BrokenFolderLeavesTheSceneUsable) {
  Folder bad("scene_survives");
  Write(bad.dir / "mobility_v2.json", "not json");
  Scene scene(SceneConfig{1.0 / 500, Eigen::Vector3d::Zero()});
  PartNetMobilityLoader loader(&scene);
  Folder good("scene_survives_good");
  Articulation art = loader.Load(good.Path());
  EXPECT_THROW(loader.Load(bad.Path()), Error);
  EXPECT_EQ(scene.GetArticulations().size(), 1u);
  art.FindJointByName("joint_1").SetDriveProperty(20000, 1500);  // a 30 kg drawer
  art.FindJointByName("joint_1").SetDriveTarget(0.1);
  scene.Step(500);
  EXPECT_NEAR(art.FindJointByName("joint_1").GetQpos(), 0.1, 0.01);
}

TEST_F(PartNetMobilityTest, MultipleCollisionsGiveOnePiecePerFile) {
  Folder f("pieces");
  // the door link gets a second collision file
  f.urdf.replace(f.urdf.find("</link>\n  <joint name=\"joint_0\""), 7,
                 "<collision><geometry><mesh filename=\"textured_objs/original-3.obj\"/>"
                 "</geometry></collision></link>");
  f.WriteAll();
  PartNetMobilityLoader loader;
  loader.urdf.load_multiple_collisions_from_file = true;
  PartNetMobilityObject obj = loader.Parse(f.Path());
  EXPECT_EQ(obj.articulation.links[obj.LinkIndex(0)].collisions.size(), 2u);
}

TEST_F(PartNetMobilityTest, PlaceOnGroundPutsTheLowestPoint10MicrometresAboveThePlane) {
  Folder f("ground");
  Scene scene;
  PartNetMobilityLoader loader(&scene);
  Articulation art = loader.Load(f.Path());
  PlaceOnGround(art, 0.25);
  // the body's back panel spans mesh y in [-0.4, 0.4]: world z in [0.25, 1.05], raised by the
  // clearance
  EXPECT_NEAR(art.GetRootPose().p.z(), 0.25 + 0.4 + 1e-5, 1e-7);
  EXPECT_NEAR(StandingRootPose(art, 0.25).p.z(), art.GetRootPose().p.z(), 1e-12);
}

// --- the real object in ../shared/realdata ------------------------------------------------------

fs::path RealObject() {
  return fs::path(PARTSIM_SOURCE_DIR) / ".." / "shared" / "realdata" / "partnet-mobility-3763";
}

TEST_F(PartNetMobilityTest, RealBottleLoadsWithBothVocabulariesAndItsScrewCap) {
  if (!fs::exists(RealObject() / "mobility.urdf")) GTEST_SKIP() << "no " << RealObject();
  PartNetMobilityLoader loader;
  PartNetMobilityObject obj = loader.Parse(RealObject().string());
  EXPECT_EQ(obj.category, "Bottle");
  ASSERT_EQ(obj.links.size(), 2u);
  EXPECT_EQ(obj.Link(0).semantic_label, "rotation_lid");
  EXPECT_EQ(obj.Link(0).semantic_joint, "slider+");
  EXPECT_EQ(obj.Link(0).partnet_name, "lid");
  EXPECT_TRUE(obj.Link(0).rotates);
  EXPECT_EQ(obj.Link(1).semantic_label, "bottle_body");
  EXPECT_EQ(obj.Link(1).partnet_name, "body");
  EXPECT_EQ(obj.Link(1).joint, "free");
  // the lid's helper carries its labels; parts map to their visuals
  const ArticulationDesc& art = obj.articulation;
  const int lid = obj.LinkIndex(0);
  EXPECT_EQ(art.links[art.links[lid].parent].name, "link_0_helper");
  EXPECT_EQ(art.links[art.links[lid].parent].semantic_label, "rotation_lid");
  ASSERT_EQ(obj.Link(1).parts.size(), 2u);
  for (const PartNetPart& p : obj.Link(1).parts) EXPECT_EQ(p.visuals.size(), 1u) << p.name;
  // mobility.urdf turns the cap continuously; mobility_v2.json says 180 degrees: mobility.urdf
  // wins, with a warning, and strict loading refuses
  ExpectOneWarning(obj.report, {"mobility_v2.json", "link_0", "continuous"});
  EXPECT_EQ(art.links[lid].joint.type, JointType::kContinuous);
  ExpectErrorMentions(RealObject().string(), {"link_0"}, /*strict=*/true);
  // bounds from bounding_box.json, y-up: the bottle is tall along y
  EXPECT_GT(obj.bbox_max.y() - obj.bbox_min.y(), obj.bbox_max.x() - obj.bbox_min.x());
}

TEST_F(PartNetMobilityTest, RealBottleStandsOnTheGroundAndItsCapReachesDriveTargets) {
  if (!fs::exists(RealObject() / "mobility.urdf")) GTEST_SKIP() << "no " << RealObject();
  Scene scene(SceneConfig{1.0 / 500});
  scene.AddGround(0.0);
  PartNetMobilityLoader loader(&scene);
  loader.urdf.fix_root_link = false;
  Articulation bottle = loader.Load(RealObject().string());
  ASSERT_EQ(bottle.Dof(), 2);  // the cap's slide and turn
  // z-up: the cap sits above the body
  const Pose body = bottle.FindLinkByName("link_1").GetPose();
  const Pose cap = bottle.FindLinkByName("link_0").GetPose();
  EXPECT_GT(cap.p.z() + 0.3, body.p.z());
  PlaceOnGround(bottle, 0.0);
  Joint slide = bottle.FindJointByName("joint_2");
  Joint turn = bottle.FindJointByName("joint_0");
  Eigen::Vector2d lim = slide.GetLimits();
  EXPECT_NEAR(lim[0], -0.108, 1e-9);
  EXPECT_NEAR(lim[1], -0.008, 1e-9);
  // the dataset's units make this bottle 1.85 m tall: its cap weighs about 10 kg
  slide.SetDriveProperty(1e5, 3000);
  slide.SetDriveTarget(-0.05);
  turn.SetDriveProperty(50, 5);
  turn.SetDriveTarget(1.0);
  const Pose start = bottle.GetRootPose();
  scene.Step(1000);
  EXPECT_NEAR(slide.GetQpos(), -0.05, 0.005);
  EXPECT_NEAR(turn.GetQpos(), 1.0, 0.05);
  // standing upright, it stays where it was put
  const Pose end = bottle.GetRootPose();
  EXPECT_LT((end.p - start.p).norm(), 0.02);
  EXPECT_LT(end.q.angularDistance(start.q), 0.05);
}

}  // namespace
}  // namespace partsim
