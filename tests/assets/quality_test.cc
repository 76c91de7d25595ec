#include "partsim/assets/quality.h"

#include <gtest/gtest.h>

#include "assets/partnet_test_folder.h"
#include "partsim/assets/generator.h"
#include "partsim/core/error.h"
#include "partsim/render/visibility.h"

namespace partsim {
namespace {

using testing::BoxObj;
using testing::Folder;
using testing::Write;
namespace fs = std::filesystem;

// CheckPartNetObject with the render layer's visibility check, as the command line runs it
ObjectQualityReport Check(const std::string& folder, QualityOptions o = QualityOptions()) {
  o.hidden_parts = HiddenMovingLinksFinder(o.render_backend, o.image_size);
  return CheckPartNetObject(folder, o);
}

const QualityCheck* Find(const ObjectQualityReport& r, const std::string& name) {
  for (const QualityCheck& c : r.checks)
    if (c.name == name) return &c;
  return nullptr;
}

TEST(QualityTest, AGoodObjectPassesEveryCheck) {
  Folder f("quality_good");
  ObjectQualityReport r = Check(f.Path());
  EXPECT_TRUE(r.Passed()) << r.ToString();
  EXPECT_EQ(r.category, "StorageFurniture");
  EXPECT_EQ(r.movable_parts, 2);
  for (const char* name : {"labels", "load", "rest", "range", "visible"})
    EXPECT_NE(Find(r, name), nullptr) << name;
}

TEST(QualityTest, APartThatJamsFailsTheRangeCheck) {
  Folder f("quality_jam");
  // a collision-only stop on the door, 0.1 m into the drawer's 0.3 m travel (nothing rigidly
  // attached to the drawer's parent, the body, collides with it: links joined by a joint do not
  // collide). The door's axis points down, so that the drawer pushes it into its limit.
  f.urdf.replace(f.urdf.find("<axis xyz=\"0 1 0\"/>"), 19, "<axis xyz=\"0 -1 0\"/>");
  f.json.replace(f.json.find("\"direction\": [0, 1, 0]"), 22, "\"direction\": [0, -1, 0]");
  f.urdf.replace(f.urdf.find("</link>\n  <joint name=\"joint_0\""), 7,
                 "<collision><geometry><mesh filename=\"textured_objs/original-5.obj\"/>"
                 "</geometry></collision></link>");
  f.WriteAll();
  // in the door's frame, at the hinge: body (0, -0.2, 0.27) is (0.3, -0.4, 0.06)
  Write(f.dir / "textured_objs/original-5.obj", BoxObj({0.3, -0.4, 0.06}, {0.2, 0.05, 0.02}));
  ObjectQualityReport r = Check(f.Path());
  EXPECT_FALSE(r.Passed());
  const QualityCheck* range = Find(r, "range");
  ASSERT_NE(range, nullptr);
  EXPECT_FALSE(range->passed);
  EXPECT_NE(range->detail.find("joint_1"), std::string::npos) << range->detail;
  EXPECT_TRUE(Find(r, "rest")->passed) << r.ToString();
}

TEST(QualityTest, AHiddenPartFailsTheVisibilityCheck) {
  Folder f("quality_hidden");
  // the drawer shrinks to a sliver inside a closed box around the whole object
  f.urdf.replace(f.urdf.find("<link name=\"link_2\">") + 20, 0,
                 "\n    <visual name=\"shell-9\"><geometry><mesh "
                 "filename=\"textured_objs/original-6.obj\"/></geometry></visual>");
  f.json.replace(f.json.find("{\"id\": 1, \"name\": \"body\""), 0,
                 "{\"id\": 9, \"name\": \"shell\", \"children\": []}, ");
  f.WriteAll();
  // a shell: six thin boxes would be exact; one closed box (outward faces) hides what is inside
  Write(f.dir / "textured_objs/original-6.obj", BoxObj({0, 0, 0.1}, {0.7, 0.8, 0.7}));
  QualityOptions o;
  o.image_size = 48;
  ObjectQualityReport r = Check(f.Path(), o);
  const QualityCheck* visible = Find(r, "visible");
  ASSERT_NE(visible, nullptr) << r.ToString();
  EXPECT_FALSE(visible->passed) << r.ToString();
}

TEST(QualityTest, AStiffHingeThatAStrongerDriveOpensPassesWithTheForceItNeeded) {
  Folder f("quality_stiff");
  // dry friction the gentle drive's stiffness cannot beat near the end of the range, which a
  // plain PD opens and closes: not a jammed part
  f.urdf.replace(f.urdf.find("<limit lower=\"-1.5707963267948966\""), 0,
                 "<dynamics friction=\"3\"/>");
  f.WriteAll();
  ObjectQualityReport r = Check(f.Path());
  const QualityCheck* range = Find(r, "range");
  ASSERT_NE(range, nullptr) << r.ToString();
  EXPECT_TRUE(range->passed) << r.ToString();
  EXPECT_NE(range->detail.find("'joint_0' needed"), std::string::npos) << range->detail;
  EXPECT_NE(range->detail.find("N m"), std::string::npos) << range->detail;
}

TEST(QualityTest, AnInconsistentFolderFailsTheLabelsCheckWithTheReason) {
  Folder f("quality_bad");
  f.semantics = "link_0 slider rotation_door\nlink_1 slider drawer\nlink_2 heavy furniture_body\n";
  f.WriteAll();
  ObjectQualityReport r = Check(f.Path());
  EXPECT_FALSE(r.Passed());
  const QualityCheck* labels = Find(r, "labels");
  ASSERT_NE(labels, nullptr) << r.ToString();
  EXPECT_FALSE(labels->passed);
  EXPECT_NE(labels->detail.find("semantics.txt"), std::string::npos) << labels->detail;
  EXPECT_NE(labels->detail.find("link_0"), std::string::npos) << labels->detail;
  // the physics checks still ran
  ASSERT_NE(Find(r, "range"), nullptr);
  EXPECT_TRUE(Find(r, "range")->passed) << r.ToString();
  // a folder that cannot be read fails to load, with the reason
  Folder g("quality_unreadable");
  Write(g.dir / "mobility_v2.json", "[");
  r = Check(g.Path());
  ASSERT_FALSE(r.checks.empty());
  EXPECT_EQ(r.checks[0].name, "load");
  EXPECT_NE(r.checks[0].detail.find("mobility_v2.json"), std::string::npos);
}

TEST(QualityTest, AGeneratedObjectOfEveryCategoryPassesEveryCheck) {
  fs::path root = fs::temp_directory_path() / "partsim_quality_generated";
  fs::remove_all(root);
  DatasetStatistics stats;
  std::vector<std::string> failures;
  for (const std::string& category : GeneratorCategories()) {
    fs::path dir = root / category;
    WriteObject(GenerateObject(category, 0, 2026), dir.string());
    ObjectQualityReport r = Check(dir.string());
    EXPECT_EQ(r.category, category);
    if (!r.Passed()) failures.push_back(r.ToString());
    stats.Add(r.category, r.movable_parts);
  }
  EXPECT_TRUE(failures.empty()) << failures.size() << " failed, e.g.\n" << failures[0];
  EXPECT_EQ(stats.per_category.size(), 46u);
  EXPECT_GT(stats.parts, 46);
  fs::remove_all(root);
}

TEST(QualityTest, StatisticsTableMatchesThePapersTotals) {
  int models = 0, parts = 0;
  for (const auto& [cat, mp] : PaperStatistics()) {
    models += mp.first;
    parts += mp.second;
  }
  EXPECT_EQ(PaperStatistics().size(), 46u);
  EXPECT_EQ(models, 2346);
  EXPECT_EQ(parts, 14068);
  DatasetStatistics stats;
  stats.Add("Door", 3);
  stats.Add("Door", 2);
  stats.Add("Faucet", 2);
  EXPECT_EQ(stats.models, 3);
  EXPECT_EQ(stats.parts, 7);
  std::string table = stats.ToTable();
  EXPECT_NE(table.find("Door"), std::string::npos);
  EXPECT_NE(table.find("2346"), std::string::npos);
}

}  // namespace
}  // namespace partsim

namespace partsim {
namespace {

// The assets layer does not render: without a finder the visibility check is refused, and with
// check_visibility off the other checks run without one.
TEST(QualityTest, TheVisibilityCheckNeedsTheRenderLayersFinder) {
  Folder f("quality_no_finder");
  f.WriteAll();
  QualityOptions o;
  try {
    CheckPartNetObject(f.Path(), o);
    FAIL() << "a visibility check without a finder was run";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("hidden_parts"), std::string::npos) << e.what();
  }
  o.check_visibility = false;
  ObjectQualityReport r = CheckPartNetObject(f.Path(), o);
  EXPECT_TRUE(r.Passed()) << r.ToString();
  EXPECT_EQ(Find(r, "visible"), nullptr);
}

}  // namespace
}  // namespace partsim
