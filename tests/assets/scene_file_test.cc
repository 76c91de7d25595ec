// Scene files and AddSceneObjects: a lone URDF, a generated PartNet-Mobility folder and a JSON
// scene of several objects land at their poses; each kind of bad input throws an error naming
// the file, the entry and the field, and leaves the scene as it was.
#include "partsim/assets/scene_file.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "partsim/assets/generator.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("partsim_scene_file_test_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

void WriteFile(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

// A two-link URDF named `robot`: a 20 cm box base and a lid on a revolute joint.
std::string TwoLinkUrdf(const std::string& robot) {
  return R"(<?xml version="1.0"?>
<robot name=")" +
         robot + R"(">
  <link name="base">
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="lid">
    <collision><origin xyz="0 0.1 0"/><geometry><box size="0.2 0.2 0.02"/></geometry></collision>
    <inertial><mass value="0.2"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="hinge" type="revolute">
    <origin xyz="0 -0.1 0.11"/><axis xyz="1 0 0"/><parent link="base"/><child link="lid"/>
    <limit lower="0" upper="1.5" effort="10" velocity="1"/>
  </joint>
</robot>
)";
}

// A number as JSON text, exactly.
std::string Json(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

// A generated PartNet-Mobility cabinet written under `dir`; returns its articulation name.
std::string WriteCabinet(const fs::path& dir) {
  GeneratedObject object = GenerateObject("StorageFurniture", 0, 7);
  WriteObject(object, dir.string());
  return object.category + "_" + object.model_id;
}

// Same rotation (q and -q alike) and position, to `tol`.
void ExpectPose(const Pose& actual, const Pose& expected, double tol = 1e-9) {
  EXPECT_LT((actual.p - expected.p).norm(), tol) << actual.ToString();
  EXPECT_LT((actual.q.toRotationMatrix() - expected.q.toRotationMatrix()).norm(), tol)
      << actual.ToString() << " vs " << expected.ToString();
  EXPECT_NEAR(std::abs(actual.q.dot(expected.q)), 1.0, tol);
}

// Runs `f`, which must throw partsim::Error whose message holds every word.
void ExpectError(const std::function<void()>& f, const std::vector<std::string>& words) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one mentioning " << words.front();
  } catch (const Error& e) {
    for (const std::string& w : words)
      EXPECT_NE(std::string(e.what()).find(w), std::string::npos)
          << "'" << e.what() << "' lacks '" << w << "'";
  }
}

class SceneFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = TempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    urdf_ = (dir_ / "lid_box.urdf").string();
    WriteFile(urdf_, TwoLinkUrdf("lid_box"));
    scene_.AddGround(0.0);
  }

  // Writes a scene file into the test's folder and returns its path.
  std::string WriteScene(const std::string& name, const std::string& text) {
    std::string p = (dir_ / name).string();
    WriteFile(p, text);
    return p;
  }

  fs::path dir_;
  std::string urdf_;
  Scene scene_;
};

TEST_F(SceneFileTest, LoadsALoneUrdfAtTheDefaultPose) {
  const Pose X_WO(Eigen::Vector3d(0.5, -1.0, 0.2),
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ())));
  std::vector<Articulation> arts = AddSceneObjects(&scene_, urdf_, X_WO);
  ASSERT_EQ(arts.size(), 1u);
  EXPECT_EQ(arts[0].GetName(), "lid_box");
  EXPECT_TRUE(arts[0].HasFixedRoot());
  EXPECT_EQ(arts[0].Dof(), 1);
  ExpectPose(arts[0].GetRootPose(), X_WO);
  // the root link sits at the pose, and stays there when fixed
  ExpectPose(arts[0].GetLink(0).GetPose(), X_WO);
  scene_.Step(50);
  ExpectPose(arts[0].GetRootPose(), X_WO);

  // the same file again, free: a second, unique name
  const Pose up(Eigen::Vector3d(2, 0, 1));
  std::vector<Articulation> more = AddSceneObjects(&scene_, urdf_, up, /*fix_root=*/false);
  ASSERT_EQ(more.size(), 1u);
  EXPECT_EQ(more[0].GetName(), "lid_box_2");
  EXPECT_FALSE(more[0].HasFixedRoot());
  ExpectPose(more[0].GetRootPose(), up);
  EXPECT_EQ(scene_.GetArticulations().size(), 2u);
}

TEST_F(SceneFileTest, LoadsAPartNetMobilityFolder) {
  const fs::path folder = dir_ / "cabinet";
  const std::string name = WriteCabinet(folder);
  const Pose X_WO(Eigen::Vector3d(1.0, 2.0, 0.0),
                  Eigen::Quaterniond(Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitZ())));
  std::vector<Articulation> arts = AddSceneObjects(&scene_, folder.string(), X_WO);
  ASSERT_EQ(arts.size(), 1u);
  EXPECT_EQ(arts[0].GetName(), name);
  EXPECT_TRUE(arts[0].HasFixedRoot());
  EXPECT_GT(arts[0].Dof(), 0);
  ExpectPose(arts[0].GetRootPose(), X_WO);
  scene_.Step(20);
  ExpectPose(arts[0].GetRootPose(), X_WO);
  EXPECT_TRUE(scene_.GetWarnings().empty());
}

TEST_F(SceneFileTest, LoadsASceneFileWithObjectsAtTheirPoses) {
  WriteCabinet(dir_ / "assets" / "cabinet");
  const double half = 0.35;
  const Pose X_WA(Eigen::Vector3d(1.0, 0.0, 0.5),
                  Eigen::Quaterniond(std::cos(half), 0, 0, std::sin(half)));
  const Eigen::Vector3d rpy(0.1, -0.2, 1.3);
  const Pose X_WB(Eigen::Vector3d(-1.5, 0.25, 0.0),
                  Eigen::Quaterniond(Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
                                     Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
                                     Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX())));
  const Pose X_WC(Eigen::Vector3d(0.0, 3.0, 1.0));
  // relative paths: the URDF beside the scene file, the cabinet in a sub-folder
  const std::string path = WriteScene("two_objects.json", R"({"objects": [
    {"path": "lid_box.urdf", "name": "box_a",
     "pose": {"position": [1, 0, 0.5], "orientation": [)" + Json(std::cos(half)) +
                                                              ", 0, 0, " + Json(std::sin(half)) +
                                                              R"(]}},
    {"path": "assets/cabinet", "name": "cabinet_b",
     "pose": {"position": [-1.5, 0.25, 0], "rpy": [0.1, -0.2, 1.3]}},
    {"path": "lid_box.urdf", "pose": {"position": [0, 3, 1]}, "fix_root": false}
  ]})");

  // the file as read
  SceneFileSpec spec = ReadSceneFile(path);
  ASSERT_EQ(spec.objects.size(), 3u);
  EXPECT_EQ(fs::path(spec.objects[0].path), fs::path(urdf_));
  EXPECT_EQ(fs::path(spec.objects[1].path), dir_ / "assets" / "cabinet");
  EXPECT_EQ(spec.objects[0].name, "box_a");
  EXPECT_TRUE(spec.objects[2].name.empty());
  EXPECT_FALSE(spec.objects[0].fix_root.has_value());
  EXPECT_EQ(spec.objects[2].fix_root, std::optional<bool>(false));
  ExpectPose(spec.objects[1].pose, X_WB);

  // the scene
  std::vector<Articulation> arts = AddSceneObjects(&scene_, path);
  ASSERT_EQ(arts.size(), 3u);
  EXPECT_EQ(arts[0].GetName(), "box_a");
  EXPECT_EQ(arts[1].GetName(), "cabinet_b");
  EXPECT_EQ(arts[2].GetName(), "lid_box");
  EXPECT_EQ(scene_.FindArticulationByName("cabinet_b"), arts[1]);
  EXPECT_TRUE(arts[0].HasFixedRoot());
  EXPECT_TRUE(arts[1].HasFixedRoot());
  EXPECT_FALSE(arts[2].HasFixedRoot());
  ExpectPose(arts[0].GetRootPose(), X_WA);
  ExpectPose(arts[1].GetRootPose(), X_WB);
  ExpectPose(arts[2].GetRootPose(), X_WC);
  // the fixed ones stay, the free one falls
  scene_.Step(100);
  ExpectPose(arts[0].GetRootPose(), X_WA);
  ExpectPose(arts[1].GetRootPose(), X_WB);
  EXPECT_LT(arts[2].GetRootPose().p.z(), 1.0 - 1e-3);
}

TEST_F(SceneFileTest, ScalesAndFixRootDefaultComeFromTheFileAndTheCaller) {
  const std::string path = WriteScene("scaled.json", R"({"objects": [
    {"path": "lid_box.urdf", "scale": 2},
    {"path": "lid_box.urdf", "fix_root": true}]})");
  std::vector<Articulation> arts = AddSceneObjects(&scene_, path, Pose(), /*fix_root=*/false);
  ASSERT_EQ(arts.size(), 2u);
  EXPECT_FALSE(arts[0].HasFixedRoot());  // the caller's default
  EXPECT_TRUE(arts[1].HasFixedRoot());   // the entry's own
  // the hinge's origin (0, -0.1, 0.11) doubles
  EXPECT_NEAR(arts[0].GetJoint(1).GetPoseInParent().p.z(), 0.22, 1e-12);
  EXPECT_NEAR(arts[1].GetJoint(1).GetPoseInParent().p.z(), 0.11, 1e-12);
}

TEST_F(SceneFileTest, BadScenesNameTheFileEntryAndFieldAndLeaveTheSceneWorking) {
  // the scene already holds one object
  const Pose X_WA(Eigen::Vector3d(0, 0, 0.3));
  Articulation first = AddSceneObjects(&scene_, urdf_, X_WA).at(0);
  WriteFile(dir_ / "mesh.obj", "v 0 0 0\n");
  fs::create_directories(dir_ / "empty_folder");
  WriteFile(dir_ / "broken.urdf", "<robot name='b'><link name='a'>");
  WriteCabinet(dir_ / "cabinet");
  const std::string good = R"({"path": "lid_box.urdf", "name": "fine"})";

  struct Case {
    std::string json;
    std::vector<std::string> words;
  };
  const std::vector<Case> cases = {
      {R"({"objects": [)", {"bad JSON"}},
      {R"({"objects": [{"path": "lid_box.urdf", "pose": {"position": [0, 1e999, 0]}}]})",
       {"bad JSON", "1e999"}},
      {R"([1, 2])", {"(top level)", "must be an object"}},
      {R"({})", {"objects", "is missing"}},
      {R"({"objects": {"path": "lid_box.urdf"}})", {"objects", "must be a list"}},
      {R"({"objects": []})", {"objects", "is empty"}},
      {R"({"objects": [{"path": "lid_box.urdf"}], "extra": 1})", {"extra", "unknown field"}},
      {R"({"objects": [)" + good + R"(, 3]})", {"objects[1]", "must be an object"}},
      {R"({"objects": [{"name": "a"}]})", {"objects[0].path", "is missing"}},
      {R"({"objects": [{"path": 3}]})", {"objects[0].path", "must be a string"}},
      {R"({"objects": [)" + good + R"(, {"path": "missing.urdf"}]})",
       {"objects[1]", "missing.urdf", "does not exist"}},
      {R"({"objects": [{"path": "mesh.obj"}]})", {"objects[0]", "mesh.obj", "unknown extension"}},
      {R"({"objects": [{"path": "empty_folder"}]})",
       {"objects[0]", "empty_folder", "neither mobility.urdf"}},
      {R"({"objects": [)" + good + R"(, {"path": "other.json"}]})",
       {"objects[1].path", "other.json", "cannot be nested"}},
      {R"({"objects": [)" + good + R"(, {"path": "broken.urdf"}]})", {"objects[1]", "broken.urdf"}},
      {R"({"objects": [{"path": "lid_box.urdf", "name": 7}]})",
       {"objects[0].name", "must be a string"}},
      {R"({"objects": [{"path": "lid_box.urdf", "pose": [0, 0, 0]}]})",
       {"objects[0].pose", "must be an object"}},
      {R"({"objects": [{"path": "lid_box.urdf", "pose": {"position": "0 0 0"}}]})",
       {"objects[0].pose.position", "list of 3 numbers"}},
      {R"({"objects": [{"path": "lid_box.urdf", "pose": {"position": [0, 0]}}]})",
       {"objects[0].pose.position", "list of 3 numbers"}},
      {R"({"objects": [{"path": "lid_box.urdf", "pose": {"position": [0, "a", 0]}}]})",
       {"objects[0].pose.position[1]", "must be a number"}},
      {R"({"objects": [{"path": "lid_box.urdf", "pose": {"orientation": [0, 0, 0, 0]}}]})",
       {"objects[0].pose.orientation", "zero"}},
      {R"({"objects": [{"path": "lid_box.urdf", "pose": {"orientation": [2, 0, 0, 0]}}]})",
       {"objects[0].pose.orientation", "norm 2"}},
      {R"({"objects": [{"path": "lid_box.urdf", "pose": {"orientation": [1, 0, 0]}}]})",
       {"objects[0].pose.orientation", "list of 4 numbers"}},
      {R"({"objects": [{"path": "lid_box.urdf",
           "pose": {"orientation": [1, 0, 0, 0], "rpy": [0, 0, 0]}}]})",
       {"objects[0].pose.rpy", "not both"}},
      {R"({"objects": [{"path": "lid_box.urdf", "pose": {"orientaton": [1, 0, 0, 0]}}]})",
       {"objects[0].pose.orientaton", "unknown field"}},
      {R"({"objects": [{"path": "lid_box.urdf", "fix_root": "yes"}]})",
       {"objects[0].fix_root", "true or false"}},
      {R"({"objects": [{"path": "lid_box.urdf", "scale": -1}]})", {"objects[0].scale", "> 0"}},
      {R"({"objects": [{"path": "lid_box.urdf", "scale": "big"}]})",
       {"objects[0].scale", "must be a number"}},
      {R"({"objects": [)" + good + R"(, {"path": "lid_box.urdf", "name": "fine"}]})",
       {"objects[1].name", "'fine'", "earlier entry"}},
      {R"({"objects": [{"path": "lid_box.urdf", "name": "lid_box"}]})",
       {"objects[0]", "'lid_box'", "taken"}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i) + ": " + cases[i].json);
    const std::string path = WriteScene("bad_" + std::to_string(i) + ".json", cases[i].json);
    std::vector<std::string> words = cases[i].words;
    words.push_back("scene file " + path);
    ExpectError([&] { AddSceneObjects(&scene_, path); }, words);
    // nothing was added, the first object is still there and the scene steps
    ASSERT_EQ(scene_.GetArticulations().size(), 1u);
    EXPECT_EQ(scene_.GetArticulations()[0], first);
    scene_.Step(5);
    ExpectPose(first.GetRootPose(), X_WA);
  }
  EXPECT_TRUE(scene_.GetWarnings().empty());

  // lone paths
  ExpectError([&] { AddSceneObjects(&scene_, (dir_ / "nope.urdf").string()); },
              {(dir_ / "nope.urdf").string(), "does not exist"});
  ExpectError([&] { AddSceneObjects(&scene_, (dir_ / "mesh.obj").string()); },
              {(dir_ / "mesh.obj").string(), "unknown extension '.obj'"});
  ExpectError([&] { AddSceneObjects(&scene_, (dir_ / "broken.urdf").string()); },
              {(dir_ / "broken.urdf").string()});
  Pose nan_pose(Eigen::Vector3d(0, std::numeric_limits<double>::quiet_NaN(), 0));
  ExpectError([&] { AddSceneObjects(&scene_, urdf_, nan_pose); }, {urdf_, "default_pose"});
  Pose zero_q(Eigen::Vector3d::Zero(), Eigen::Quaterniond(0, 0, 0, 0));
  ExpectError([&] { AddSceneObjects(&scene_, urdf_, zero_q); }, {urdf_, "default_pose"});
  ExpectError([&] { AddSceneObjects(nullptr, urdf_); }, {urdf_, "scene"});
  ExpectError([&] { ReadSceneFile((dir_ / "nope.json").string()); },
              {(dir_ / "nope.json").string(), "does not exist"});
  ASSERT_EQ(scene_.GetArticulations().size(), 1u);

  // and a good file still loads afterwards
  const std::string ok = WriteScene("ok.json", R"({"objects": [)" + good + "]}");
  EXPECT_EQ(AddSceneObjects(&scene_, ok).at(0).GetName(), "fine");
  scene_.Step(5);
  EXPECT_EQ(scene_.GetArticulations().size(), 2u);
}

}  // namespace
}  // namespace partsim
