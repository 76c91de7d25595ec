// The scene's render world, ids, lights and backend choice.
#include "partsim/render/scene_render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"
#include "render/render_test_util.h"

namespace partsim {
namespace {

using testing::AddCrate;
using testing::AddLamp;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

class SceneRenderTest : public ::testing::Test {
 protected:
  void SetUp() override { SetRenderBackend(scene_, "null"); }
  Scene scene_;
};

// The pose of every instance is its body's pose composed with the visual's pose.
void ExpectInstancesFollowBodies(Scene& scene) {
  const RenderWorld& world = GetRenderWorld(scene);
  std::map<uint32_t, RenderVisualInfo> visuals;
  for (const RenderVisualInfo& v : GetRenderVisuals(scene)) visuals[v.id] = v;
  std::map<uint32_t, RenderEntityInfo> entities;
  for (const RenderEntityInfo& e : GetRenderEntities(scene)) entities[e.id] = e;
  for (const RenderInstance& inst : world.instances) {
    ASSERT_TRUE(entities.count(inst.entity_id)) << inst.entity_id;
    ASSERT_TRUE(visuals.count(inst.visual_id)) << inst.visual_id;
    EXPECT_EQ(visuals[inst.visual_id].entity_id, inst.entity_id);
    const RenderEntityInfo& e = entities[inst.entity_id];
    Pose X_WB;
    const BodyDesc* body;
    if (e.is_link) {
      Link link = scene.FindArticulationByName(e.articulation_name).GetLink(e.link_index);
      X_WB = link.GetPose();
      body = &link.GetDesc();
    } else {
      Actor actor(&scene, e.actor_id);
      X_WB = actor.GetPose();
      body = &actor.GetDesc();
    }
    // find the visual by name in its body
    const VisualShape* visual = nullptr;
    for (const VisualShape& v : body->visuals)
      if (v.name == visuals[inst.visual_id].name) visual = &v;
    ASSERT_NE(visual, nullptr);
    Eigen::Matrix4d expected = (X_WB * visual->pose).ToMatrix();
    EXPECT_LT((inst.X_WV - expected).norm(), 1e-9) << visual->name;
  }
}

TEST_F(SceneRenderTest, InstancesFollowBodiesAndIdsNameThem) {
  scene_.AddGround();
  Articulation lamp = AddLamp(scene_);
  Actor crate = AddCrate(scene_, Eigen::Vector3d(1, 1, 0.5));
  UpdateRender(scene_);
  const RenderWorld& world = GetRenderWorld(scene_);
  // ground 1 + crate 1 + lamp 2 + 2
  ASSERT_EQ(world.instances.size(), 6u);
  ExpectInstancesFollowBodies(scene_);

  // move things: the arm turns, the crate falls
  lamp.SetQpos(Eigen::VectorXd::Constant(1, 1.1));
  scene_.Step(50);
  UpdateRender(scene_);
  ExpectInstancesFollowBodies(scene_);

  // ids are unique and name the right things
  std::set<uint32_t> visual_ids, entity_ids;
  for (const RenderInstance& inst : world.instances) {
    EXPECT_GE(inst.visual_id, 1u);
    EXPECT_GE(inst.entity_id, 1u);
    EXPECT_TRUE(visual_ids.insert(inst.visual_id).second);
    entity_ids.insert(inst.entity_id);
  }
  EXPECT_EQ(entity_ids.size(), 4u);  // ground, base, arm, crate
  std::map<std::string, RenderEntityInfo> by_name;
  for (const RenderEntityInfo& e : GetRenderEntities(scene_)) by_name[e.name] = e;
  ASSERT_EQ(by_name.size(), 4u);
  EXPECT_FALSE(by_name["ground"].is_link);
  EXPECT_FALSE(by_name["crate"].is_link);
  EXPECT_EQ(by_name["crate"].actor_id, crate.GetId());
  EXPECT_EQ(by_name["crate"].semantic_label, "box");
  EXPECT_TRUE(by_name["arm"].is_link);
  EXPECT_EQ(by_name["arm"].articulation_name, "lamp");
  EXPECT_EQ(by_name["arm"].articulation_id, lamp.GetId());
  EXPECT_EQ(by_name["arm"].link_index, 1);
  EXPECT_EQ(by_name["arm"].semantic_label, "lid");
  EXPECT_EQ(by_name["base"].semantic_label, "body");
  std::map<std::string, RenderVisualInfo> visual_by_name;
  for (const RenderVisualInfo& v : GetRenderVisuals(scene_)) visual_by_name[v.name] = v;
  EXPECT_EQ(visual_by_name["bulb"].entity_id, by_name["arm"].id);
  EXPECT_EQ(visual_by_name["post"].entity_id, by_name["base"].id);
  EXPECT_EQ(visual_by_name["lid_panel"].entity_id, by_name["crate"].id);
  // materials travel with the instances
  for (const RenderInstance& inst : world.instances)
    if (inst.visual_id == visual_by_name["bulb"].id)
      EXPECT_EQ(inst.material.base_color, Eigen::Vector4f(0.2f, 0.4f, 0.6f, 1.0f));
}

TEST_F(SceneRenderTest, GroundIsALargeSquare) {
  scene_.AddGround(0.25);
  UpdateRender(scene_);
  const RenderWorld& world = GetRenderWorld(scene_);
  ASSERT_EQ(world.instances.size(), 1u);
  const MeshData& m = *world.instances[0].mesh;
  ASSERT_EQ(m.faces.size(), 2u);
  Eigen::Vector3f lo = m.vertices[0], hi = m.vertices[0];
  for (const Eigen::Vector3f& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  EXPECT_FLOAT_EQ(hi.x() - lo.x(), 20.0f);
  EXPECT_FLOAT_EQ(hi.y() - lo.y(), 20.0f);
  EXPECT_NEAR(world.instances[0].X_WV(2, 3), 0.25, 1e-12);
}

TEST_F(SceneRenderTest, GeometryVersionChangesOnlyWithMeshesOrMaterials) {
  Actor crate = AddCrate(scene_, Eigen::Vector3d(0, 0, 1));
  UpdateRender(scene_);
  const RenderWorld& world = GetRenderWorld(scene_);
  uint64_t v0 = world.geometry_version;
  std::shared_ptr<const MeshData> mesh = world.instances.at(0).mesh;
  // poses only
  scene_.Step(20);
  UpdateRender(scene_);
  EXPECT_EQ(world.geometry_version, v0);
  // a recompile that changes no geometry (timestep) keeps the version and the mesh
  scene_.SetTimestep(0.001);
  UpdateRender(scene_);
  EXPECT_EQ(world.geometry_version, v0);
  EXPECT_EQ(world.instances.at(0).mesh, mesh);
  // a new actor with the same primitive shares its mesh
  Actor crate2 = AddCrate(scene_, Eigen::Vector3d(2, 0, 1), "crate2");
  UpdateRender(scene_);
  EXPECT_NE(world.geometry_version, v0);
  ASSERT_EQ(world.instances.size(), 2u);
  EXPECT_EQ(world.instances[1].mesh, mesh);
  // removing an actor removes its instances
  uint64_t v1 = world.geometry_version;
  scene_.RemoveActor(crate);
  UpdateRender(scene_);
  EXPECT_NE(world.geometry_version, v1);
  ASSERT_EQ(world.instances.size(), 1u);
  EXPECT_EQ(world.instances[0].entity_id, GetRenderEntities(scene_).at(0).id);
  EXPECT_EQ(GetRenderEntities(scene_).at(0).name, "crate2");
  EXPECT_EQ(world.instances[0].mesh, mesh);
}

TEST_F(SceneRenderTest, LightsAreValidatedAndCopiedIntoTheWorld) {
  AddDirectionalLight(scene_, Eigen::Vector3d(0, 0, -2), Eigen::Vector3f(1, 1, 1), true);
  AddPointLight(scene_, Eigen::Vector3d(1, 2, 3), Eigen::Vector3f(2, 2, 2));
  AddSpotLight(scene_, Eigen::Vector3d(0, 0, 3), Eigen::Vector3d(0, 0, -1), 0.2, 0.4,
               Eigen::Vector3f(5, 5, 5));
  SetAmbientLight(scene_, Eigen::Vector3f(0.3f, 0.3f, 0.3f));
  // refused: the light list stays as it was
  EXPECT_THROW(AddDirectionalLight(scene_, Eigen::Vector3d::Zero(), Eigen::Vector3f::Ones()),
               Error);
  EXPECT_THROW(AddPointLight(scene_, Eigen::Vector3d(kNaN, 0, 0), Eigen::Vector3f::Ones()), Error);
  EXPECT_THROW(AddPointLight(scene_, Eigen::Vector3d::Zero(), Eigen::Vector3f(-1, 0, 0)), Error);
  EXPECT_THROW(AddSpotLight(scene_, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.5, 0.3,
                            Eigen::Vector3f::Ones()),
               Error);
  EXPECT_THROW(AddSpotLight(scene_, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.1, 2.0,
                            Eigen::Vector3f::Ones()),
               Error);
  EXPECT_THROW(SetAmbientLight(scene_, Eigen::Vector3f(0, -1, 0)), Error);
  ASSERT_EQ(GetLights(scene_).size(), 3u);
  EXPECT_EQ(GetLights(scene_)[0].type, LightType::kDirectional);
  EXPECT_TRUE(GetLights(scene_)[0].shadow);
  EXPECT_LT((GetLights(scene_)[0].direction - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
  EXPECT_EQ(GetLights(scene_)[2].outer_angle, 0.4);
  UpdateRender(scene_);
  EXPECT_EQ(GetRenderWorld(scene_).lights.size(), 3u);
  EXPECT_EQ(GetRenderWorld(scene_).ambient, Eigen::Vector3f(0.3f, 0.3f, 0.3f));
}

TEST_F(SceneRenderTest, BackendsByName) {
  EXPECT_EQ(GetRenderBackend(scene_).Name(), "null");
  try {
    SetRenderBackend(scene_, "vulkan");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("rasterizer, pathtracer or null"), std::string::npos);
  }
  // the refused name kept the backend
  EXPECT_EQ(GetRenderBackend(scene_).Name(), "null");
  EXPECT_THROW(SetRenderBackend(scene_, std::unique_ptr<RenderBackend>()), Error);
  SetRenderBackend(scene_, std::make_unique<testing::PlaneBackend>());
  EXPECT_EQ(GetRenderBackend(scene_).Name(), "test-plane");
}

}  // namespace
}  // namespace partsim
