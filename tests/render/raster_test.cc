// Rasterizer tests: invariants of the pictures (colours, exact albedo, depth back-projected onto
// the true surface, normals, ids, shadows, spot cones, textures, custom shaders, errors). They run
// on whatever EGL device there is, Mesa's llvmpipe included.
#include <gtest/gtest.h>
#include <png.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <future>
#include <memory>
#include <set>
#include <sstream>
#include <string>

#include "partsim/core/constants.h"
#include "partsim/core/error.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera_math.h"
#include "render/jpeg_test_util.h"
#include "render/raster/shadows.h"

namespace partsim {
namespace {

// a box of half sizes h centred at the origin, 12 triangles counter-clockwise from outside,
// without normals (the backend computes flat ones)
std::shared_ptr<MeshData> Box(const Eigen::Vector3f& h) {
  auto m = std::make_shared<MeshData>();
  for (int i = 0; i < 8; ++i) {
    m->vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                             (i & 4) ? h.z() : -h.z());
  }
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& q : quads) {
    m->faces.emplace_back(q[0], q[1], q[2]);
    m->faces.emplace_back(q[0], q[2], q[3]);
  }
  return m;
}

// a square of half size s in the xy plane facing +z, with per-vertex normals and uvs
// (u along x, v along y, (0, 0) at the -x -y corner)
std::shared_ptr<MeshData> Quad(float s) {
  auto m = std::make_shared<MeshData>();
  m->vertices = {{-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}};
  m->normals.assign(4, Eigen::Vector3f::UnitZ());
  m->uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m->faces = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

RenderInstance Instance(std::shared_ptr<MeshData> mesh, const Eigen::Vector3d& p,
                        const Eigen::Vector4f& color, uint32_t visual_id, uint32_t entity_id,
                        const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  RenderInstance inst;
  inst.mesh = std::move(mesh);
  inst.material.base_color = color;
  inst.X_WV.topLeftCorner<3, 3>() = R;
  inst.X_WV.topRightCorner<3, 1>() = p;
  inst.visual_id = visual_id;
  inst.entity_id = entity_id;
  return inst;
}

// a quad's rotation such that it faces a camera looking along +x: the quad's u runs to the right
// of the image (-y of the world) and v upwards (+z)
Eigen::Matrix3d FacingCamera() {
  Eigen::Matrix3d R_WP;
  R_WP.col(0) = -Eigen::Vector3d::UnitY();
  R_WP.col(1) = Eigen::Vector3d::UnitZ();
  R_WP.col(2) = -Eigen::Vector3d::UnitX();
  return R_WP;
}

// a camera at the origin looking along +x (partsim's x forward, y left, z up)
CameraParams Camera(int w, int h, const Pose& X_WC = Pose(), double fovy = 1.0) {
  return MakeCameraParams(w, h, IntrinsicsFromFovy(w, h, fovy), 0.05, 50.0, X_WC);
}

// a camera above the point p looking straight down, image up = +x of the world
CameraParams CameraAbove(int w, int h, const Eigen::Vector3d& p, double fovy = 1.0) {
  return Camera(w, h,
                Pose(p, Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY()))),
                fovy);
}

// pixel (u, v) of a world point
Eigen::Vector2d Project(const CameraParams& cam, const Eigen::Vector3d& p_W) {
  Eigen::Vector3d p_O = RotationCameraToCv().transpose() * cam.X_WC.Inverse().Transform(p_W);
  Eigen::Vector3d uv = cam.K * (p_O / p_O.z());
  return uv.head<2>();
}

size_t Pixel(const Picture& pic, const Eigen::Vector2d& uv) {
  int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
  EXPECT_TRUE(u >= 0 && u < pic.width && v >= 0 && v < pic.height) << uv.transpose();
  return static_cast<size_t>(v) * pic.width + u;
}

Eigen::Vector4f Rgba(const std::vector<float>& img, size_t pixel) {
  return Eigen::Vector4f(img[4 * pixel], img[4 * pixel + 1], img[4 * pixel + 2],
                         img[4 * pixel + 3]);
}

LightDesc Directional(const Eigen::Vector3d& direction, bool shadow = false) {
  LightDesc l;
  l.type = LightType::kDirectional;
  l.direction = direction.normalized();
  l.color = Eigen::Vector3f::Constant(3.0f);
  l.shadow = shadow;
  return l;
}

// one backend for the whole suite: creating a context costs a little
RenderBackend& Backend() {
  static std::unique_ptr<RenderBackend> backend = MakeRasterBackend();
  return *backend;
}

std::string ReadFile(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(RasterTest, NameAndDevice) {
  EXPECT_EQ(Backend().Name(), "rasterizer");
  EXPECT_FALSE(Backend().Device().empty());
}

TEST(RasterTest, RedBoxIsRedWhereItProjectsAndBackgroundElsewhere) {
  RenderWorld world;
  world.instances.push_back(Instance(Box({0.1f, 0.1f, 0.1f}), {1, 0, 0}, {1, 0, 0, 1}, 3, 2));
  world.lights.push_back(Directional({1, 0.3, -0.5}));
  CameraParams cam = Camera(64, 48);
  Picture pic;
  Backend().Render(world, cam, &pic);
  ASSERT_EQ(pic.width, 64);
  ASSERT_EQ(pic.height, 48);
  ASSERT_EQ(pic.color.size(), 64u * 48 * 4);
  ASSERT_EQ(pic.segmentation.size(), 64u * 48 * 2);

  // the front face at x = 0.9 spans |y|, |z| < 0.1: inside and outside its projection
  int inside = 0, outside = 0;
  for (int v = 0; v < pic.height; ++v) {
    for (int u = 0; u < pic.width; ++u) {
      size_t i = static_cast<size_t>(v) * pic.width + u;
      Eigen::Vector3d ray = cam.K.inverse() * Eigen::Vector3d(u, v, 1);  // OpenCV
      // ray hits x = 0.9 at (0.9, -0.9 rx, -0.9 ry) in the world
      double y = -0.9 * ray.x(), z = -0.9 * ray.y();
      bool hit = std::abs(y) < 0.095 && std::abs(z) < 0.095;
      bool miss = std::abs(y) > 0.115 || std::abs(z) > 0.115;
      if (hit) {
        ++inside;
        EXPECT_EQ(Rgba(pic.albedo, i), Eigen::Vector4f(1, 0, 0, 1)) << u << "," << v;
        Eigen::Vector4f c = Rgba(pic.color, i);
        EXPECT_GT(c.x(), 0.2f);
        EXPECT_LT(c.y(), 0.1f * c.x());
        EXPECT_LT(c.z(), 0.1f * c.x());
        EXPECT_EQ(pic.segmentation[2 * i], 3u);
        EXPECT_EQ(pic.segmentation[2 * i + 1], 2u);
      } else if (miss) {
        ++outside;
        EXPECT_EQ(Rgba(pic.color, i), Eigen::Vector4f::Zero());
        EXPECT_EQ(Rgba(pic.albedo, i), Eigen::Vector4f::Zero());
        EXPECT_EQ(Rgba(pic.position, i), Eigen::Vector4f::Zero());
        EXPECT_EQ(Rgba(pic.normal, i), Eigen::Vector4f::Zero());
        EXPECT_EQ(pic.segmentation[2 * i], 0u);
        EXPECT_EQ(pic.segmentation[2 * i + 1], 0u);
      }
    }
  }
  EXPECT_GT(inside, 50);
  EXPECT_GT(outside, 1000);
}

// every pixel's depth, back-projected through K^-1 and the camera pose, lands on the plane; the
// position output agrees with it and the normal output is the plane's normal in the GL frame
void CheckTiltedPlane(const Pose& X_WC, const Eigen::Matrix3d& R_WP, const Eigen::Vector3d& c_W) {
  RenderWorld world;
  world.instances.push_back(Instance(Quad(5.0f), c_W, {0.5, 0.6, 0.7, 1}, 1, 1, R_WP));
  world.lights.push_back(Directional({1, 0, -1}));
  CameraParams cam = Camera(80, 60, X_WC);
  Picture pic;
  Backend().Render(world, cam, &pic);
  Eigen::Vector3d n_W = R_WP.col(2);
  Eigen::Matrix3d R_WO = X_WC.q.toRotationMatrix() * RotationCameraToCv();
  Eigen::Vector3d n_G = cam.view.topLeftCorner<3, 3>() * n_W;
  double max_plane_error = 0, max_position_error = 0, max_normal_error = 0;
  int seen = 0;
  for (int v = 0; v < pic.height; ++v) {
    for (int u = 0; u < pic.width; ++u) {
      size_t i = static_cast<size_t>(v) * pic.width + u;
      Eigen::Vector4f pos = Rgba(pic.position, i);
      ASSERT_GT(pos.w(), 0.0f) << "pixel " << u << "," << v << " sees nothing";
      ++seen;
      Eigen::Vector3d p_O = pos.w() * (cam.K.inverse() * Eigen::Vector3d(u, v, 1));
      Eigen::Vector3d p_W = X_WC.p + R_WO * p_O;
      max_plane_error = std::max(max_plane_error, std::abs(n_W.dot(p_W - c_W)));
      Eigen::Vector3d p_G(p_O.x(), -p_O.y(), -p_O.z());
      max_position_error =
          std::max(max_position_error, (pos.head<3>().cast<double>() - p_G).norm());
      Eigen::Vector3d n = Rgba(pic.normal, i).head<3>().cast<double>();
      max_normal_error = std::max(max_normal_error, (n - n_G).norm());
      EXPECT_EQ(pic.normal[4 * i + 3], 0.0f);
    }
  }
  EXPECT_EQ(seen, pic.width * pic.height);
  EXPECT_LT(max_plane_error, 1e-3);
  EXPECT_LT(max_position_error, 1e-4);
  EXPECT_LT(max_normal_error, 1e-3);
}

TEST(RasterTest, DepthBackProjectsOntoTiltedPlane) {
  // plane through (1, 0, 0), turned 30 degrees about z, then 20 about y, facing the camera
  Eigen::Matrix3d R_WP = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                          Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitY()) *
                          Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitY()))
                             .toRotationMatrix();
  CheckTiltedPlane(Pose(), R_WP, {1, 0, 0});
  // and from a camera that is itself turned and moved
  Pose X_WC({0.2, -0.3, 0.1},
            Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(-0.15, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX())));
  CheckTiltedPlane(X_WC, R_WP, {1.1, -0.2, 0.2});
}

TEST(RasterTest, DepthOfBoxFaceAndNormalsOfSides) {
  // a box seen from above and aside: its top face at z = 0.2 and its front face at x = 0.8
  RenderWorld world;
  world.instances.push_back(Instance(Box({0.2f, 0.3f, 0.2f}), {1, 0, 0}, {0.8, 0.8, 0.8, 1}, 1, 1));
  Pose X_WC({0, 0, 0.8}, Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitY())));
  CameraParams cam = Camera(96, 96, X_WC, 1.2);
  Picture pic;
  Backend().Render(world, cam, &pic);
  Eigen::Matrix3d R_WO = X_WC.q.toRotationMatrix() * RotationCameraToCv();
  Eigen::Matrix3d R_GW = cam.view.topLeftCorner<3, 3>();
  int top = 0, front = 0;
  for (int v = 0; v < pic.height; ++v) {
    for (int u = 0; u < pic.width; ++u) {
      size_t i = static_cast<size_t>(v) * pic.width + u;
      float depth = pic.position[4 * i + 3];
      if (depth <= 0) continue;
      Eigen::Vector3d p_W = X_WC.p + R_WO * (depth * (cam.K.inverse() * Eigen::Vector3d(u, v, 1)));
      Eigen::Vector3d n_G = Rgba(pic.normal, i).head<3>().cast<double>();
      // away from the edge, the point is on the face whose normal the pixel reports
      bool inner = std::abs(p_W.y()) < 0.29;
      if (inner && (n_G - R_GW * Eigen::Vector3d::UnitZ()).norm() < 1e-3) {
        if (p_W.x() > 0.81 && p_W.x() < 1.19) {
          EXPECT_NEAR(p_W.z(), 0.2, 1e-3);
          ++top;
        }
      } else if (inner && (n_G + R_GW * Eigen::Vector3d::UnitX()).norm() < 1e-3) {
        if (p_W.z() > -0.19 && p_W.z() < 0.19) {
          EXPECT_NEAR(p_W.x(), 0.8, 1e-3);
          ++front;
        }
      }
    }
  }
  EXPECT_GT(top, 100);
  EXPECT_GT(front, 100);
}

TEST(RasterTest, SegmentationIdsOfEachInstance) {
  RenderWorld world;
  world.instances.push_back(Instance(Box({0.1f, 0.1f, 0.1f}), {1, 0.25, 0}, {1, 0, 0, 1}, 7, 4));
  world.instances.push_back(Instance(Box({0.1f, 0.1f, 0.1f}), {1, -0.25, 0}, {0, 1, 0, 1}, 9, 5));
  CameraParams cam = Camera(64, 64);
  Picture pic;
  Backend().Render(world, cam, &pic);
  size_t a = Pixel(pic, Project(cam, {0.9, 0.25, 0}));
  size_t b = Pixel(pic, Project(cam, {0.9, -0.25, 0}));
  size_t bg = Pixel(pic, Project(cam, {0.9, 0, 0}));
  EXPECT_EQ(pic.segmentation[2 * a], 7u);
  EXPECT_EQ(pic.segmentation[2 * a + 1], 4u);
  EXPECT_EQ(pic.segmentation[2 * b], 9u);
  EXPECT_EQ(pic.segmentation[2 * b + 1], 5u);
  EXPECT_EQ(pic.segmentation[2 * bg], 0u);
  EXPECT_EQ(pic.segmentation[2 * bg + 1], 0u);
  // left in the world (+y) is left in the image
  EXPECT_LT(Project(cam, {0.9, 0.25, 0}).x(), 32);
  EXPECT_EQ(Rgba(pic.albedo, a), Eigen::Vector4f(1, 0, 0, 1));
  EXPECT_EQ(Rgba(pic.albedo, b), Eigen::Vector4f(0, 1, 0, 1));
}

// mean pixel column and row of an id
Eigen::Vector2d Centroid(const Picture& pic, uint32_t id) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int n = 0;
  for (int v = 0; v < pic.height; ++v) {
    for (int u = 0; u < pic.width; ++u) {
      if (pic.segmentation[2 * (static_cast<size_t>(v) * pic.width + u)] == id) {
        sum += Eigen::Vector2d(u, v);
        ++n;
      }
    }
  }
  EXPECT_GT(n, 0);
  return sum / std::max(n, 1);
}

TEST(RasterTest, MovingAnInstanceMovesItsPixels) {
  RenderWorld world;
  world.instances.push_back(Instance(Box({0.1f, 0.1f, 0.1f}), {1, 0, 0}, {1, 1, 1, 1}, 1, 1));
  world.geometry_version = 1;
  CameraParams cam = Camera(64, 64);
  Picture before, after;
  Backend().Render(world, cam, &before);
  Eigen::Vector2d c0 = Centroid(before, 1);
  EXPECT_NEAR(c0.x(), 31.5, 0.5);
  EXPECT_NEAR(c0.y(), 31.5, 0.5);
  // move left (+y) and up (+z) by 0.2 m: same geometry version, only the pose changed
  world.instances[0].X_WV(1, 3) = 0.2;
  world.instances[0].X_WV(2, 3) = 0.2;
  Backend().Render(world, cam, &after);
  Eigen::Vector2d c1 = Centroid(after, 1);
  Eigen::Vector2d expected = Project(cam, {0.9, 0.2, 0.2});
  EXPECT_LT(c1.x(), c0.x() - 10);
  EXPECT_LT(c1.y(), c0.y() - 10);
  EXPECT_NEAR(c1.x(), expected.x(), 2.0);
  EXPECT_NEAR(c1.y(), expected.y(), 2.0);
}

TEST(RasterTest, PictureSizeFollowsTheCamera) {
  RenderWorld world;
  world.instances.push_back(Instance(Box({0.1f, 0.1f, 0.1f}), {1, 0, 0}, {1, 1, 1, 1}, 1, 1));
  Picture pic;
  for (auto [w, h] : {std::pair{32, 16}, std::pair{50, 70}, std::pair{33, 17}}) {
    CameraParams cam = Camera(w, h);
    Backend().Render(world, cam, &pic);
    ASSERT_EQ(pic.width, w);
    ASSERT_EQ(pic.height, h);
    ASSERT_EQ(pic.position.size(), static_cast<size_t>(w) * h * 4);
    ASSERT_EQ(pic.segmentation.size(), static_cast<size_t>(w) * h * 2);
    // the box is in the middle of every picture
    Eigen::Vector2d c = Centroid(pic, 1);
    EXPECT_NEAR(c.x(), (w - 1) / 2.0, 0.51);
    EXPECT_NEAR(c.y(), (h - 1) / 2.0, 0.51);
  }
}

// a ground plane with a box on it, seen from above; light travels along +x and down
RenderWorld ShadowWorld(bool shadow) {
  RenderWorld world;
  world.instances.push_back(Instance(Quad(3.0f), {1.5, 0, 0}, {0.8, 0.8, 0.8, 1}, 1, 1));
  world.instances.push_back(
      Instance(Box({0.1f, 0.1f, 0.1f}), {1.5, 0, 0.1}, {0.8, 0.8, 0.8, 1}, 2, 2));
  world.lights.push_back(Directional({1, 0, -1}, shadow));
  world.ambient = Eigen::Vector3f::Constant(0.05f);
  return world;
}

TEST(RasterTest, DirectionalShadowDarkensTheGroundBehindTheBox) {
  CameraParams cam = CameraAbove(96, 96, {1.5, 0, 2});
  Picture lit, shadowed;
  Backend().Render(ShadowWorld(false), cam, &lit);
  Backend().Render(ShadowWorld(true), cam, &shadowed);
  // behind the box (x from 1.6 to 1.8 at 45 degrees) and in front of it
  size_t behind = Pixel(lit, Project(cam, {1.7, 0, 0}));
  size_t front = Pixel(lit, Project(cam, {1.3, 0, 0}));
  size_t side = Pixel(lit, Project(cam, {1.7, 0.4, 0}));
  float lit_behind = lit.color[4 * behind], dark_behind = shadowed.color[4 * behind];
  EXPECT_GT(lit_behind, 0.3f);
  EXPECT_LT(dark_behind, 0.3f * lit_behind);
  EXPECT_NEAR(shadowed.color[4 * front], lit.color[4 * front], 1e-4);
  EXPECT_NEAR(shadowed.color[4 * side], lit.color[4 * side], 1e-4);
  // the box's own top is lit in both
  size_t top = Pixel(lit, Project(cam, {1.5, 0, 0.2}));
  EXPECT_NEAR(shadowed.color[4 * top], lit.color[4 * top], 1e-4);
  EXPECT_GT(lit.color[4 * top], 0.3f);
}

// A fresh backend draws unshadowed pictures with a 1 x 1 stand-in for the shadow maps, and makes
// the maps at its first shadowed picture: the unshadowed picture is the same before and after.
TEST(RasterTest, ShadowMapsAreMadeAtTheFirstShadowedPicture) {
  std::unique_ptr<RenderBackend> fresh = MakeRasterBackend();
  CameraParams cam = CameraAbove(64, 64, {1.5, 0, 2});
  Picture before, shadowed, after;
  fresh->Render(ShadowWorld(false), cam, &before);
  fresh->Render(ShadowWorld(true), cam, &shadowed);
  fresh->Render(ShadowWorld(false), cam, &after);
  EXPECT_EQ(before.color, after.color);
  const size_t behind = Pixel(before, Project(cam, {1.7, 0, 0}));
  EXPECT_LT(shadowed.color[4 * behind], 0.3f * before.color[4 * behind]);
}

// a spot light above ShadowWorld's box, with a shadow
LightDesc SpotAbove() {
  LightDesc spot;
  spot.type = LightType::kSpot;
  spot.position = {1.5, 0.3, 1.5};
  spot.direction = Eigen::Vector3d(0, -0.2, -1).normalized();
  spot.inner_angle = 0.5;
  spot.outer_angle = 0.6;
  spot.color = Eigen::Vector3f::Constant(2.0f);
  spot.shadow = true;
  return spot;
}

// the picture a backend that never drew anything else draws
Picture FreshPicture(const RenderWorld& world, const CameraParams& cam, unsigned outputs,
                     const RasterOptions& options = RasterOptions()) {
  Picture pic;
  MakeRasterBackend(options)->Render(world, cam, &pic, outputs);
  return pic;
}

// Shadow maps are drawn again only when what they hold would change: a still scene reuses them,
// a moved caster or light or (for the sun) a moved camera draws them again, and every picture is
// the one a fresh backend draws, to the bit, on the deferred and the forward path.
TEST(RasterTest, ShadowMapsAreKeptWhileNothingTheyHoldMoves) {
  for (unsigned outputs : {unsigned{kAllOutputs}, unsigned{kColor | kPosition}}) {
    SCOPED_TRACE(outputs);
    std::unique_ptr<RenderBackend> backend = MakeRasterBackend();
    RenderWorld world = ShadowWorld(true);
    world.lights.push_back(SpotAbove());
    CameraParams cam = CameraAbove(64, 64, {1.5, 0, 2});
    auto render = [&](const CameraParams& c) {
      Picture pic;
      backend->Render(world, c, &pic, outputs);
      EXPECT_EQ(pic.color, FreshPicture(world, c, outputs).color);
      return pic;
    };
    auto counters = [&] {
      RenderCounters n = backend->Counters();
      return std::make_pair(n.shadow_layers_drawn, n.shadow_layers_reused);
    };
    Picture first = render(cam);
    EXPECT_EQ(counters(), std::make_pair(uint64_t{2}, uint64_t{0}));
    render(cam);  // nothing moved: both maps kept
    EXPECT_EQ(counters(), std::make_pair(uint64_t{2}, uint64_t{2}));
    // the box moves: both maps again, and the shadow with it
    world.instances[1].X_WV(1, 3) = 0.3;
    Picture moved = render(cam);
    EXPECT_NE(moved.color, first.color);
    EXPECT_EQ(counters(), std::make_pair(uint64_t{4}, uint64_t{2}));
    world.instances[1].X_WV(1, 3) = 0.0;
    EXPECT_EQ(render(cam).color, first.color);
    EXPECT_EQ(counters(), std::make_pair(uint64_t{6}, uint64_t{2}));
    // the camera moves and still sees the whole scene: the sun's map covers the scene's box
    // cut by the view's, the same box, and the spot light's does not depend on the view
    render(CameraAbove(64, 64, {1.6, 0.1, 2.2}));
    EXPECT_EQ(counters(), std::make_pair(uint64_t{6}, uint64_t{4}));
    // the spot light turns: its map alone
    world.lights[1].direction = Eigen::Vector3d(0.2, -0.2, -1).normalized();
    render(cam);
    EXPECT_EQ(counters(), std::make_pair(uint64_t{7}, uint64_t{5}));
    // a camera that sees part of the scene: the sun's map fits that part, the spot's is kept
    CameraParams close = CameraAbove(64, 64, {1.5, 0, 0.6});
    close = MakeCameraParams(64, 64, close.K, close.near, 1.0, close.X_WC);
    render(close);
    EXPECT_EQ(counters(), std::make_pair(uint64_t{8}, uint64_t{6}));
    // a picture without colour draws no map and keeps them
    Picture depth_only;
    backend->Render(world, cam, &depth_only, kPosition);
    EXPECT_EQ(counters(), std::make_pair(uint64_t{8}, uint64_t{6}));
    EXPECT_EQ(backend->Counters().pictures, 8u);
  }
}

// RenderMany (a camera set in one submission, read back through pixel-pack buffers) gives each
// camera the picture Render gives it, to the bit: forward and deferred outputs, cameras of
// different sizes, a shadowed sun and spot, and Segmentation read back as 16-bit numbers when
// every id fits and as 32-bit ones when one does not.
TEST(RasterTest, RenderManyGivesEachCameraItsPicture) {
  RenderWorld world = ShadowWorld(true);
  world.lights.push_back(SpotAbove());
  const std::vector<CameraParams> cameras = {CameraAbove(64, 64, {1.5, 0, 2}),
                                             CameraAbove(96, 48, {1.6, 0.1, 2.2}),
                                             CameraAbove(64, 64, {1.4, -0.2, 1.8})};
  RenderWorld wide = world;  // ids beyond 16 bits
  wide.instances[1].visual_id = 70000;
  wide.instances[1].entity_id = 123456;
  for (const RenderWorld* w : {&world, &wide}) {
    for (unsigned outputs : {unsigned{kAllOutputs}, unsigned{kColor | kPosition},
                             unsigned{kSegmentation | kNormal}, unsigned{kPosition}}) {
      SCOPED_TRACE(outputs);
      std::unique_ptr<RenderBackend> one = MakeRasterBackend(), many = MakeRasterBackend();
      std::vector<Picture> pictures(cameras.size());
      std::vector<Picture*> out;
      for (Picture& p : pictures) out.push_back(&p);
      many->RenderMany(*w, cameras, out, outputs);
      for (size_t i = 0; i < cameras.size(); ++i) {
        Picture expected;
        one->Render(*w, cameras[i], &expected, outputs);
        EXPECT_EQ(pictures[i].outputs, outputs);
        EXPECT_EQ(pictures[i].width, cameras[i].width);
        EXPECT_EQ(pictures[i].color, expected.color);
        EXPECT_EQ(pictures[i].albedo, expected.albedo);
        EXPECT_EQ(pictures[i].normal, expected.normal);
        EXPECT_EQ(pictures[i].position, expected.position);
        EXPECT_EQ(pictures[i].segmentation, expected.segmentation);
      }
      EXPECT_EQ(many->Counters().pictures, cameras.size());
      if (w == &wide && (outputs & kSegmentation)) {
        // the wide ids came back whole
        bool seen = false;
        for (size_t k = 0; k < pictures[0].segmentation.size(); k += 2)
          seen = seen || (pictures[0].segmentation[k] == 70000 &&
                          pictures[0].segmentation[k + 1] == 123456);
        EXPECT_TRUE(seen);
      }
    }
  }
  // arguments are checked before anything is drawn; the error names the camera
  std::vector<Picture> two(2);
  std::vector<Picture*> out = {&two[0], &two[1]};
  two[0].outputs = kColor;
  EXPECT_THROW(Backend().RenderMany(world, cameras, out), Error);  // 3 cameras, 2 pictures
  std::vector<CameraParams> bad = {cameras[0], cameras[1]};
  bad[1].width = 0;
  try {
    Backend().RenderMany(world, bad, out);
    FAIL() << "a camera of width 0 was rendered";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("camera 1 of 2"), std::string::npos) << e.what();
  }
  EXPECT_EQ(two[0].outputs, unsigned{kColor});  // untouched
}

// With the built-in G-buffer shader the deferred path reads Position back as x, y, z (w = -z is
// set on the CPU): the same bytes as a backend given that shader as a custom one, which reads all
// four channels, alone and through RenderMany.
TEST(RasterTest, PositionReadAsXyzEqualsTheFourChannels) {
  const std::string dir = std::string(PARTSIM_SOURCE_DIR) + "/shaders/";
  RasterOptions custom;
  custom.gbuffer_fragment_shader =
      "#version 450 core\n" + ReadFile(dir + "surface.glsl") + ReadFile(dir + "gbuffer_main.glsl");
  std::unique_ptr<RenderBackend> four = MakeRasterBackend(custom), xyz = MakeRasterBackend();
  RenderWorld world = ShadowWorld(false);
  // high enough to see past the ground's edges
  const std::vector<CameraParams> cameras = {CameraAbove(48, 40, {1.5, 0, 8}),
                                             CameraAbove(32, 32, {1.2, 0.3, 9})};
  for (unsigned outputs : {unsigned{kAllOutputs}, unsigned{kPosition | kNormal}}) {
    std::vector<Picture> many(cameras.size());
    std::vector<Picture*> out = {&many[0], &many[1]};
    xyz->RenderMany(world, cameras, out, outputs);
    for (size_t i = 0; i < cameras.size(); ++i) {
      Picture a, b;
      four->Render(world, cameras[i], &a, outputs);
      xyz->Render(world, cameras[i], &b, outputs);
      ASSERT_EQ(a.position.size(), b.position.size());
      EXPECT_EQ(0, std::memcmp(a.position.data(), b.position.data(), a.position.size() * 4));
      EXPECT_EQ(0, std::memcmp(a.position.data(), many[i].position.data(), a.position.size() * 4));
      // both a surface and the background are in the picture
      int seen = 0, empty = 0;
      for (size_t k = 3; k < b.position.size(); k += 4) (b.position[k] > 0 ? seen : empty)++;
      EXPECT_GT(seen, 0);
      EXPECT_GT(empty, 0);
    }
  }
}

// shadow_map_size = 0 sizes the maps from the picture: the same shadow, drawn with maps of
// 512 texels for a 64 x 64 picture; 2048 for 1024 x 1024 and larger
TEST(RasterTest, AutomaticShadowMapSizeFollowsThePicture) {
  RasterOptions automatic;
  automatic.shadow_map_size = 0;
  RasterOptions fixed;
  fixed.shadow_map_size = 512;
  CameraParams cam = CameraAbove(64, 64, {1.5, 0, 2});
  EXPECT_EQ(FreshPicture(ShadowWorld(true), cam, kColor, automatic).color,
            FreshPicture(ShadowWorld(true), cam, kColor, fixed).color);
  Picture lit = FreshPicture(ShadowWorld(false), cam, kColor, automatic);
  Picture shadowed = FreshPicture(ShadowWorld(true), cam, kColor, automatic);
  const size_t behind = Pixel(lit, Project(cam, {1.7, 0, 0}));
  EXPECT_LT(shadowed.color[4 * behind], 0.3f * lit.color[4 * behind]);
  for (int side : {1, 64, 256}) EXPECT_EQ(internal::raster::ShadowMaps::AutoSize(side, 1), 512);
  EXPECT_EQ(internal::raster::ShadowMaps::AutoSize(300, 400), 1024);
  EXPECT_EQ(internal::raster::ShadowMaps::AutoSize(640, 480), 2048);
  EXPECT_EQ(internal::raster::ShadowMaps::AutoSize(4096, 4096), 2048);
  RasterOptions bad;
  bad.shadow_map_size = -1;
  EXPECT_THROW(MakeRasterBackend(bad), Error);
}

// A batch keeps the context current on its thread: the same pictures as outside one; another
// thread is refused while it lasts and renders once it has ended; batches nest; a backend made
// within the batch on the same thread (FreshPicture) takes the thread's context, and the batch's
// next picture takes its own back.
TEST(RasterTest, BatchKeepsTheContextOnItsThread) {
  std::unique_ptr<RenderBackend> backend = MakeRasterBackend();
  const RenderWorld world = ShadowWorld(true);
  const CameraParams cam = CameraAbove(48, 48, {1.5, 0, 2});
  Picture alone;
  backend->Render(world, cam, &alone);
  auto render_elsewhere = [&] {
    return std::async(std::launch::async,
                      [&] {
                        Picture pic;
                        backend->Render(world, cam, &pic);
                        return pic;
                      })
        .get();
  };
  {
    RenderBatch batch(*backend);
    for (int i = 0; i < 3; ++i) {
      Picture pic;
      backend->Render(world, cam, &pic);
      EXPECT_EQ(pic.color, alone.color);
      EXPECT_EQ(pic.segmentation, alone.segmentation);
    }
    {
      RenderBatch inner(*backend);
      Picture pic;
      backend->Render(world, cam, &pic, kColor | kPosition);
      EXPECT_EQ(pic.color, FreshPicture(world, cam, kColor | kPosition).color);
    }
    try {
      render_elsewhere();
      ADD_FAILURE() << "a picture from another thread during a batch did not throw";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("batch begun on another thread"), std::string::npos)
          << e.what();
    }
    // the batch goes on after the refusal
    Picture pic;
    backend->Render(world, cam, &pic);
    EXPECT_EQ(pic.color, alone.color);
  }
  EXPECT_EQ(render_elsewhere().color, alone.color);  // released: any thread renders
  EXPECT_THROW(backend->EndBatch(), Error);
  // a batch begun on another thread that ended there leaves the context free here
  std::async(std::launch::async, [&] { RenderBatch b(*backend); }).get();
  Picture here;
  backend->Render(world, cam, &here);
  EXPECT_EQ(here.color, alone.color);
}

TEST(RasterTest, SpotLightLightsInsideItsConeOnly) {
  CameraParams cam = CameraAbove(96, 96, {1.5, 0, 3});
  for (bool shadow : {false, true}) {
    RenderWorld world;
    world.instances.push_back(Instance(Quad(3.0f), {1.5, 0, 0}, {0.8, 0.8, 0.8, 1}, 1, 1));
    world.instances.push_back(
        Instance(Box({0.04f, 0.04f, 0.04f}), {1.5, 0.1, 0.5}, {0.8, 0.8, 0.8, 1}, 2, 2));
    LightDesc spot;
    spot.type = LightType::kSpot;
    spot.position = {1.5, 0, 1};
    spot.direction = {0, 0, -1};
    spot.inner_angle = 0.3;
    spot.outer_angle = 0.4;
    spot.color = Eigen::Vector3f::Constant(2.0f);
    spot.shadow = shadow;
    world.lights.push_back(spot);
    world.ambient.setZero();
    Picture pic;
    Backend().Render(world, cam, &pic);
    // tan(0.3) = 0.309, tan(0.4) = 0.423 at 1 m below the light
    float centre = pic.color[4 * Pixel(pic, Project(cam, {1.5, 0, 0}))];
    float inner = pic.color[4 * Pixel(pic, Project(cam, {1.5, -0.25, 0}))];
    float middle =
        pic.color[4 * Pixel(pic, Project(cam, {1.5 + 0.366 * 0.7071, 0.366 * 0.7071, 0}))];
    float outside = pic.color[4 * Pixel(pic, Project(cam, {1.5, -0.5, 0}))];
    float far_outside = pic.color[4 * Pixel(pic, Project(cam, {2.5, 1.0, 0}))];
    EXPECT_GT(centre, 0.3f);
    EXPECT_GT(inner, 0.5f * centre);
    EXPECT_GT(middle, 0.0f);
    EXPECT_LT(middle, inner);
    EXPECT_EQ(outside, 0.0f);
    EXPECT_EQ(far_outside, 0.0f);
    // the small box at (1.5, 0.1, 0.5) shadows the ground twice as far from the cone's axis, along
    // the ray from the light: (1.5, 0, 1) -> (1.5, 0.1, 0.5) -> (1.5, 0.2, 0)
    float under = pic.color[4 * Pixel(pic, Project(cam, {1.5, 0.2, 0}))];
    if (shadow) {
      EXPECT_LT(under, 0.1f * centre);
    } else {
      EXPECT_GT(under, 0.7f * centre);
    }
  }
}

TEST(RasterTest, CustomLightingShaderChangesTheColour) {
  RenderWorld world;
  world.instances.push_back(Instance(Box({0.1f, 0.1f, 0.1f}), {1, 0, 0}, {1, 0, 0, 1}, 1, 1));
  world.lights.push_back(Directional({1, 0.3, -0.5}));
  CameraParams cam = Camera(32, 32);
  RasterOptions options;
  options.lighting_fragment_shader = R"(#version 450 core
uniform sampler2D u_position;
layout(location = 0) out vec4 o_color;
void main() {
  float depth = texelFetch(u_position, ivec2(gl_FragCoord.xy), 0).w;
  o_color = depth > 0.0 ? vec4(0.0, 1.0, 0.0, 1.0) : vec4(0.0, 0.0, 1.0, 1.0);
}
)";
  std::unique_ptr<RenderBackend> custom = MakeRasterBackend(options);
  Picture pic;
  custom->Render(world, cam, &pic);
  size_t centre = 16 * 32 + 16;
  EXPECT_EQ(Rgba(pic.color, centre), Eigen::Vector4f(0, 1, 0, 1));
  EXPECT_EQ(Rgba(pic.color, 0), Eigen::Vector4f(0, 0, 1, 1));
  // other outputs are still those of the built-in G-buffer pass
  EXPECT_EQ(Rgba(pic.albedo, centre), Eigen::Vector4f(1, 0, 0, 1));
  EXPECT_EQ(pic.segmentation[2 * centre], 1u);
}

TEST(RasterTest, ShippedToonShaderCompilesAndBandsTheColour) {
  std::string source =
      ReadFile(std::string(PARTSIM_SOURCE_DIR) + "/shaders/example_toon/lighting.frag");
  ASSERT_FALSE(source.empty());
  RasterOptions options;
  options.lighting_fragment_shader = source;
  std::unique_ptr<RenderBackend> toon = MakeRasterBackend(options);
  // a sphere-like gradient: a tilted plane lit at grazing angles has smoothly varying shading
  // under the built-in shader, and few distinct levels under the toon one
  RenderWorld world;
  Eigen::Matrix3d R_WP(Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitY()));
  world.instances.push_back(Instance(Quad(2.0f), {1, 0, 0}, {0.2, 0.4, 0.9, 1}, 1, 1, R_WP));
  LightDesc point;
  point.type = LightType::kPoint;
  point.position = {0.7, 0.4, 0.2};
  point.color = Eigen::Vector3f::Constant(0.3f);
  world.lights.push_back(point);
  CameraParams cam = Camera(64, 64);
  Picture plain, banded;
  Backend().Render(world, cam, &plain);
  toon->Render(world, cam, &banded);
  std::set<float> plain_levels, toon_levels;
  for (size_t i = 0; i < 64 * 64; ++i) {
    plain_levels.insert(plain.color[4 * i + 2]);
    toon_levels.insert(banded.color[4 * i + 2]);
  }
  EXPECT_GT(plain_levels.size(), 100u);
  EXPECT_LE(toon_levels.size(), 8u);
}

TEST(RasterTest, BrokenShaderThrowsNamingThePass) {
  RasterOptions lighting;
  lighting.lighting_fragment_shader = "#version 450 core\nvoid main() { this is not glsl; }\n";
  try {
    MakeRasterBackend(lighting);
    FAIL() << "a broken lighting shader was accepted";
  } catch (const Error& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("lighting pass"), std::string::npos) << what;
    EXPECT_NE(what.find("compile"), std::string::npos) << what;
  }
  RasterOptions gbuffer;
  gbuffer.gbuffer_fragment_shader = "#version 450 core\nout vec4 c;\nvoid main() { c = x; }\n";
  try {
    MakeRasterBackend(gbuffer);
    FAIL() << "a broken G-buffer shader was accepted";
  } catch (const Error& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("gbuffer pass"), std::string::npos) << what;
  }
  // compiles, but the vertex output the fragment shader reads does not exist: link error
  RasterOptions link;
  link.gbuffer_vertex_shader =
      "#version 450 core\nlayout(location = 0) in vec3 a_position;\nvoid main() { gl_Position = "
      "vec4(a_position, 1.0); }\n";
  link.gbuffer_fragment_shader =
      "#version 450 core\nin vec3 v_missing;\nout vec4 c;\nvoid main() { c = vec4(v_missing, 1.0); "
      "}\n";
  try {
    MakeRasterBackend(link);
    // some drivers link it anyway (the input reads as undefined)
  } catch (const Error& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("gbuffer pass"), std::string::npos) << what;
    EXPECT_NE(what.find("link"), std::string::npos) << what;
  }
}

TEST(RasterTest, MissingTextureThrowsNamingTheFile) {
  RenderWorld world;
  world.instances.push_back(Instance(Quad(0.5f), {1, 0, 0}, {1, 1, 1, 1}, 1, 1, FacingCamera()));
  world.instances[0].material.diffuse_texture = "/nonexistent/partsim_missing_texture.png";
  Picture pic;
  try {
    Backend().Render(world, Camera(16, 16), &pic);
    FAIL() << "a missing texture was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/partsim_missing_texture.png"),
              std::string::npos)
        << e.what();
  }
  // the backend stays usable
  world.instances[0].material.diffuse_texture.clear();
  Backend().Render(world, Camera(16, 16), &pic);
  EXPECT_EQ(pic.segmentation[2 * (8 * 16 + 8)], 1u);
}

void WriteRgbPng(const std::string& path, int w, int h, const std::vector<uint8_t>& rgb) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = w;
  image.height = h;
  image.format = PNG_FORMAT_RGB;
  ASSERT_TRUE(png_image_write_to_file(&image, path.c_str(), 0, rgb.data(), 0, nullptr));
}

TEST(RasterTest, TexturedQuadShowsTheTextureColours) {
  // 4 x 4 texels in 2 x 2 blocks: top red, green; bottom blue, white (row 0 at the top of the
  // file), so that filtering around the centre of a block sees one colour
  std::string path = ::testing::TempDir() + "/partsim_raster_texture.png";
  const uint8_t block[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 255}};
  std::vector<uint8_t> rgb;
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      const uint8_t* c = block[(y / 2) * 2 + x / 2];
      rgb.insert(rgb.end(), c, c + 3);
    }
  }
  WriteRgbPng(path, 4, 4, rgb);
  RenderWorld world;
  world.instances.push_back(Instance(Quad(0.2f), {1, 0, 0}, {1, 1, 1, 1}, 1, 1, FacingCamera()));
  world.instances[0].material.diffuse_texture = path;
  world.ambient = Eigen::Vector3f::Ones();
  CameraParams cam = Camera(64, 64);
  Picture pic;
  Backend().Render(world, cam, &pic);
  // centres of the four texels, uv (0.25 | 0.75, 0.25 | 0.75); v = 0 is the bottom of the image
  auto albedo_at = [&](double y, double z) {
    return Rgba(pic.albedo, Pixel(pic, Project(cam, {0.999, y, z})));
  };
  auto near = [](const Eigen::Vector4f& a, const Eigen::Vector4f& b) {
    return (a - b).cwiseAbs().maxCoeff() < 0.05f;
  };
  EXPECT_TRUE(near(albedo_at(0.1, 0.1), {1, 0, 0, 1})) << albedo_at(0.1, 0.1).transpose();
  EXPECT_TRUE(near(albedo_at(-0.1, 0.1), {0, 1, 0, 1})) << albedo_at(-0.1, 0.1).transpose();
  EXPECT_TRUE(near(albedo_at(0.1, -0.1), {0, 0, 1, 1})) << albedo_at(0.1, -0.1).transpose();
  EXPECT_TRUE(near(albedo_at(-0.1, -0.1), {1, 1, 1, 1})) << albedo_at(-0.1, -0.1).transpose();
  // the base colour multiplies the texture
  world.instances[0].material.base_color = {0.5, 0.5, 0.5, 1};
  Backend().Render(world, cam, &pic);
  EXPECT_TRUE(near(albedo_at(-0.1, -0.1), {0.5, 0.5, 0.5, 1}));
  std::remove(path.c_str());
}

TEST(RasterTest, JpegTextureIsDecoded) {
  // 16 x 16 of one sRGB colour (200, 100, 50)
  std::string path = ::testing::TempDir() + "/partsim_raster_texture.jpg";
  ASSERT_TRUE(testing::WriteSolidJpeg(path, 16, 16, 200, 100, 50));
  RenderWorld world;
  world.instances.push_back(Instance(Quad(0.2f), {1, 0, 0}, {1, 1, 1, 1}, 1, 1, FacingCamera()));
  world.instances[0].material.diffuse_texture = path;
  CameraParams cam = Camera(32, 32);
  Picture pic;
  Backend().Render(world, cam, &pic);
  auto linear = [](double c) {
    c /= 255;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  Eigen::Vector4f a = Rgba(pic.albedo, 16 * 32 + 16);
  EXPECT_NEAR(a.x(), linear(200), 0.02);
  EXPECT_NEAR(a.y(), linear(100), 0.02);
  EXPECT_NEAR(a.z(), linear(50), 0.02);
  std::remove(path.c_str());
}

// Color and Position alone take the forward path: the same colours (within 2/255 at >= 99.5%
// of pixels) and positions (1e-4 m) as the deferred path, under a shadowing sun, a point light
// and a spot light, with textured and untextured materials of any roughness and metalness
TEST(RasterTest, ForwardPathMatchesDeferredPath) {
  std::string path = ::testing::TempDir() + "/partsim_raster_forward_texture.png";
  std::vector<uint8_t> rgb;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      bool odd = (x / 2 + y / 2) % 2;
      rgb.insert(rgb.end(), {uint8_t(odd ? 220 : 40), uint8_t(odd ? 180 : 90), uint8_t(60)});
    }
  }
  WriteRgbPng(path, 8, 8, rgb);
  RenderWorld world;
  // ground, boxes of several materials, textured quads on the ground and facing the camera
  world.instances.push_back(Instance(Quad(2.0f), {1.5, 0, 0}, {0.9f, 0.9f, 0.9f, 1}, 1, 1));
  world.instances[0].material.roughness = 0.83f;
  world.instances.push_back(Instance(Quad(0.2f), {0.9, -0.4, 0.001}, {1, 1, 1, 1}, 6, 6));
  world.instances.back().material.diffuse_texture = path;
  const Eigen::Vector3d boxes[] = {{1.3, 0.3, 0.15}, {1.7, -0.2, 0.1}, {1.4, -0.5, 0.2}};
  const float roughness[] = {0.12f, 0.5f, 0.937f}, metallic[] = {0.0f, 0.71f, 0.33f};
  for (int i = 0; i < 3; ++i) {
    float h = static_cast<float>(boxes[i].z());
    world.instances.push_back(Instance(Box({0.12f, 0.1f, h}), boxes[i],
                                       {0.8f - 0.2f * i, 0.3f + 0.2f * i, 0.5f, 1}, 2 + i, 2 + i));
    world.instances.back().material.roughness = roughness[i];
    world.instances.back().material.metallic = metallic[i];
  }
  world.instances.push_back(
      Instance(Quad(0.15f), {1.9, 0.4, 0.3}, {1, 1, 1, 1}, 5, 5, FacingCamera()));
  world.instances.back().material.diffuse_texture = path;
  world.lights.push_back(Directional({-0.2, 0.6, -1}, true));
  LightDesc point;
  point.type = LightType::kPoint;
  point.position = {1.0, 0.5, 1.0};
  point.color = Eigen::Vector3f(1.5f, 1.2f, 1.0f);
  world.lights.push_back(point);
  LightDesc spot;
  spot.type = LightType::kSpot;
  spot.position = {1.6, -0.3, 1.2};
  spot.direction = {0, 0.2, -1};
  spot.color = Eigen::Vector3f::Constant(1.0f);
  spot.shadow = true;
  world.lights.push_back(spot);
  world.ambient = Eigen::Vector3f::Constant(0.1f);
  // from above and in front, the horizon in view (background pixels)
  Pose X_WC(Eigen::Vector3d(0.2, 0.1, 0.9),
            Eigen::Quaterniond(Eigen::AngleAxisd(0.45, Eigen::Vector3d::UnitY())));
  CameraParams cam = Camera(160, 120, X_WC, 1.1);

  Picture deferred, forward;
  Backend().Render(world, cam, &deferred);
  Backend().Render(world, cam, &forward, kColor | kPosition);
  size_t n = 160 * 120;
  EXPECT_EQ(forward.outputs, unsigned{kColor | kPosition});
  ASSERT_EQ(forward.color.size(), 4 * n);
  ASSERT_EQ(forward.position.size(), 4 * n);
  EXPECT_TRUE(forward.albedo.empty());
  EXPECT_TRUE(forward.normal.empty());
  EXPECT_TRUE(forward.segmentation.empty());
  size_t close = 0, surface = 0, background = 0, lit = 0;
  double max_position_error = 0;
  for (size_t i = 0; i < n; ++i) {
    float diff = 0;
    for (int k = 0; k < 4; ++k)
      diff = std::max(diff, std::abs(forward.color[4 * i + k] - deferred.color[4 * i + k]));
    close += diff <= 2.0f / 255;
    for (int k = 0; k < 4; ++k) {
      max_position_error =
          std::max(max_position_error, static_cast<double>(std::abs(forward.position[4 * i + k] -
                                                                    deferred.position[4 * i + k])));
    }
    bool seen = deferred.position[4 * i + 3] > 0;
    surface += seen;
    background += !seen;
    lit += seen && deferred.color[4 * i] > 0.2f;
  }
  // the scene fills most of the picture, with sky above the horizon and lit surfaces
  EXPECT_GT(surface, n / 2);
  EXPECT_GT(background, n / 20);
  EXPECT_GT(lit, n / 10);
  EXPECT_GE(close, static_cast<size_t>(0.995 * n)) << n - close << " pixels differ by > 2/255";
  EXPECT_LT(max_position_error, 1e-4);
  // the sun's shadow is there: the first box's top centre shadows the ground at
  // (1.3, 0.3) + 0.3 (-0.2, 0.6)
  size_t shade = Pixel(deferred, Project(cam, {1.24, 0.48, 0.0}));
  size_t sunny = Pixel(deferred, Project(cam, {1.0, 0.0, 0.0}));
  EXPECT_LT(forward.color[4 * shade + 1], 0.6f * forward.color[4 * sunny + 1]);

  // any other output takes the deferred path, which renders only what was asked for
  Picture some;
  Backend().Render(world, cam, &some, kColor | kNormal);
  EXPECT_EQ(some.color, deferred.color);
  EXPECT_EQ(some.normal, deferred.normal);
  EXPECT_TRUE(some.position.empty());
  EXPECT_TRUE(some.albedo.empty());
  // and all outputs again after a forward picture
  Picture again;
  Backend().Render(world, cam, &again);
  EXPECT_EQ(again.color, deferred.color);
  EXPECT_EQ(again.segmentation, deferred.segmentation);

  // a larger picture, whose depth more worker threads convert in more parts, with and without
  // the colour read back beside them: the same Position as the deferred path
  CameraParams big = Camera(400, 300, X_WC, 1.1);
  Picture big_deferred;
  Backend().Render(world, big, &big_deferred, kPosition | kSegmentation);
  for (unsigned outputs : {unsigned{kColor | kPosition}, unsigned{kPosition}}) {
    Picture big_forward;
    big_forward.position.assign(4 * 400 * 300, -5.0f);  // every value must be written
    Backend().Render(world, big, &big_forward, outputs);
    ASSERT_EQ(big_forward.position.size(), big_deferred.position.size());
    float worst = 0;
    for (size_t i = 0; i < big_forward.position.size(); ++i) {
      worst = std::max(worst, std::abs(big_forward.position[i] - big_deferred.position[i]));
    }
    EXPECT_LT(worst, 1e-4f) << PictureOutputNames(outputs);
  }
  std::remove(path.c_str());
}

TEST(RasterTest, CustomShadersKeepTheDeferredPathForColorAndPosition) {
  // a custom lighting pass that paints every surface green: Color + Position still runs it
  RasterOptions options;
  options.lighting_fragment_shader = R"(#version 450 core
uniform sampler2D u_position;
layout(location = 0) out vec4 o_color;
void main() {
  vec4 p = texelFetch(u_position, ivec2(gl_FragCoord.xy), 0);
  o_color = p.w > 0.0 ? vec4(0.0, 1.0, 0.0, 1.0) : vec4(0.0);
}
)";
  std::unique_ptr<RenderBackend> custom = MakeRasterBackend(options);
  RenderWorld world;
  world.instances.push_back(Instance(Box({0.2f, 0.2f, 0.2f}), {1, 0, 0}, {1, 0, 0, 1}, 1, 1));
  CameraParams cam = Camera(32, 32);
  Picture pic;
  custom->Render(world, cam, &pic, kColor | kPosition);
  size_t centre = 16 * 32 + 16;
  EXPECT_EQ(Rgba(pic.color, centre), Eigen::Vector4f(0, 1, 0, 1));
  EXPECT_NEAR(pic.position[4 * centre + 3], 0.8, 1e-4);
}

TEST(RasterTest, ManyInstancesAndBackends) {
  // a grid of 400 boxes with their own ids, rendered by two backends in turn
  RenderWorld world;
  auto box = Box({0.01f, 0.01f, 0.01f});
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      world.instances.push_back(
          Instance(box, {2, 0.6 - 0.06 * j, 0.6 - 0.06 * i}, {1, 1, 1, 1}, 1 + i * 20 + j, 1000));
    }
  }
  std::unique_ptr<RenderBackend> second = MakeRasterBackend();
  CameraParams cam = Camera(200, 200, Pose(), 0.8);
  Picture a, b;
  Backend().Render(world, cam, &a);
  second->Render(world, cam, &b);
  EXPECT_EQ(a.segmentation, b.segmentation);
  EXPECT_EQ(a.position, b.position);
  for (int k : {0, 57, 399}) {
    int i = k / 20, j = k % 20;
    size_t p = Pixel(a, Project(cam, {1.99, 0.6 - 0.06 * j, 0.6 - 0.06 * i}));
    EXPECT_EQ(a.segmentation[2 * p], static_cast<uint32_t>(k + 1));
  }
}

}  // namespace
}  // namespace partsim
