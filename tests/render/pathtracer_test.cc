// Path tracer backend: determinism, geometry outputs against the true surfaces, light units,
// soft shadows and colour bleeding, built on hand-made render worlds; then through a scene and
// its camera, and against the rasterizer.
#include <gtest/gtest.h>
#include <png.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"
#include "partsim/render/camera_math.h"
#include "partsim/render/scene_render.h"
#include "render/jpeg_test_util.h"
#include "render/render_test_util.h"

namespace partsim {
namespace {

constexpr double kPiD = 3.14159265358979323846;

/// An axis-aligned box mesh of half-size h, four vertices per face with the face's normal.
std::shared_ptr<MeshData> BoxMesh(const Eigen::Vector3f& h) {
  auto m = std::make_shared<MeshData>();
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = static_cast<float>(sign);
      // u, v span the face so that u x v = n
      Eigen::Vector3f u = Eigen::Vector3f::Zero(), v;
      u[(axis + 1) % 3] = 1.0f;
      v = n.cross(u);
      int base = static_cast<int>(m->vertices.size());
      for (auto [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        Eigen::Vector3f p = n + a * u + b * v;
        m->vertices.push_back(p.cwiseProduct(h));
        m->normals.push_back(n);
      }
      m->faces.emplace_back(base, base + 1, base + 2);
      m->faces.emplace_back(base, base + 2, base + 3);
    }
  }
  return m;
}

/// A square of half-size s in the xy plane facing +z, with uvs (0, 0) at (-s, -s).
std::shared_ptr<MeshData> PlaneMesh(float s, bool with_normals = true) {
  auto m = std::make_shared<MeshData>();
  m->vertices = {{-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}};
  m->uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  if (with_normals) m->normals.assign(4, Eigen::Vector3f::UnitZ());
  m->faces = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

RenderInstance Instance(std::shared_ptr<MeshData> mesh, const Eigen::Vector3f& color,
                        const Eigen::Matrix4d& X_WV, uint32_t id) {
  RenderInstance inst;
  inst.mesh = std::move(mesh);
  inst.material.base_color << color, 1.0f;
  inst.material.roughness = 1.0f;
  inst.X_WV = X_WV;
  inst.visual_id = id;
  inst.entity_id = 100 + id;
  return inst;
}

Eigen::Matrix4d Translation(double x, double y, double z) {
  Eigen::Matrix4d X = Eigen::Matrix4d::Identity();
  X.topRightCorner<3, 1>() << x, y, z;
  return X;
}

/// Camera pose at `eye` looking at `target` (x forward, y left, z up).
Pose LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
            const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ()) {
  Eigen::Vector3d x = (target - eye).normalized();
  Eigen::Vector3d y = up.cross(x).normalized();
  Eigen::Matrix3d R;
  R << x, y, x.cross(y);
  return Pose(eye, Eigen::Quaterniond(R));
}

CameraParams Camera(int w, int h, double fovy_deg, const Pose& X_WC) {
  return MakeCameraParams(w, h, IntrinsicsFromFovy(w, h, fovy_deg * kPiD / 180.0), 0.01, 100.0,
                          X_WC);
}

LightDesc Directional(const Eigen::Vector3d& direction, float intensity) {
  LightDesc l;
  l.type = LightType::kDirectional;
  l.direction = direction.normalized();
  l.color = Eigen::Vector3f::Constant(intensity);
  return l;
}

Picture Render(const RenderWorld& world, const CameraParams& cam, int spp, int depth,
               uint64_t seed = 0, int threads = 0) {
  PathTracerOptions o;
  o.samples_per_pixel = spp;
  o.max_depth = depth;
  o.seed = seed;
  o.threads = threads;
  Picture pic;
  MakePathTracerBackend(o)->Render(world, cam, &pic);
  return pic;
}

/// A ground plane, a box on it and a light: the scene of several tests.
RenderWorld BoxOnGround() {
  RenderWorld world;
  world.instances.push_back(
      Instance(PlaneMesh(5.0f), {0.8f, 0.8f, 0.8f}, Eigen::Matrix4d::Identity(), 1));
  world.instances.push_back(
      Instance(BoxMesh({0.1f, 0.1f, 0.1f}), {0.8f, 0.1f, 0.1f}, Translation(0, 0, 0.1), 2));
  world.lights.push_back(Directional({-0.3, 0.2, -1.0}, 2.0f));
  world.ambient = Eigen::Vector3f::Constant(0.2f);
  return world;
}

TEST(PathTracerTest, RejectsBadOptions) {
  PathTracerOptions o;
  o.samples_per_pixel = 0;
  try {
    MakePathTracerBackend(o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("samples_per_pixel"), std::string::npos) << e.what();
  }
  o = PathTracerOptions();
  o.max_depth = 0;
  try {
    MakePathTracerBackend(o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("max_depth"), std::string::npos) << e.what();
  }
  o = PathTracerOptions();
  o.threads = -1;
  EXPECT_THROW(MakePathTracerBackend(o), Error);
  EXPECT_EQ(MakePathTracerBackend()->Name(), "pathtracer");
}

TEST(PathTracerTest, SameSeedSameImageWhateverTheThreads) {
  RenderWorld world = BoxOnGround();
  CameraParams cam = Camera(48, 40, 60, LookAt({0.8, -0.6, 0.7}, {0, 0, 0.05}));
  Picture a = Render(world, cam, 4, 3, 7, 1);
  Picture b = Render(world, cam, 4, 3, 7, 2);
  Picture c = Render(world, cam, 4, 3, 8, 2);
  ASSERT_EQ(a.color.size(), 48u * 40u * 4u);
  EXPECT_EQ(0, std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(float)));
  EXPECT_EQ(a.segmentation, b.segmentation);
  EXPECT_NE(0, std::memcmp(a.color.data(), c.color.data(), a.color.size() * sizeof(float)));
  // the G-buffer comes from the centre ray and does not depend on the seed
  EXPECT_EQ(a.position, c.position);
  EXPECT_EQ(a.segmentation, c.segmentation);

  // the same backend twice gives the same bytes too
  PathTracerOptions o;
  o.samples_per_pixel = 4;
  o.seed = 7;
  o.max_depth = 3;
  auto backend = MakePathTracerBackend(o);
  Picture d, e;
  backend->Render(world, cam, &d);
  backend->Render(world, cam, &e);
  EXPECT_EQ(0, std::memcmp(d.color.data(), a.color.data(), a.color.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(d.color.data(), e.color.data(), d.color.size() * sizeof(float)));
}

/// A plane through p0 with unit normal n (the plane's +z), a camera about 1 m away.
struct TiltedPlane {
  Eigen::Vector3d p0{0.1, -0.05, 0.2};
  Eigen::Vector3d n;
  Eigen::Matrix4d X_WV = Eigen::Matrix4d::Identity();
  TiltedPlane() {
    Eigen::Matrix3d R = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()) *
                         Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitY()))
                            .toRotationMatrix();
    n = R.col(2);
    X_WV.topLeftCorner<3, 3>() = R;
    X_WV.topRightCorner<3, 1>() = p0;
  }
};

TEST(PathTracerTest, DepthBackProjectsOntoTheSurface) {
  TiltedPlane plane;
  RenderWorld world;
  world.instances.push_back(Instance(PlaneMesh(10.0f, false), {0.5f, 0.5f, 0.5f}, plane.X_WV, 1));
  const Pose X_WC = LookAt(plane.p0 + 0.8 * plane.n + 0.5 * plane.X_WV.block<3, 1>(0, 0), plane.p0);
  CameraParams cam = Camera(64, 48, 70, X_WC);
  Picture pic = Render(world, cam, 1, 1);
  const Eigen::Matrix3d K_inv = cam.K.inverse();
  const Eigen::Matrix3d R_WO = X_WC.q.toRotationMatrix() * RotationCameraToCv();
  int hits = 0;
  double worst = 0;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const float* p = &pic.position[4 * (v * cam.width + u)];
      if (p[3] == 0.0f) continue;
      ++hits;
      // OpenCV back-projection of the depth
      Eigen::Vector3d p_O = p[3] * (K_inv * Eigen::Vector3d(u, v, 1));
      Eigen::Vector3d p_W = X_WC.p + R_WO * p_O;
      worst = std::max(worst, std::abs(plane.n.dot(p_W - plane.p0)));
      // xyz is the same point in the OpenGL camera frame
      EXPECT_NEAR(p[0], p_O.x(), 1e-4);
      EXPECT_NEAR(p[1], -p_O.y(), 1e-4);
      EXPECT_NEAR(p[2], -p_O.z(), 1e-4);
    }
  }
  EXPECT_EQ(hits, cam.width * cam.height);  // the plane fills the view
  EXPECT_LT(worst, 1e-3);
  EXPECT_GT((X_WC.p - plane.p0).norm(), 0.9);
}

TEST(PathTracerTest, NormalsOfATiltedPlaneInTheGlFrame) {
  TiltedPlane plane;
  const Pose X_WC = LookAt(plane.p0 + 0.8 * plane.n + 0.5 * plane.X_WV.block<3, 1>(0, 0), plane.p0);
  const Eigen::Matrix3d R_GW = (X_WC.q.toRotationMatrix() * RotationCameraToGl()).transpose();
  const Eigen::Vector3d n_G = R_GW * plane.n;
  for (bool with_normals : {false, true}) {
    RenderWorld world;
    world.instances.push_back(
        Instance(PlaneMesh(10.0f, with_normals), {0.5f, 0.5f, 0.5f}, plane.X_WV, 1));
    CameraParams cam = Camera(32, 24, 70, X_WC);
    Picture pic = Render(world, cam, 1, 1);
    for (int i = 0; i < cam.width * cam.height; ++i) {
      Eigen::Vector3d n(pic.normal[4 * i], pic.normal[4 * i + 1], pic.normal[4 * i + 2]);
      ASSERT_NEAR(n.norm(), 1.0, 1e-5);
      ASSERT_LT((n - n_G).norm(), 1e-4) << "pixel " << i << " normals " << with_normals;
      ASSERT_EQ(pic.normal[4 * i + 3], 0.0f);
    }
  }
}

/// Centroid (u, v) of the pixels with a visual id.
Eigen::Vector2d Centroid(const Picture& pic, uint32_t id, int* count) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  *count = 0;
  for (int v = 0; v < pic.height; ++v) {
    for (int u = 0; u < pic.width; ++u) {
      if (pic.segmentation[2 * (v * pic.width + u)] != id) continue;
      sum += Eigen::Vector2d(u, v);
      ++*count;
    }
  }
  return *count ? Eigen::Vector2d(sum / *count) : sum;
}

TEST(PathTracerTest, SegmentationIdsFollowTheInstances) {
  RenderWorld world = BoxOnGround();
  world.instances.push_back(
      Instance(BoxMesh({0.05f, 0.05f, 0.05f}), {0.1f, 0.8f, 0.1f}, Translation(0, 0.4, 0.05), 3));
  // looking straight down: image up is world +x, image left is world +y
  const Pose X_WC = LookAt({0, 0, 2}, {0, 0, 0}, Eigen::Vector3d::UnitX());
  CameraParams cam = Camera(128, 128, 40, X_WC);
  PathTracerOptions o;
  o.samples_per_pixel = 1;
  o.max_depth = 1;
  auto backend = MakePathTracerBackend(o);
  Picture before;
  backend->Render(world, cam, &before);

  // the pixel seeing the box centre, the small box and the ground
  auto ids = [&](const Picture& pic, const Eigen::Vector3d& p_W) {
    Eigen::Vector3d p_O =
        (X_WC.q.toRotationMatrix() * RotationCameraToCv()).transpose() * (p_W - X_WC.p);
    Eigen::Vector3d uv = cam.K * (p_O / p_O.z());
    int i =
        static_cast<int>(std::lround(uv.y())) * cam.width + static_cast<int>(std::lround(uv.x()));
    return std::pair{pic.segmentation[2 * i], pic.segmentation[2 * i + 1]};
  };
  EXPECT_EQ(ids(before, {0, 0, 0.2}), (std::pair<uint32_t, uint32_t>{2, 102}));
  EXPECT_EQ(ids(before, {0, 0.4, 0.1}), (std::pair<uint32_t, uint32_t>{3, 103}));
  EXPECT_EQ(ids(before, {0.3, -0.3, 0}), (std::pair<uint32_t, uint32_t>{1, 101}));

  // move the small box 0.2 m along -y (image right) without a geometry change
  int n_before, n_after;
  Eigen::Vector2d c_before = Centroid(before, 3, &n_before);
  world.instances[2].X_WV = Translation(0, 0.2, 0.05);
  Picture after;
  backend->Render(world, cam, &after);
  Eigen::Vector2d c_after = Centroid(after, 3, &n_after);
  ASSERT_GT(n_before, 60);
  EXPECT_NEAR(n_after, n_before, 0.2 * n_before);  // more or less of its sides in view
  // 0.2 m at 1.9 m from the camera
  double expected_shift = cam.K(0, 0) * 0.2 / 1.9;
  EXPECT_NEAR(c_after.x() - c_before.x(), expected_shift, 1.0);
  EXPECT_NEAR(c_after.y() - c_before.y(), 0.0, 0.5);
  EXPECT_EQ(ids(after, {0, 0.4, 0.1}), (std::pair<uint32_t, uint32_t>{1, 101}));
  EXPECT_EQ(ids(after, {0, 0.2, 0.1}), (std::pair<uint32_t, uint32_t>{3, 103}));

  // a fresh backend agrees with the moved one
  Picture fresh = Render(world, cam, 1, 1);
  EXPECT_EQ(fresh.segmentation, after.segmentation);
  EXPECT_EQ(fresh.position, after.position);

  // a new geometry version with a different mesh is rebuilt
  world.instances[2].mesh = BoxMesh({0.1f, 0.1f, 0.05f});
  ++world.geometry_version;
  Picture bigger;
  backend->Render(world, cam, &bigger);
  int n_bigger;
  Centroid(bigger, 3, &n_bigger);
  EXPECT_GT(n_bigger, 2.5 * n_after);  // top 4 times larger, sides twice
}

TEST(PathTracerTest, BackgroundIsEmptyEverywhere) {
  RenderWorld world = BoxOnGround();
  // looking up at the sky
  CameraParams cam = Camera(16, 16, 40, LookAt({0, 0, 1}, {0.1, 0, 3}));
  Picture pic = Render(world, cam, 2, 2);
  for (float x : pic.color) ASSERT_EQ(x, 0.0f);
  for (float x : pic.albedo) ASSERT_EQ(x, 0.0f);
  for (float x : pic.position) ASSERT_EQ(x, 0.0f);
  for (float x : pic.normal) ASSERT_EQ(x, 0.0f);
  for (uint32_t x : pic.segmentation) ASSERT_EQ(x, 0u);
}

TEST(PathTracerTest, LitRedBoxIsRed) {
  RenderWorld world = BoxOnGround();
  CameraParams cam = Camera(48, 48, 50, LookAt({0.7, -0.5, 0.6}, {0, 0, 0.1}));
  Picture pic = Render(world, cam, 8, 3);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (int i = 0; i < cam.width * cam.height; ++i) {
    if (pic.segmentation[2 * i] != 2) continue;
    sum += Eigen::Vector3d(pic.color[4 * i], pic.color[4 * i + 1], pic.color[4 * i + 2]);
    EXPECT_EQ(pic.color[4 * i + 3], 1.0f);
    EXPECT_FLOAT_EQ(pic.albedo[4 * i], 0.8f);
    EXPECT_FLOAT_EQ(pic.albedo[4 * i + 1], 0.1f);
    ++n;
  }
  ASSERT_GT(n, 100);
  Eigen::Vector3d mean = sum / n;
  EXPECT_GT(mean.x(), 0.1);
  EXPECT_GT(mean.x(), 3 * mean.y());
  EXPECT_GT(mean.x(), 3 * mean.z());
}

TEST(PathTracerTest, LightUnitsOnAGreyPlane) {
  // a grey plane (roughness 1) seen from straight above, lit head-on by a directional light of
  // irradiance E: L = E ((1 - F0) base A / pi + F0 D G / 4) with Oren-Nayar A = 1 - 0.5 / 1.33
  // and D = 1 / pi, G = 1 for alpha = 1
  RenderWorld world;
  world.instances.push_back(
      Instance(PlaneMesh(100.0f), {0.5f, 0.5f, 0.5f}, Eigen::Matrix4d::Identity(), 1));
  world.ambient.setZero();
  world.lights.push_back(Directional({0, 0, -1}, 2.0f));
  CameraParams cam = Camera(9, 9, 2, LookAt({0, 0, 1}, {0, 0, 0}, Eigen::Vector3d::UnitX()));
  Picture pic = Render(world, cam, 4, 1);
  const double on_a = 1 - 0.5 / 1.33;
  double expected = 2.0 * (0.96 * 0.5 * on_a / kPiD + 0.04 / (4 * kPiD));
  EXPECT_NEAR(pic.color[4 * (4 * 9 + 4)], expected, 0.005 * expected);

  // under a uniform environment of radiance A only, L = A (diffuse albedo + specular albedo):
  // seen head-on, Oren-Nayar is A on_a base (1 - F) with F = 0.04 almost everywhere, and the
  // specular albedo of F0 = 0.04 is below 0.04
  world.lights.clear();
  world.ambient = Eigen::Vector3f::Constant(0.3f);
  cam = Camera(24, 24, 10, LookAt({0, 0, 1}, {0, 0, 0}, Eigen::Vector3d::UnitX()));
  pic = Render(world, cam, 64, 1);
  double mean = 0;
  for (int i = 0; i < 24 * 24; ++i) mean += pic.color[4 * i] / (24 * 24);
  const double diffuse = 0.3 * on_a * 0.5 * 0.96;
  EXPECT_GT(mean, 0.98 * diffuse);
  EXPECT_LT(mean, diffuse + 0.3 * 0.04);
}

TEST(PathTracerTest, SoftShadowBehindAWall) {
  // a low sun (20 degrees) behind a 1 m tall, 2 m wide wall at x = 0: the shadow on the ground
  // ends near x = 2.85 m, with a penumbra about 0.15 m long (0.5 degree angular radius)
  RenderWorld world;
  world.instances.push_back(
      Instance(PlaneMesh(10.0f), {0.8f, 0.8f, 0.8f}, Eigen::Matrix4d::Identity(), 1));
  world.instances.push_back(
      Instance(BoxMesh({0.1f, 1.0f, 0.5f}), {0.8f, 0.8f, 0.8f}, Translation(0, 0, 0.5), 2));
  const double elevation = 20 * kPiD / 180;
  world.lights.push_back(Directional({std::cos(elevation), 0, -std::sin(elevation)}, 3.0f));
  world.ambient = Eigen::Vector3f::Constant(0.05f);
  // straight down at the shadow's end; image up is world +x
  const double tip = 0.1 + 1.0 / std::tan(elevation);
  CameraParams cam =
      Camera(64, 64, 40, LookAt({tip, 0, 1.5}, {tip, 0, 0}, Eigen::Vector3d::UnitX()));
  Picture pic = Render(world, cam, 64, 1);
  // the same without the wall, to divide out the shading of the open ground
  world.instances.pop_back();
  Picture open = Render(world, cam, 64, 1);
  // lit fraction down the image (towards the wall), averaged over the central columns
  std::vector<double> profile(cam.height, 0.0);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 24; u < 40; ++u) {
      int i = 4 * (v * cam.width + u);
      profile[v] += pic.color[i] / open.color[i] / 16;
    }
  }
  const double lit = profile.front(), dark = profile.back();
  EXPECT_NEAR(lit, 1.0, 0.02);
  EXPECT_LT(dark, 0.3);
  int penumbra = 0;
  for (int v = 0; v < cam.height; ++v) {
    double s = (profile[v] - dark) / (lit - dark);
    if (s > 0.1 && s < 0.9) ++penumbra;
    // monotone from lit to dark, up to noise
    if (v > 0) EXPECT_LT(profile[v], profile[v - 1] + 0.03) << v;
  }
  // about 0.15 m at 1.09 m / 64 px: some 9 pixels, of which the 10-90% band is most
  EXPECT_GE(penumbra, 3);
  EXPECT_LE(penumbra, 12);
}

/// Mean red / green ratio of a white wall standing on a floor of colour `floor`.
double WallRedOverGreen(const Eigen::Vector3f& floor) {
  RenderWorld world;
  world.instances.push_back(Instance(PlaneMesh(3.0f), floor, Eigen::Matrix4d::Identity(), 1));
  // the wall: a plane at x = 0 facing +x
  Eigen::Matrix4d X_WV = Translation(0, 0, 1.5);
  X_WV.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(kPiD / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  world.instances.push_back(Instance(PlaneMesh(1.5f), {0.8f, 0.8f, 0.8f}, X_WV, 2));
  // light from straight above: the floor is lit, the wall only by the floor and the sky
  world.lights.push_back(Directional({0, 0, -1}, 3.0f));
  world.ambient = Eigen::Vector3f::Constant(0.1f);
  CameraParams cam = Camera(40, 40, 60, LookAt({2.0, 0, 0.6}, {0, 0, 0.4}));
  Picture pic = Render(world, cam, 16, 3, 1);
  double r = 0, g = 0;
  for (int i = 0; i < cam.width * cam.height; ++i) {
    if (pic.segmentation[2 * i] != 2) continue;
    r += pic.color[4 * i];
    g += pic.color[4 * i + 1];
  }
  EXPECT_GT(g, 0.0);
  return r / g;
}

TEST(PathTracerTest, ColourBleedsFromARedFloorOntoAWhiteWall) {
  double white = WallRedOverGreen({0.8f, 0.8f, 0.8f});
  double red = WallRedOverGreen({0.8f, 0.1f, 0.1f});
  EXPECT_NEAR(white, 1.0, 0.05);
  EXPECT_GT(red, 1.5);
}

/// Writes a w x h RGBA8 PNG.
void WritePng(const std::string& path, int w, int h, const std::vector<uint8_t>& rgba) {
  png_image image;
  std::memset(&image, 0, sizeof(image));
  image.version = PNG_IMAGE_VERSION;
  image.width = w;
  image.height = h;
  image.format = PNG_FORMAT_RGBA;
  ASSERT_TRUE(png_image_write_to_file(&image, path.c_str(), 0, rgba.data(), 0, nullptr));
}

TEST(PathTracerTest, DiffuseTexturesInAlbedoAndMissingFileNamed) {
  // 8 x 8 texture of four quadrants: top red | green, bottom blue | white (sRGB 255 = linear 1)
  std::string path = ::testing::TempDir() + "/pt_texture_test.png";
  std::vector<uint8_t> rgba;
  for (int row = 0; row < 8; ++row) {
    for (int col = 0; col < 8; ++col) {
      int quadrant = (row < 4 ? 0 : 2) + (col < 4 ? 0 : 1);
      const uint8_t colours[4][4] = {
          {255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {255, 255, 255, 255}};
      rgba.insert(rgba.end(), colours[quadrant], colours[quadrant] + 4);
    }
  }
  WritePng(path, 8, 8, rgba);
  RenderWorld world;
  RenderInstance inst =
      Instance(PlaneMesh(1.0f), {1.0f, 1.0f, 1.0f}, Eigen::Matrix4d::Identity(), 1);
  inst.material.diffuse_texture = path;
  world.instances.push_back(inst);
  // straight down, image up = world +y, image left = world -x: the plane's uv axes
  CameraParams cam = Camera(40, 40, 60, LookAt({0, 0, 1}, {0, 0, 0}, Eigen::Vector3d::UnitY()));
  Picture pic = Render(world, cam, 1, 1);
  auto albedo = [&](int u, int v) {
    const float* a = &pic.albedo[4 * (v * cam.width + u)];
    return Eigen::Vector3f(a[0], a[1], a[2]);
  };
  // pixels 6 and 33 see uv 0.3 and 0.7: the file's top-left quadrant is at the image's top left
  EXPECT_LT((albedo(6, 6) - Eigen::Vector3f(1, 0, 0)).norm(), 1e-3);
  EXPECT_LT((albedo(33, 6) - Eigen::Vector3f(0, 1, 0)).norm(), 1e-3);
  EXPECT_LT((albedo(6, 33) - Eigen::Vector3f(0, 0, 1)).norm(), 1e-3);
  EXPECT_LT((albedo(33, 33) - Eigen::Vector3f(1, 1, 1)).norm(), 1e-3);
  std::remove(path.c_str());

  // a JPEG of one sRGB colour (200, 100, 50)
  path = ::testing::TempDir() + "/pt_texture_test.jpg";
  ASSERT_TRUE(testing::WriteSolidJpeg(path, 16, 16, 200, 100, 50));
  world.instances[0].material.diffuse_texture = path;
  pic = Render(world, cam, 1, 1);
  auto linear = [](double c) { return std::pow((c / 255 + 0.055) / 1.055, 2.4); };
  EXPECT_LT((albedo(20, 20) - Eigen::Vector3d(linear(200), linear(100), linear(50)).cast<float>())
                .cwiseAbs()
                .maxCoeff(),
            0.02);
  std::remove(path.c_str());

  world.instances[0].material.diffuse_texture = "/nonexistent/wood.png";
  try {
    Render(world, cam, 1, 1);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/wood.png"), std::string::npos);
  }
}

TEST(PathTracerTest, ThroughTheSceneAndItsCamera) {
  Scene scene;
  scene.AddGround();
  Articulation lamp = testing::AddLamp(scene);
  testing::AddCrate(scene, {-0.3, 0.3, 0.1});
  AddDirectionalLight(scene, {-0.3, 0.2, -1.0}, {1.5f, 1.5f, 1.5f}, true);
  AddPointLight(scene, {0.5, -0.5, 1.5}, {0.5f, 0.5f, 0.5f});
  SetAmbientLight(scene, {0.2f, 0.2f, 0.2f});
  SetRenderBackend(scene, "pathtracer");
  EXPECT_EQ(GetRenderBackend(scene).Name(), "pathtracer");
  partsim::Camera cam = AddCamera(scene, "c", 64, 48, 1.0, 0.05, 20.0);
  cam.SetLocalPose(LookAt({1.4, -1.2, 1.1}, {0.1, 0, 0.3}));
  UpdateRender(scene);
  cam.TakePicture();
  const Picture pic = cam.GetPictureData();

  // every id seen names a visual of the scene; the lamp's four visuals and the crate are seen
  std::map<uint32_t, RenderVisualInfo> visuals;
  for (const RenderVisualInfo& v : GetRenderVisuals(scene)) visuals[v.id] = v;
  std::set<std::string> seen;
  for (int i = 0; i < pic.width * pic.height; ++i) {
    uint32_t id = pic.segmentation[2 * i];
    if (id == 0) continue;
    ASSERT_TRUE(visuals.count(id)) << id;
    EXPECT_EQ(visuals[id].entity_id, pic.segmentation[2 * i + 1]);
    seen.insert(visuals[id].name);
  }
  for (const char* name : {"foot", "post", "bar", "bulb", "lid_panel"}) {
    EXPECT_TRUE(seen.count(name)) << name;
  }

  // the picture is the backend's picture of the scene's render world
  Picture direct;
  MakePathTracerBackend()->Render(GetRenderWorld(scene), cam.GetParams(), &direct);
  EXPECT_EQ(0,
            std::memcmp(direct.color.data(), pic.color.data(), pic.color.size() * sizeof(float)));
  EXPECT_EQ(direct.segmentation, pic.segmentation);

  // turning the lamp's arm moves the pixels of its bulb
  uint32_t bulb = 0;
  for (const auto& [id, v] : visuals) {
    if (v.name == "bulb") bulb = id;
  }
  int n_before, n_after;
  Eigen::Vector2d before = Centroid(pic, bulb, &n_before);
  lamp.SetQpos(Eigen::VectorXd::Constant(1, 1.2));
  UpdateRender(scene);
  cam.TakePicture();
  Eigen::Vector2d after = Centroid(cam.GetPictureData(), bulb, &n_after);
  ASSERT_GT(n_before, 0);
  ASSERT_GT(n_after, 0);
  EXPECT_GT((after - before).norm(), 3.0);
}

/// Fraction of pixels where both backends see a surface and agree on its position within `tol`
/// metres, and fraction of all pixels with identical segmentation.
void ComparePictures(const Picture& a, const Picture& b, double tol, double* position_agree,
                     double* segmentation_agree, int* both_hit) {
  int agree = 0, same = 0;
  *both_hit = 0;
  const int n = a.width * a.height;
  for (int i = 0; i < n; ++i) {
    if (a.segmentation[2 * i] == b.segmentation[2 * i] &&
        a.segmentation[2 * i + 1] == b.segmentation[2 * i + 1]) {
      ++same;
    }
    if (a.position[4 * i + 3] <= 0 || b.position[4 * i + 3] <= 0) continue;
    ++*both_hit;
    Eigen::Vector3d pa(a.position[4 * i], a.position[4 * i + 1], a.position[4 * i + 2]);
    Eigen::Vector3d pb(b.position[4 * i], b.position[4 * i + 1], b.position[4 * i + 2]);
    if ((pa - pb).norm() < tol && std::abs(a.position[4 * i + 3] - b.position[4 * i + 3]) < tol) {
      ++agree;
    }
  }
  *position_agree = *both_hit ? static_cast<double>(agree) / *both_hit : 0.0;
  *segmentation_agree = static_cast<double>(same) / n;
}

TEST(PathTracerTest, AgreesWithTheRasterizerOnPositionAndSegmentation) {
  std::unique_ptr<RenderBackend> raster;
  try {
    raster = MakeRasterBackend();
  } catch (const Error& e) {
    GTEST_SKIP() << "no rasterizer here: " << e.what();
  }
  RenderWorld world = BoxOnGround();
  // a tilted box and a second box behind the first
  Eigen::Matrix4d X_WV = Translation(-0.25, 0.3, 0.2);
  X_WV.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 2).normalized()).toRotationMatrix();
  world.instances.push_back(Instance(BoxMesh({0.15f, 0.05f, 0.1f}), {0.2f, 0.6f, 0.2f}, X_WV, 3));
  world.instances.push_back(
      Instance(BoxMesh({0.2f, 0.2f, 0.3f}), {0.3f, 0.3f, 0.8f}, Translation(-0.6, -0.2, 0.3), 4));
  for (const Pose& X_WC :
       {LookAt({0.9, -0.7, 0.6}, {0, 0, 0.1}), LookAt({-0.2, -1.0, 1.4}, {-0.2, 0.1, 0.1})}) {
    CameraParams cam = Camera(96, 72, 60, X_WC);
    Picture r, p;
    raster->Render(world, cam, &r);
    p = Render(world, cam, 1, 1);
    double position_agree, segmentation_agree;
    int both_hit;
    ComparePictures(r, p, 1e-3, &position_agree, &segmentation_agree, &both_hit);
    EXPECT_GT(both_hit, 96 * 72 / 2);
    EXPECT_GE(position_agree, 0.99);
    EXPECT_GE(segmentation_agree, 0.99);
  }
}

TEST(PathTracerTest, AgreesWithTheRasterizerOnDirectLight) {
  std::unique_ptr<RenderBackend> raster;
  try {
    raster = MakeRasterBackend();
  } catch (const Error& e) {
    GTEST_SKIP() << "no rasterizer here: " << e.what();
  }
  // one plane, so no shadows and no indirect light; no ambient: the two shade the same
  // material under the same lights
  RenderWorld world;
  world.instances.push_back(
      Instance(PlaneMesh(5.0f), {0.7f, 0.5f, 0.3f}, Eigen::Matrix4d::Identity(), 1));
  world.instances[0].material.roughness = 0.5f;
  world.instances[0].material.metallic = 0.3f;
  world.ambient.setZero();
  world.lights.push_back(Directional({-0.5, 0.3, -1.0}, 1.5f));
  LightDesc point;
  point.type = LightType::kPoint;
  point.position = Eigen::Vector3d(0.3, 0.4, 0.8);
  point.color = Eigen::Vector3f(0.3f, 0.4f, 0.5f);
  world.lights.push_back(point);
  CameraParams cam = Camera(48, 36, 60, LookAt({1.0, -0.8, 0.9}, {0, 0, 0}));
  Picture r, p;
  raster->Render(world, cam, &r);
  p = Render(world, cam, 16, 1);
  double sum_r = 0, sum_p = 0, worst = 0;
  int compared = 0;
  for (int v = 1; v + 1 < cam.height; ++v) {
    for (int u = 1; u + 1 < cam.width; ++u) {
      // inside the plane's image, away from its edges (the path tracer antialiases them)
      bool inside = true;
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          inside = inside && r.segmentation[2 * ((v + dv) * cam.width + u + du)] == 1;
        }
      }
      if (!inside) continue;
      ++compared;
      int i = v * cam.width + u;
      for (int k = 0; k < 3; ++k) {
        double a = r.color[4 * i + k], b = p.color[4 * i + k];
        sum_r += a;
        sum_p += b;
        worst = std::max(worst, std::abs(a - b) / std::max(a, 0.02));
      }
    }
  }
  EXPECT_GT(compared, cam.width * cam.height / 2);
  EXPECT_GT(sum_r, 0.0);
  EXPECT_NEAR(sum_p / sum_r, 1.0, 0.01);
  EXPECT_LT(worst, 0.05);
}

}  // namespace
}  // namespace partsim
