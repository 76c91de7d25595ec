#include "partsim/render/backend.h"

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>

#include "partsim/core/error.h"
#include "partsim/render/camera_math.h"
#include "render/render_test_util.h"

namespace partsim {
namespace {

using testing::PlaneBackend;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

CameraParams GoodCamera() {
  return MakeCameraParams(8, 6, IntrinsicsFromFovy(8, 6, 1.0), 0.1, 10.0, Pose());
}

// Render with `camera` changed by `edit` throws a message naming `argument`, and never reaches
// the backend's DoRender.
void ExpectRefused(const std::function<void(CameraParams&)>& edit, const std::string& argument) {
  PlaneBackend backend;
  CameraParams camera = GoodCamera();
  edit(camera);
  Picture picture;
  try {
    backend.Render(RenderWorld(), camera, &picture);
    ADD_FAILURE() << "no error for a bad " << argument;
  } catch (const Error& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("'test-plane'"), std::string::npos) << message;
    EXPECT_NE(message.find(argument), std::string::npos) << message;
  }
  EXPECT_EQ(backend.renders, 0) << argument;
}

TEST(RenderBackendTest, RenderRefusesBadCamerasForEveryBackend) {
  ExpectRefused([](CameraParams& c) { c.width = 0; }, "camera.width");
  ExpectRefused([](CameraParams& c) { c.width = RenderBackend::kMaxPictureSize + 1; },
                "camera.width");
  ExpectRefused([](CameraParams& c) { c.height = -3; }, "camera.height");
  ExpectRefused([](CameraParams& c) { c.K(0, 0) = 0; }, "camera.K");
  ExpectRefused([](CameraParams& c) { c.K(1, 2) = kNaN; }, "camera.K");
  ExpectRefused([](CameraParams& c) { c.near = 0; }, "camera.near");
  ExpectRefused([](CameraParams& c) { c.near = kNaN; }, "camera.near");
  ExpectRefused([](CameraParams& c) { c.far = c.near; }, "camera.far");
  ExpectRefused([](CameraParams& c) { c.far = std::numeric_limits<double>::infinity(); },
                "camera.far");
  ExpectRefused([](CameraParams& c) { c.X_WC.p.x() = kNaN; }, "camera.X_WC");
  ExpectRefused([](CameraParams& c) { c.X_WC.q.coeffs() *= 2; }, "camera.X_WC");
  ExpectRefused([](CameraParams& c) { c.view(0, 3) = kNaN; }, "camera.view");
  ExpectRefused([](CameraParams& c) { c.projection(2, 2) = kNaN; }, "camera.projection");
}

TEST(RenderBackendTest, RenderRefusesBadOutputsAndNullPicture) {
  PlaneBackend backend;
  Picture picture;
  EXPECT_THROW(backend.Render(RenderWorld(), GoodCamera(), &picture, 0), Error);
  EXPECT_THROW(backend.Render(RenderWorld(), GoodCamera(), &picture, kAllOutputs + 1), Error);
  EXPECT_THROW(backend.Render(RenderWorld(), GoodCamera(), nullptr), Error);
  EXPECT_EQ(backend.renders, 0);
}

// PlaneBackend fills every output; Render keeps only those asked for
TEST(RenderBackendTest, RenderKeepsOnlyTheOutputsAskedFor) {
  PlaneBackend backend;
  Picture picture;
  backend.Render(RenderWorld(), GoodCamera(), &picture, kColor | kSegmentation);
  EXPECT_EQ(backend.renders, 1);
  EXPECT_EQ(backend.last_outputs, unsigned{kColor | kSegmentation});
  EXPECT_EQ(picture.outputs, unsigned{kColor | kSegmentation});
  EXPECT_EQ(picture.color.size(), 4u * 8 * 6);
  EXPECT_EQ(picture.segmentation.size(), 2u * 8 * 6);
  EXPECT_TRUE(picture.albedo.empty());
  EXPECT_TRUE(picture.normal.empty());
  EXPECT_TRUE(picture.position.empty());
}

TEST(RenderBackendTest, NullBackendFillsBackgroundOfTheCameraSize) {
  std::unique_ptr<RenderBackend> backend = MakeNullBackend();
  Picture picture;
  backend->Render(RenderWorld(), GoodCamera(), &picture, kPosition);
  EXPECT_EQ(picture.width, 8);
  EXPECT_EQ(picture.height, 6);
  ASSERT_EQ(picture.position.size(), 4u * 8 * 6);
  for (float v : picture.position) EXPECT_EQ(v, 0.0f);
  EXPECT_TRUE(picture.color.empty());
  EXPECT_THROW(backend->Render(RenderWorld(), GoodCamera(), &picture, 64), Error);
}

}  // namespace
}  // namespace partsim
