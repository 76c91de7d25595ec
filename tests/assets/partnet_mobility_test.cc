// A hand-written PartNet-Mobility folder (y-up file frame, a hinge with a negative limit, a
// slider, a body), read, cross-checked and loaded; and each kind of bad folder.
#include "partsim/assets/partnet_mobility.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "assets/partnet_test_folder.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using testing::Folder;
using testing::Write;

void ExpectErrorMentions(const std::string& folder, std::vector<std::string> words) {
  try {
    PartNetMobilityLoader().Parse(folder);
    FAIL() << "no error";
  } catch (const Error& e) {
    for (const std::string& w : words)
      EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what() << " lacks " << w;
  }
}

TEST(PartNetMobilityTest, ReadsLabelsJointsLimitsAndParts) {
  Folder f("good");
  PartNetMobilityObject obj = PartNetMobilityLoader().Parse(f.Path());
  EXPECT_EQ(obj.category, "StorageFurniture");
  EXPECT_EQ(obj.model_id, "9001");
  EXPECT_EQ(obj.articulation.name, "StorageFurniture_9001");
  ASSERT_EQ(obj.links.size(), 3u);
  const LinkDesc& door = obj.articulation.links[obj.LinkIndex(0)];
  EXPECT_EQ(door.semantic_label, "rotation_door");
  EXPECT_EQ(door.joint.type, JointType::kRevolute);
  EXPECT_NEAR(door.joint.lower, -M_PI / 2, 1e-9);
  EXPECT_NEAR(door.joint.upper, 0.0, 1e-12);
  EXPECT_EQ(obj.articulation.links[obj.LinkIndex(1)].joint.type, JointType::kPrismatic);
  EXPECT_EQ(obj.articulation.links[obj.LinkIndex(2)].semantic_label, "cabinet_body");
  EXPECT_EQ(obj.Link(2).joint, "heavy");
  EXPECT_EQ(PartNetMobilityObject::MotionJointType(obj.Link(0)), JointType::kRevolute);
  // the handle of the door on link_0
  std::vector<int> handle = obj.PartVisuals(0, "handle");
  ASSERT_EQ(handle.size(), 1u);
  EXPECT_EQ(door.visuals[handle[0]].name, "handle-3");
  EXPECT_NEAR(obj.bbox_max.z(), 0.22, 1e-12);
}

TEST(PartNetMobilityTest, LoadsZUpWithTheFilesAxes) {
  Folder f("zup");
  Scene scene(SceneConfig{1.0 / 500, Eigen::Vector3d::Zero()});
  PartNetMobilityLoader loader(&scene);
  Articulation art = loader.Load(f.Path());
  EXPECT_EQ(art.Dof(), 2);
  // the file's vertical y axis is the world's z; its front (+z) is the world's -y
  Joint door = art.FindJointByName("joint_0");
  Joint drawer = art.FindJointByName("joint_1");
  EXPECT_LT((door.GetGlobalAxis() - Eigen::Vector3d::UnitZ()).norm(), 1e-9);
  EXPECT_LT((drawer.GetGlobalAxis() - Eigen::Vector3d(0, -1, 0)).norm(), 1e-9);
  // the hinge sits at file (-0.3, *, 0.21) -> world x = -0.3, y = -0.21
  Pose hinge = door.GetGlobalPose();
  EXPECT_NEAR(hinge.p.x(), -0.3, 1e-9);
  EXPECT_NEAR(hinge.p.y(), -0.21, 1e-9);
  // the door opens to negative angles: driven to -1 it swings its free edge towards +y... and
  // stays within its limits
  door.SetDriveProperty(200, 20);
  door.SetDriveTarget(-1.0);
  drawer.SetDriveProperty(500, 50);
  drawer.SetDriveTarget(0.2);
  scene.Step(1000);
  EXPECT_NEAR(door.GetQpos(), -1.0, 0.02);
  EXPECT_NEAR(drawer.GetQpos(), 0.2, 0.01);
  Pose drawer_pose = art.GetLink(art.FindLinkByName("link_1").GetIndex()).GetPose();
  EXPECT_NEAR(drawer_pose.p.y(), -0.2, 0.01);  // slid out to the front (world -y)
}

TEST(PartNetMobilityTest, ScaledFolderPassesItsChecksWithScaledAxesAndSliderLimits) {
  Folder f("scaled");
  PartNetMobilityObject one = PartNetMobilityLoader().Parse(f.Path());
  PartNetMobilityLoader loader;
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
}

TEST(PartNetMobilityTest, MissingFileIsNamed) {
  Folder f("missing");
  fs::remove(f.dir / "semantics.txt");
  ExpectErrorMentions(f.Path(), {"semantics.txt", "missing"});
}

TEST(PartNetMobilityTest, JsonThatDisagreesWithTheUrdfIsNamed) {
  Folder f("limits");
  f.json.replace(f.json.find("\"a\": -90"), 8, "\"a\": -60");
  f.WriteAll();
  ExpectErrorMentions(f.Path(), {"mobility.urdf", "link_0", "limits"});

  Folder g("type");
  g.json.replace(g.json.find("\"joint\": \"slider\""), 17, "\"joint\": \"hinge\" ");
  g.semantics = "link_0 hinge rotation_door\nlink_1 hinge drawer\nlink_2 heavy cabinet_body\n";
  g.WriteAll();
  ExpectErrorMentions(g.Path(), {"link_1", "prismatic"});

  Folder h("axis");
  h.json.replace(h.json.find("[0, 1, 0]"), 9, "[1, 0, 0]");
  h.WriteAll();
  ExpectErrorMentions(h.Path(), {"link_0", "axis"});

  Folder s("semantics");
  s.semantics = "link_0 hinge door\nlink_1 slider drawer\nlink_2 heavy cabinet_body\n";
  s.WriteAll();
  ExpectErrorMentions(s.Path(), {"semantics.txt", "link_0", "rotation_door"});
}

TEST(PartNetMobilityTest, UnknownJointTypeIsNamed) {
  Folder f("unknown");
  f.json.replace(f.json.find("\"joint\": \"heavy\""), 16, "\"joint\": \"bolted\"");
  f.WriteAll();
  ExpectErrorMentions(f.Path(), {"mobility_v2.json", "link_2", "bolted"});
}

TEST(PartNetMobilityTest, BrokenObjIsNamedAndTheBatchGoesOn) {
  Folder good("batch/a_good");
  Folder bad("batch/b_broken");
  Write(bad.dir / "textured_objs/original-2.obj", "v 0 0 0\nf 1 2 3\nthis is not an obj\n");
  ExpectErrorMentions(bad.Path(), {"original-2.obj"});
  Folder malformed("batch/c_malformed");
  Write(malformed.dir / "mobility_v2.json", "[{\"id\": 0,");
  std::vector<PartNetBatchEntry> batch = ParsePartNetMobilityBatch(
      (fs::temp_directory_path() / "partsim_pm/batch").string(), PartNetMobilityLoader());
  ASSERT_EQ(batch.size(), 3u);
  EXPECT_TRUE(batch[0].ok) << batch[0].error;
  EXPECT_FALSE(batch[1].ok);
  EXPECT_NE(batch[1].error.find("original-2.obj"), std::string::npos) << batch[1].error;
  EXPECT_FALSE(batch[2].ok);
  EXPECT_NE(batch[2].error.find("malformed JSON"), std::string::npos) << batch[2].error;
}

TEST(PartNetMobilityTest, MultipleCollisionsGiveOnePiecePerFile) {
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

}  // namespace
}  // namespace partsim
