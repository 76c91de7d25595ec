// Scenes of many bodies: actors added one by one join the model at its next use (one compile,
// not one per actor), MuJoCo's arena grows when a step fills it, and
// what MuJoCo refuses or cannot allocate gives an error that leaves the scene as it was.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "partsim/core/error.h"
#include "partsim/physics/mjcf.h"
#include "partsim/physics/scene.h"
#include "physics/scene_internal.h"

namespace partsim {
namespace {

ActorDesc Box(const std::string& name, const Eigen::Vector3d& at, double half = 0.05) {
  ActorDesc d;
  d.name = name;
  d.pose = Pose(at);
  CollisionShape s;
  s.type = ShapeType::kBox;
  s.half_size = Eigen::Vector3d::Constant(half);
  d.collisions.push_back(s);
  return d;
}

// A thousand actors added one by one cost one compile; a chain of 500 links loads and steps.
TEST(CapacityTest, ActorsAddedOneByOneCompileOnceAtTheNextUse) {
  SceneConfig cfg;
  cfg.integrator = Integrator::kEuler;
  cfg.gravity = Eigen::Vector3d::Zero();
  Scene scene(cfg);
  const uint64_t before = scene.impl().description_version;
  for (int i = 0; i < 1000; ++i)
    scene.AddActor(Box("b" + std::to_string(i),
                       Eigen::Vector3d(0.3 * (i % 10), 0.3 * (i / 10 % 10), 0.3 * (i / 100))));
  EXPECT_EQ(scene.impl().description_version, before);  // nothing compiled yet
  EXPECT_EQ(scene.GetActors().size(), 1000u);
  Actor last = scene.GetActors().back();
  last.SetPose(Pose(Eigen::Vector3d(5, 5, 5)));  // placed before it is compiled: no compile
  EXPECT_EQ(scene.impl().description_version, before);
  scene.Step(10);
  EXPECT_EQ(scene.impl().description_version, before + 1);
  EXPECT_NEAR(last.GetPose().p.x(), 5.0, 1e-12);
  EXPECT_NEAR(scene.GetActors()[123].GetPose().p.z(), 0.3, 1e-12);
}

ArticulationDesc Chain(int links) {
  ArticulationDesc chain;
  chain.name = "chain";
  chain.fix_root = true;
  for (int i = 0; i < links; ++i) {
    LinkDesc l;
    l.name = "l" + std::to_string(i);
    l.parent = i - 1;
    CollisionShape s;
    s.type = ShapeType::kCapsule;
    s.radius = 0.01;
    s.half_length = 0.04;
    l.collisions.push_back(s);
    if (i > 0) {
      l.joint.name = "j" + std::to_string(i);
      l.joint.type = JointType::kRevolute;
      l.joint.lower = -0.5;
      l.joint.upper = 0.5;
      l.joint.pose_in_parent = Pose(Eigen::Vector3d(0.1, 0, 0));
    }
    chain.links.push_back(l);
  }
  return chain;
}

// Deep chains: MuJoCo 2.2.2's XML parser stopped at 100 nested bodies (a chain of about 95
// links); a chain of 500 links now loads, steps and answers dynamics queries.
TEST(CapacityTest, AChainOf500LinksLoadsAndSteps) {
  Scene scene;
  Articulation a = scene.AddArticulation(Chain(500));
  EXPECT_EQ(a.Dof(), 499);
  a.SetQpos(Eigen::VectorXd::Constant(a.Dof(), 0.01));
  scene.Step(5);
  EXPECT_TRUE(a.GetQpos().allFinite());
  EXPECT_EQ(a.ComputePassiveForce(true, true).size(), 499);
  // a second articulation beside it
  scene.AddArticulation(Chain(120));
  EXPECT_EQ(scene.GetArticulations().size(), 2u);
  scene.Step(1);
}

// Boxes dropped on the ground need more of MuJoCo's arena than the scene was given (here a
// small one, as if an earlier scene had needed little): the arena grows (with a warning) and
// every box comes to rest on the ground, none through it.
TEST(CapacityTest, TheArenaGrowsWhenAStepFillsIt) {
  Scene scene;
  scene.AddGround(0.0);
  for (int i = 0; i < 80; ++i)  // 4 contacts each on the ground
    scene.AddActor(
        Box("b" + std::to_string(i), Eigen::Vector3d(0.3 * (i % 10), 0.3 * (i / 10), 0.06)));
  scene.impl().arena_capacity = 96 * 1024;
  scene.Step(200);
  bool grew = false;
  for (const Warning& w : scene.GetWarnings())
    grew |= w.message.find("arena grown to") != std::string::npos;
  EXPECT_TRUE(grew);
  EXPECT_GT(scene.GetMjModel()->narena, 96 * 1024);
  for (const Actor& a : scene.GetActors())
    if (a.GetName() != "ground") EXPECT_NEAR(a.GetPose().p.z(), 0.05, 2e-3) << a.GetName();
  // a clone keeps the grown arena
  std::unique_ptr<Scene> copy = scene.Clone();
  EXPECT_EQ(copy->GetMjModel()->narena, scene.GetMjModel()->narena);
}

// A scene without collision shapes cannot have contacts: MuJoCo's arena starts small (a
// rendered dataset object compiles without MuJoCo's ~14 MB estimate), the chain still steps and
// answers dynamics queries, and once shapes that can touch are added the arena is the usual one.
TEST(CapacityTest, ASceneWithoutCollisionShapesStartsWithASmallArena) {
  Scene scene;
  ArticulationDesc chain = Chain(30);
  for (LinkDesc& l : chain.links) l.collisions.clear();
  Articulation a = scene.AddArticulation(chain);
  a.SetQpos(Eigen::VectorXd::Constant(a.Dof(), 0.3));
  scene.Step(50);
  EXPECT_TRUE(a.GetQpos().allFinite());
  EXPECT_LT(scene.GetMjModel()->narena, 1 << 20);
  const Eigen::MatrixXd mass = a.ComputeManipulatorInertiaMatrix();
  EXPECT_EQ(mass.rows(), a.Dof());
  EXPECT_TRUE(mass.allFinite());
  EXPECT_GT(mass.diagonal().minCoeff(), 0.0);

  scene.AddGround(0.0);
  scene.AddActor(Box("box", Eigen::Vector3d(3, 0, 0.2)));
  scene.Step(300);
  EXPECT_GT(scene.GetMjModel()->narena, 4 << 20);
  EXPECT_NEAR(scene.GetActors().back().GetPose().p.z(), 0.05, 2e-3);  // resting, not through
}

// An actor MuJoCo refuses (an inertia that breaks A + B >= C, which only the compiler checks)
// is named when the scene next compiles and left out; the actors added with it stay in.
TEST(CapacityTest, AnActorMuJoCoRefusesIsLeftOutAndTheOthersStay) {
  Scene scene;
  scene.AddGround(0.0);
  scene.AddActor(Box("good1", Eigen::Vector3d(0, 0, 0.5)));
  ActorDesc bad = Box("bad", Eigen::Vector3d(1, 0, 0.5));
  bad.inertial = Inertial{1.0, Pose(), Eigen::Vector3d(0.01, 0.01, 1.0)};
  scene.AddActor(bad);  // validated, not compiled yet
  scene.AddActor(Box("good2", Eigen::Vector3d(2, 0, 0.5)));
  try {
    scene.Step(1);
    ADD_FAILURE() << "the bad actor was compiled";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("1 of the 4 actors"), std::string::npos) << m;
    EXPECT_NE(m.find("'bad'"), std::string::npos) << m;
  }
  std::vector<std::string> names;
  for (const Actor& a : scene.GetActors()) names.push_back(a.GetName());
  EXPECT_EQ(names, (std::vector<std::string>{"ground", "good1", "good2"}));
  scene.Step(10);
  EXPECT_LT(scene.GetActors()[1].GetPose().p.z(), 0.5);  // falling
}

// A thin disc of `corners` corners (a prism 1 cm thick): every point on one of two planes, what
// cost qhull about n^2.5.
std::vector<Eigen::Vector3f> ThinDisc(int corners) {
  std::vector<Eigen::Vector3f> v;
  for (float z : {0.0f, 0.01f})
    for (int k = 0; k < corners; ++k) {
      const double a = 2 * M_PI * k / corners;
      v.emplace_back(static_cast<float>(0.1 * std::cos(a)), static_cast<float>(0.1 * std::sin(a)),
                     z);
    }
  return v;
}

// Hull vertices MuJoCo keeps of the scene's only mesh.
int HullVertices(Scene& scene) {
  scene.impl().EnsureCompiled();
  const mjModel* m = scene.impl().m();
  EXPECT_EQ(m->nmesh, 1);
  return m->mesh_graphadr[0] < 0 ? m->mesh_vertnum[0] : m->mesh_graph[m->mesh_graphadr[0]];
}

// Meshes that reach MuJoCo without the assets layer's bound (a shape put in a description, an
// MJCF file's mesh) keep at most 2000 hull vertices: a 10,000-corner disc compiled for a minute.
TEST(CapacityTest, MeshesOfManyCoplanarPointsKeepABoundedHull) {
  Scene scene;
  scene.AddGround(0.0);
  auto mesh = std::make_shared<MeshData>();
  mesh->vertices = ThinDisc(10000);
  ActorDesc d;
  d.name = "disc";
  d.pose = Pose(Eigen::Vector3d(0, 0, 0.05));
  CollisionShape shape;
  shape.type = ShapeType::kConvexMesh;
  shape.mesh = mesh;
  d.collisions.push_back(shape);
  Actor disc = scene.AddActor(d);
  EXPECT_LE(HullVertices(scene), 2000);
  scene.Step(500);
  EXPECT_NEAR(disc.GetPose().p.z(), 0.0, 3e-3);  // rests on its face

  // an MJCF mesh: bounded unless the file sets maxhullvert itself
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("partsim_hull_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  std::string vertices;
  for (const Eigen::Vector3f& p : ThinDisc(10000))
    vertices +=
        std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + " ";
  for (const std::string bound : {"", " maxhullvert=\"100\""}) {
    std::ofstream(dir / "disc.xml")
        << "<mujoco><asset><mesh name=\"disc\" vertex=\"" << vertices << "\"" << bound
        << "/></asset><worldbody><body><freejoint/><geom type=\"mesh\" "
           "mesh=\"disc\"/></body></worldbody></mujoco>\n";
    Scene from_file;
    LoadMjcf(from_file, (dir / "disc.xml").string());
    EXPECT_LE(HullVertices(from_file), bound.empty() ? 2000 : 100) << bound;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace partsim
