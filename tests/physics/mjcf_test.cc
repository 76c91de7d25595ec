// MJCF models in a scene (partsim/physics/mjcf.h): MuJoCo's own models from ../shared/realdata
// (tendons, an equality-closed loop, a textured mesh, <replicate>) and files written here
// (<include>, <attach> with <model> assets, relative paths, errors) load, simulate as MuJoCo
// defines them and get partsim's handles.
#include "partsim/physics/mjcf.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "partsim/core/error.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;

const fs::path kRealMjcf = fs::path(PARTSIM_SOURCE_DIR) / ".." / "shared" / "realdata" / "mjcf";

#define REQUIRE_REALDATA() \
  if (!fs::exists(kRealMjcf)) GTEST_SKIP() << "no " << kRealMjcf << " (../shared)"

fs::path TempDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() /
                 ("partsim_mjcf_test_" + name + "_" +
                  std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void Write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

// The car: a free body with two wheels on hinges, a fixed-tendon differential and two motors.
// It becomes one articulation with a free root; its floor becomes a static actor; driving the
// "forward" motor moves it forward (MuJoCo's tendons carry the motor's force to the wheels).
TEST(MjcfTest, TheCarDrivesOnItsTendonsAndIsAnArticulation) {
  REQUIRE_REALDATA();
  Scene scene;
  MjcfModel car = LoadMjcf(scene, (kRealMjcf / "car" / "car.xml").string());
  EXPECT_EQ(car.GetName(), "car");
  ASSERT_EQ(car.GetArticulations().size(), 1u);
  Articulation a = car.GetArticulations()[0];
  EXPECT_EQ(a.GetName(), "car");
  EXPECT_FALSE(a.HasFixedRoot());
  EXPECT_EQ(a.Dof(), 2);  // the two wheels
  EXPECT_EQ(a.GetLinks().size(), 3u);
  EXPECT_NO_THROW(a.FindJointByName("left"));
  ASSERT_EQ(car.GetActors().size(), 1u);
  EXPECT_EQ(car.GetActors()[0].GetType(), ActorType::kStatic);
  EXPECT_EQ(car.GetActuatorNames(), (std::vector<std::string>{"forward", "turn"}));
  EXPECT_EQ(car.GetTendonNames(), (std::vector<std::string>{"forward", "turn"}));
  // the chassis is drawn: a mesh visual
  bool mesh = false;
  for (const Link& l : a.GetLinks())
    for (const VisualShape& v : l.GetDesc().visuals) mesh |= v.type == ShapeType::kConvexMesh;
  EXPECT_TRUE(mesh);

  const Eigen::Vector3d start = a.GetRootPose().p;
  car.SetCtrl("forward", 1.0);
  scene.Step(1000);                  // 2 s
  EXPECT_EQ(car.GetCtrl()[0], 1.0);  // kept across steps
  const Eigen::Vector3d moved = a.GetRootPose().p - start;
  EXPECT_GT(moved.head<2>().norm(), 0.1) << moved.transpose();
  // the tendon "forward" is the mean of the wheel angles, as the file defines it
  const Eigen::VectorXd q = a.GetQpos();
  EXPECT_NEAR(car.GetTendonLengths()[0], 0.5 * (q[0] + q[1]), 1e-9);
  for (const Warning& w : scene.GetWarnings()) ADD_FAILURE() << w.message;
}

// The slider-crank: unnamed bodies and joints, position actuators through slider-crank
// transmissions. Partsim names what the file leaves unnamed, the state survives a recompile
// (an actor added later), and the controls reach MuJoCo.
TEST(MjcfTest, TheSliderCrankKeepsItsStateAcrossARecompile) {
  REQUIRE_REALDATA();
  Scene scene;
  MjcfModel model = LoadMjcf(scene, (kRealMjcf / "slider_crank" / "slider_crank.xml").string());
  EXPECT_EQ(model.GetActuatorNames(), (std::vector<std::string>{"forward", "backward", "broken"}));
  EXPECT_EQ(model.GetArticulations().size(), 2u);  // two trees, each on a hinge to the world
  model.SetCtrl(Eigen::Vector3d(0.05, -0.05, 0.0));
  scene.Step(500);
  const Eigen::VectorXd q = model.GetQpos();
  EXPECT_GT(q.cwiseAbs().maxCoeff(), 0.05);
  // add an actor: the scene recompiles, the model's state and controls stay
  ActorDesc box;
  box.name = "box";
  box.pose = Pose(Eigen::Vector3d(1, 1, 1));
  box.collisions.emplace_back();
  box.collisions.back().half_size = Eigen::Vector3d::Constant(0.05);
  scene.AddActor(box);
  scene.Step(0);
  EXPECT_TRUE(model.GetQpos().isApprox(q, 1e-12));
  EXPECT_EQ(model.GetCtrl()[0], 0.05);
  // the articulation handles read the same joints
  double sum = 0;
  for (const Articulation& a : model.GetArticulations()) sum += a.GetQpos().cwiseAbs().sum();
  EXPECT_NEAR(sum, q.cwiseAbs().sum(), 1e-12);
}

// The mug: a textured OBJ mesh (relative paths) drawn with its texture, and box collision geoms
// in group 3 (MuJoCo does not draw them): a dynamic actor that falls onto the floor.
TEST(MjcfTest, TheMugIsADynamicArticulationWithItsTexturedMesh) {
  REQUIRE_REALDATA();
  Scene scene;
  MjcfModel mug =
      LoadMjcf(scene, (kRealMjcf / "mug" / "mug.xml").string(), Pose(Eigen::Vector3d(0, 0, 0.2)));
  ASSERT_EQ(mug.GetArticulations().size(), 1u);  // the mug and its handle
  Articulation a = mug.GetArticulations()[0];
  EXPECT_FALSE(a.HasFixedRoot());
  const std::vector<VisualShape>& visuals = a.GetLinks()[0].GetDesc().visuals;
  ASSERT_EQ(visuals.size(), 1u);  // the mesh; the collision boxes are not drawn
  EXPECT_EQ(visuals[0].type, ShapeType::kConvexMesh);
  EXPECT_FALSE(visuals[0].mesh->uvs.empty());
  EXPECT_EQ(fs::path(visuals[0].material.diffuse_texture).filename(), "mug.png");
  EXPECT_TRUE(fs::exists(visuals[0].material.diffuse_texture));
  EXPECT_GT(a.GetLinks()[0].GetDesc().collisions.size(), 10u);
  // the model was placed as a whole, its floor too: the mug stands on it, 0.2 m up
  scene.Step(100);
  EXPECT_NEAR(a.GetRootPose().p.z(), 0.2, 0.01);
  // lifted by 0.3 m through its handle, it falls back onto the floor
  Pose up = a.GetRootPose();
  up.p.z() += 0.3;
  a.SetRootPose(up);
  scene.Step(500);
  EXPECT_NEAR(a.GetRootPose().p.z(), 0.2, 0.01);
}

// <replicate>: Newton's cradle's seven balls (5 + 2 replicated), each a free body hung on two
// spatial tendons, and its floor. Loaded into a scene, the file's timestep (1e-4) gives way to
// the scene's, without a warning about it: the scene's options hold for everything in it. A
// scene made with the file's options (SceneConfigFromMjcf) runs it as MuJoCo would.
TEST(MjcfTest, ReplicatedBodiesAllGetHandlesAndTheSceneKeepsItsOptions) {
  REQUIRE_REALDATA();
  const std::string path = (kRealMjcf / "replicate" / "newton_cradle.xml").string();
  {
    Scene scene;
    LoadMjcf(scene, path);
    EXPECT_DOUBLE_EQ(scene.GetMjModel()->opt.timestep, SceneConfig().timestep);
    for (const Warning& w : scene.GetWarnings())
      EXPECT_EQ(w.message.find("conflict"), std::string::npos) << w.message;
  }
  const SceneConfig config = SceneConfigFromMjcf(path);
  EXPECT_DOUBLE_EQ(config.timestep, 1e-4);
  Scene scene(config);
  MjcfModel cradle = LoadMjcf(scene, path);
  EXPECT_TRUE(cradle.GetArticulations().empty());
  int balls = 0;
  for (const Actor& a : cradle.GetActors()) balls += a.GetType() == ActorType::kDynamic;
  EXPECT_EQ(balls, 7);
  EXPECT_EQ(cradle.GetActors().size(), 8u);  // and the floor
  EXPECT_EQ(cradle.GetTendonNames().size(), 14u);
  // the balls hang on their tendons: none falls to the floor
  scene.Step(2000);
  for (const Actor& a : cradle.GetActors())
    if (a.GetType() == ActorType::kDynamic) EXPECT_GT(a.GetPose().p.z(), 0.03) << a.GetName();
  EXPECT_TRUE(scene.GetWarnings().empty()) << scene.GetWarnings()[0].message;
}

// <include>, <attach> with a <model> asset, and meshes found relative to the file that names
// them; two copies of one file in one scene get different prefixes.
TEST(MjcfTest, IncludeAttachAndRelativePathsWork) {
  const fs::path dir = TempDir("include");
  Write(dir / "parts" / "arm.xml", R"(<mujoco model="arm">
  <worldbody>
    <body name="upper" pos="0 0 0.5">
      <joint name="shoulder" type="hinge" axis="0 1 0" range="-60 60"/>
      <geom type="capsule" size="0.02" fromto="0 0 0 0.3 0 0"/>
      <body name="lower" pos="0.3 0 0">
        <joint name="elbow" type="hinge" axis="0 1 0"/>
        <geom type="capsule" size="0.02" fromto="0 0 0 0.3 0 0"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor name="elbow_motor" joint="elbow"/></actuator>
</mujoco>)");
  Write(dir / "assets" / "tetra.obj",
        "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\n"
        "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  Write(dir / "floor.xml", R"(<mujoco><worldbody>
  <geom name="floor" type="plane" size="2 2 0.1"/>
</worldbody></mujoco>)");
  Write(dir / "main.xml", R"(<mujoco model="cell">
  <compiler meshdir="assets"/>
  <asset>
    <model name="arm" file="parts/arm.xml"/>
    <mesh name="tetra" file="tetra.obj"/>
  </asset>
  <include file="floor.xml"/>
  <worldbody>
    <body name="rock" pos="1 0 0.3"><freejoint/><geom type="mesh" mesh="tetra"/></body>
    <frame pos="0 1 0"><attach model="arm" body="upper" prefix="left_"/></frame>
  </worldbody>
</mujoco>)");
  Scene scene;
  MjcfModel cell = LoadMjcf(scene, (dir / "main.xml").string());
  EXPECT_EQ(cell.GetPrefix(), "cell/");
  EXPECT_EQ(cell.GetActuatorNames(), (std::vector<std::string>{"left_elbow_motor"}));
  EXPECT_GE(cell.MjId(mjOBJ_BODY, "left_upper"), 0);
  EXPECT_GE(cell.MjId(mjOBJ_GEOM, "floor"), 0);
  Articulation arm = scene.FindArticulationByName("left_upper");
  EXPECT_EQ(arm.Dof(), 2);
  EXPECT_NEAR(arm.GetQlimits()(0, 1), M_PI / 3, 1e-12);       // MJCF's degrees, as radians
  EXPECT_NEAR(arm.GetLinks()[1].GetPose().p.y(), 1.0, 1e-9);  // placed by the frame
  Actor rock = scene.FindActorByName("rock");
  EXPECT_EQ(rock.GetType(), ActorType::kDynamic);
  scene.Step(300);
  EXPECT_LT(rock.GetPose().p.z(), 0.1);  // fell onto the included floor
  // a second copy of the same file
  MjcfModel again = LoadMjcf(scene, (dir / "main.xml").string(), Pose(Eigen::Vector3d(5, 0, 0)));
  EXPECT_EQ(again.GetPrefix(), "cell#2/");
  EXPECT_EQ(GetMjcfModels(scene).size(), 2u);
  scene.Step(10);
  fs::remove_all(dir);
}

// Bad MJCF: MuJoCo's own message with the file and line; the scene is as it was.
TEST(MjcfTest, BadMjcfGivesMuJoCosMessageAndLeavesTheSceneAsItWas) {
  const fs::path dir = TempDir("bad");
  Scene scene;
  scene.AddGround(0.0);
  ActorDesc box;
  box.name = "box";
  box.pose = Pose(Eigen::Vector3d(0, 0, 1));
  box.collisions.emplace_back();
  box.collisions.back().half_size = Eigen::Vector3d::Constant(0.05);
  Actor b = scene.AddActor(box);
  scene.Step(50);
  const std::vector<char> state = scene.Pack();
  const int nbody = static_cast<int>(scene.GetMjModel()->nbody);

  auto expect_refused = [&](const std::string& file, const std::string& text,
                            const std::vector<std::string>& words) {
    Write(dir / file, text);
    try {
      LoadMjcf(scene, (dir / file).string());
      ADD_FAILURE() << file << " was accepted";
    } catch (const Error& e) {
      const std::string m = e.what();
      for (const std::string& w : words) EXPECT_NE(m.find(w), std::string::npos) << m;
    }
    EXPECT_EQ(scene.GetMjModel()->nbody, nbody);
    EXPECT_TRUE(scene.Pack() == state) << file;  // not even recompiled
    EXPECT_TRUE(GetMjcfModels(scene).empty());
  };
  // not XML
  expect_refused("broken.xml", "<mujoco>\n<worldbody>\n<body>\n</mujoco>\n",
                 {"broken.xml", "Line number=3"});
  // an unknown attribute, on line 3
  expect_refused("attr.xml",
                 "<mujoco>\n<worldbody>\n<body wobble=\"1\"><geom size=\".1\"/></body>\n"
                 "</worldbody></mujoco>\n",
                 {"attr.xml", "wobble", "line 3"});
  // a mesh file that is not there (found at compile)
  expect_refused("mesh.xml",
                 "<mujoco><asset><mesh name=\"m\" file=\"nothere.stl\"/></asset>\n"
                 "<worldbody><geom type=\"mesh\" mesh=\"m\"/></worldbody></mujoco>\n",
                 {"nothere.stl"});
  try {
    LoadMjcf(scene, (dir / "absent.xml").string());
    ADD_FAILURE() << "an absent file was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("absent.xml"), std::string::npos) << e.what();
  }
  scene.Step(500);
  EXPECT_NEAR(b.GetPose().p.z(), 0.05, 2e-3);  // the scene goes on
  fs::remove_all(dir);
}

// Hostile files: bytes that are not text, bodies nested past what MuJoCo's parser takes, numbers
// past a double's range, a root that is not <mujoco>. Each is refused with a message that names
// the file; the scene is as it was, and the detection of MJCF files survives them.
TEST(MjcfTest, HostileFilesAreRefusedByNameAndTheSceneGoesOn) {
  const fs::path dir = TempDir("hostile");
  Scene scene;
  scene.AddGround(0.0);
  scene.Step(5);
  const std::vector<char> state = scene.Pack();
  std::string garbage = "<mujoco>\n<worldbody>\n<body name=\"";
  for (int i = 0; i < 3000; ++i) garbage += static_cast<char>(128 + (i * 37) % 128);
  garbage += std::string("\0\xff\xfe<<>>", 8) + "\"/></worldbody></mujoco>\n";
  std::string deep = "<mujoco><worldbody>";
  for (int i = 0; i < 2000; ++i) deep += "<body><geom size=\".01\"/>";
  for (int i = 0; i < 2000; ++i) deep += "</body>";
  deep += "</worldbody></mujoco>\n";
  const std::vector<std::pair<std::string, std::string>> files = {
      {"garbage.xml", garbage},
      {"deep.xml", deep},
      {"huge.xml",
       "<mujoco><worldbody><body pos=\"1e999 0 0\"><geom size=\".1\"/></body>"
       "</worldbody></mujoco>\n"},
      {"robot.xml", "<robot name=\"r\"><link name=\"a\"/></robot>\n"},
      {"empty.xml", ""},
  };
  for (const auto& [name, text] : files) {
    Write(dir / name, text);
    try {
      LoadMjcf(scene, (dir / name).string());
      ADD_FAILURE() << name << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
    EXPECT_TRUE(scene.Pack() == state) << name;
    EXPECT_TRUE(GetMjcfModels(scene).empty()) << name;
  }
  // MuJoCo's parser would import the URDF: partsim names it and its own loader instead
  try {
    LoadMjcf(scene, (dir / "robot.xml").string());
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("<robot>, not <mujoco> (a URDF"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(IsMjcfFile((dir / "robot.xml").string()));
  EXPECT_FALSE(IsMjcfFile((dir / "empty.xml").string()));
  EXPECT_TRUE(IsMjcfFile((dir / "garbage.xml").string()));  // a <mujoco> root, refused later
  scene.Step(10);
  fs::remove_all(dir);
}

TEST(MjcfTest, IsMjcfFileReadsTheRootElement) {
  const fs::path dir = TempDir("detect");
  Write(dir / "a.xml", "<?xml version=\"1.0\"?>\n<!-- a model -->\n<mujoco model=\"x\"/>\n");
  Write(dir / "b.xml", "<robot name=\"r\"/>\n");
  EXPECT_TRUE(IsMjcfFile((dir / "a.xml").string()));
  EXPECT_FALSE(IsMjcfFile((dir / "b.xml").string()));
  EXPECT_FALSE(IsMjcfFile((dir / "none.xml").string()));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace partsim
