#include "partsim/render/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "partsim/render/camera_math.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"
#include "render/render_test_util.h"

namespace partsim {
namespace {

using testing::AddCrate;
using testing::AddLamp;
using testing::PlaneBackend;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A camera at `p` looking at `target` (x forward, z up as far as possible).
Pose LookAt(const Eigen::Vector3d& p, const Eigen::Vector3d& target) {
  Eigen::Vector3d x = (target - p).normalized();
  Eigen::Vector3d y = Eigen::Vector3d::UnitZ().cross(x).normalized();
  Eigen::Matrix3d R;
  R << x, y, x.cross(y);
  return Pose(p, Eigen::Quaterniond(R));
}

void ExpectPoseNear(const Pose& a, const Pose& b, double tol = 1e-9) {
  EXPECT_LT((a.p - b.p).norm(), tol) << a.ToString() << " vs " << b.ToString();
  EXPECT_LT(a.q.angularDistance(b.q), tol) << a.ToString() << " vs " << b.ToString();
}

class CameraTest : public ::testing::Test {
 protected:
  void SetUp() override { SetRenderBackend(scene_, "null"); }
  Scene scene_;
};

TEST_F(CameraTest, IntrinsicsFromFovy) {
  Camera cam = AddCamera(scene_, "c", 640, 480, 1.0, 0.1, 10.0);
  Eigen::Matrix3d K = cam.GetIntrinsicMatrix();
  double f = 240.0 / std::tan(0.5);
  EXPECT_NEAR(K(0, 0), f, 1e-9);
  EXPECT_NEAR(K(1, 1), f, 1e-9);
  EXPECT_NEAR(K(0, 2), 319.5, 1e-12);
  EXPECT_NEAR(K(1, 2), 239.5, 1e-12);
  EXPECT_EQ(K(2, 2), 1.0);
  EXPECT_NEAR(cam.GetFovy(), 1.0, 1e-12);
  EXPECT_NEAR(cam.GetFovx(), 2 * std::atan(320.0 / f), 1e-12);
  // a new fovy keeps square pixels and a centred principal point
  cam.SetFovy(0.5);
  EXPECT_NEAR(cam.GetFovy(), 0.5, 1e-12);
  EXPECT_NEAR(cam.GetIntrinsicMatrix()(0, 0), cam.GetIntrinsicMatrix()(1, 1), 1e-9);
  // explicit intrinsics
  cam.SetIntrinsics(500, 510, 300, 200);
  K = cam.GetIntrinsicMatrix();
  EXPECT_EQ(K(0, 0), 500);
  EXPECT_EQ(K(1, 1), 510);
  EXPECT_EQ(K(0, 2), 300);
  EXPECT_EQ(K(1, 2), 200);
  EXPECT_NEAR(cam.GetFovy(), 2 * std::atan(240.0 / 510), 1e-12);
  EXPECT_EQ(cam.GetName(), "c");
  EXPECT_EQ(cam.GetWidth(), 640);
  EXPECT_EQ(cam.GetHeight(), 480);
  EXPECT_EQ(cam.GetNear(), 0.1);
  EXPECT_EQ(cam.GetFar(), 10.0);
}

TEST_F(CameraTest, OpenCvProjectionEqualsOpenGlProjectionInPixels) {
  Camera cam = AddCamera(scene_, "c", 320, 240, 0.9, 0.05, 20.0);
  cam.SetIntrinsics(300, 280, 150.25, 125.75);  // off-centre principal point
  Pose X_WC = LookAt(Eigen::Vector3d(1.0, -2.0, 1.5), Eigen::Vector3d(0.1, 0.2, 0.3));
  cam.SetLocalPose(X_WC);
  ExpectPoseNear(cam.GetPose(), X_WC);

  Eigen::Matrix3d K = cam.GetIntrinsicMatrix();
  Eigen::Matrix<double, 3, 4> Rt = cam.GetExtrinsicMatrix();
  Eigen::Matrix4d model = cam.GetModelMatrix();
  Eigen::Matrix4d view = model.inverse();
  Eigen::Matrix4d proj = cam.GetProjectionMatrix();
  CameraParams params = cam.GetParams();
  EXPECT_LT((params.view - view).norm(), 1e-9);
  EXPECT_LT((params.projection - proj).norm(), 1e-12);
  EXPECT_LT((params.K - K).norm(), 1e-12);
  EXPECT_LT((params.view * model - Eigen::Matrix4d::Identity()).norm(), 1e-9);

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-0.5, 0.5);
  for (int k = 0; k < 50; ++k) {
    Eigen::Vector3d p_W = Eigen::Vector3d(0.1, 0.2, 0.3) + Eigen::Vector3d(U(rng), U(rng), U(rng));
    // OpenCV: K [R | t] p
    Eigen::Vector3d uvw = K * Rt * p_W.homogeneous();
    double u_cv = uvw.x() / uvw.z(), v_cv = uvw.y() / uvw.z();
    // OpenGL: clip = P V p; framebuffer pixel centres at half-integers, row 0 at the bottom
    Eigen::Vector4d clip = proj * view * p_W.homogeneous();
    Eigen::Vector3d ndc = clip.head<3>() / clip.w();
    double x_fb = 0.5 * (ndc.x() + 1) * 320, y_fb = 0.5 * (ndc.y() + 1) * 240;
    EXPECT_NEAR(x_fb - 0.5, u_cv, 1e-6);
    EXPECT_NEAR((240 - y_fb) - 0.5, v_cv, 1e-6);
    // in front of the camera: positive OpenCV depth, inside the clip volume in z
    EXPECT_GT(uvw.z(), 0);
    EXPECT_GT(ndc.z(), -1);
    EXPECT_LT(ndc.z(), 1);
  }
}

TEST_F(CameraTest, ModelMatrixAxesFollowConventions) {
  Camera cam = AddCamera(scene_, "c", 64, 48, 1.0, 0.1, 10.0);
  Pose X_WC = LookAt(Eigen::Vector3d(2, 0, 0), Eigen::Vector3d::Zero());
  cam.SetLocalPose(X_WC);
  Eigen::Matrix4d model = cam.GetModelMatrix();
  // OpenGL camera looks along -z: world direction (-1, 0, 0)
  EXPECT_LT((model.block<3, 1>(0, 2) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-12);
  // up is world +z
  EXPECT_LT((model.block<3, 1>(0, 1) - Eigen::Vector3d(0, 0, 1)).norm(), 1e-12);
  EXPECT_LT((model.block<3, 1>(0, 3) - Eigen::Vector3d(2, 0, 0)).norm(), 1e-12);
  // OpenCV extrinsics: the camera centre maps to the origin, the target straight ahead
  Eigen::Matrix<double, 3, 4> Rt = cam.GetExtrinsicMatrix();
  EXPECT_LT((Rt * Eigen::Vector4d(2, 0, 0, 1)).norm(), 1e-12);
  EXPECT_LT((Rt * Eigen::Vector4d(0, 0, 0, 1) - Eigen::Vector3d(0, 0, 2)).norm(), 1e-12);
}

TEST_F(CameraTest, MountedCameraFollowsItsLinkAndActor) {
  Articulation lamp = AddLamp(scene_);
  Link arm = lamp.GetLink(1);
  Pose local(Eigen::Vector3d(0.4, 0, 0.1),
             Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY())));
  Camera cam = AddMountedCamera(scene_, "wrist", arm, local, 32, 24, 1.0, 0.01, 5.0);
  ExpectPoseNear(cam.GetPose(), arm.GetPose() * local);
  for (double q : {0.0, 0.7, -1.9}) {
    lamp.SetQpos(Eigen::VectorXd::Constant(1, q));
    UpdateRender(scene_);
    ExpectPoseNear(cam.GetPose(), arm.GetPose() * local);
    ExpectPoseNear(cam.GetLocalPose(), local);
  }
  // the camera really moved: the arm turns about world z through the hinge
  lamp.SetQpos(Eigen::VectorXd::Constant(1, 0.0));
  UpdateRender(scene_);
  Pose at0 = cam.GetPose();
  lamp.SetQpos(Eigen::VectorXd::Constant(1, M_PI / 2));
  UpdateRender(scene_);
  EXPECT_GT((cam.GetPose().p - at0.p).norm(), 0.3);
  EXPECT_NEAR(cam.GetPose().p.z(), at0.p.z(), 1e-9);
  // a new local pose applies at once
  Pose local2(Eigen::Vector3d(0, 0, 0.3));
  cam.SetLocalPose(local2);
  ExpectPoseNear(cam.GetPose(), arm.GetPose() * local2);

  // on an actor that falls
  Actor crate = AddCrate(scene_, Eigen::Vector3d(3, 0, 1));
  Camera cam2 = AddMountedCamera(scene_, "top", crate, local, 16, 16, 1.0, 0.01, 5.0);
  scene_.Step(100);
  UpdateRender(scene_);
  EXPECT_LT(crate.GetPose().p.z(), 0.99);
  ExpectPoseNear(cam2.GetPose(), crate.GetPose() * local);
  // the mount goes away: the camera stays where it was, now free
  Pose last = cam2.GetPose();
  scene_.RemoveActor(crate);
  UpdateRender(scene_);
  ExpectPoseNear(cam2.GetPose(), last);
  EXPECT_EQ(GetCameras(scene_).size(), 2u);
}

TEST_F(CameraTest, BadCameraArgumentsThrowAndLeaveTheSceneUnchanged) {
  auto expect_error = [&](auto&& f, const std::string& word) {
    size_t before = GetCameras(scene_).size();
    try {
      f();
      ADD_FAILURE() << "no error for " << word;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
    EXPECT_EQ(GetCameras(scene_).size(), before);
  };
  expect_error([&] { AddCamera(scene_, "c", 0, 10, 1.0, 0.1, 1.0); }, "width");
  expect_error([&] { AddCamera(scene_, "c", 10, 20000, 1.0, 0.1, 1.0); }, "height");
  expect_error([&] { AddCamera(scene_, "c", 10, -3, 1.0, 0.1, 1.0); }, "height");
  expect_error([&] { AddCamera(scene_, "c", 10, 10, 0.0, 0.1, 1.0); }, "fovy");
  expect_error([&] { AddCamera(scene_, "c", 10, 10, M_PI, 0.1, 1.0); }, "fovy");
  expect_error([&] { AddCamera(scene_, "c", 10, 10, kNaN, 0.1, 1.0); }, "fovy");
  expect_error([&] { AddCamera(scene_, "c", 10, 10, 1.0, 1.0, 1.0); }, "far");
  expect_error([&] { AddCamera(scene_, "c", 10, 10, 1.0, 2.0, 1.0); }, "far");
  expect_error([&] { AddCamera(scene_, "c", 10, 10, 1.0, 0.0, 1.0); }, "near");
  expect_error([&] { AddCamera(scene_, "c", 10, 10, 1.0, kNaN, 1.0); }, "near");
  Actor crate = AddCrate(scene_, Eigen::Vector3d(0, 0, 1));
  Pose bad(Eigen::Vector3d(kNaN, 0, 0));
  expect_error([&] { AddMountedCamera(scene_, "m", crate, bad, 8, 8, 1.0, 0.1, 1.0); },
               "local_pose");

  Camera cam = AddCamera(scene_, "ok", 8, 6, 1.0, 0.1, 1.0);
  expect_error([&] { cam.SetNearFar(0.5, 0.5); }, "far");
  expect_error([&] { cam.SetFovy(-1); }, "fovy");
  expect_error([&] { cam.SetIntrinsics(0, 1, 1, 1); }, "fx");
  expect_error([&] { cam.SetLocalPose(bad); }, "pose");
  expect_error([&] { cam.GetPictureData(); }, "take_picture");
  expect_error([&] { cam.GetDepth(); }, "take_picture");
  // the camera is unchanged by the refused calls
  EXPECT_EQ(cam.GetNear(), 0.1);
  EXPECT_EQ(cam.GetFar(), 1.0);
  EXPECT_NEAR(cam.GetFovy(), 1.0, 1e-12);
  ExpectPoseNear(cam.GetPose(), Pose());

  cam.TakePicture();
  expect_error([&] { cam.GetFloatPicture("Depth"); }, "Color, Albedo, Normal, Position");
  expect_error([&] { cam.GetUintPicture("Color"); }, "Segmentation");
  // the scene keeps working
  cam.TakePicture();
  EXPECT_EQ(cam.GetFloatPicture("Color").size(), 8u * 6 * 4);
  scene_.Step(10);
  UpdateRender(scene_);
}

TEST_F(CameraTest, PicturesHaveTheirSizesAndNamedOutputs) {
  Camera cam = AddCamera(scene_, "c", 7, 5, 1.0, 0.1, 10.0);
  cam.TakePicture();  // no UpdateRender yet: the picture builds the render world itself
  for (const char* name : {"Color", "Albedo", "Normal", "Position"}) {
    EXPECT_TRUE(IsFloatPictureName(name));
    EXPECT_EQ(cam.GetFloatPicture(name).size(), 7u * 5 * 4) << name;
  }
  EXPECT_FALSE(IsFloatPictureName("Segmentation"));
  EXPECT_EQ(cam.GetUintPicture("Segmentation").size(), 7u * 5 * 2);
  EXPECT_EQ(cam.GetDepth().size(), 7u * 5);
  EXPECT_EQ(cam.GetColorRGBA8().size(), 7u * 5 * 4);
  EXPECT_EQ(cam.GetPictureData().width, 7);
  EXPECT_EQ(cam.GetPictureData().height, 5);
}

TEST_F(CameraTest, ColorIsSrgbEncodedAndDepthIsPositionW) {
  SetRenderBackend(scene_, std::make_unique<PlaneBackend>(1.5, 0.5f));
  Camera cam = AddCamera(scene_, "c", 6, 4, 1.0, 0.1, 10.0);
  cam.TakePicture();
  std::vector<uint8_t> rgba = cam.GetColorRGBA8();
  std::vector<float> depth = cam.GetDepth();
  // pixel (1, 0): linear 0.5 is sRGB 188
  EXPECT_EQ(rgba[4 * 1 + 0], 188);
  EXPECT_EQ(rgba[4 * 1 + 3], 255);
  EXPECT_EQ(rgba[0], 0);  // left column: nothing
  EXPECT_FLOAT_EQ(depth[1], 1.5f);
  EXPECT_EQ(depth[0], 0.0f);
  EXPECT_EQ(cam.GetUintPicture("Segmentation")[2 * 1 + 1], 3u);
}

TEST_F(CameraTest, PictureOfSomeOutputsThrowsNamingAnOutputNotTaken) {
  auto backend = std::make_unique<PlaneBackend>(1.5, 0.5f);
  PlaneBackend* plane = backend.get();
  SetRenderBackend(scene_, std::move(backend));
  Camera cam = AddCamera(scene_, "c", 6, 4, 1.0, 0.1, 10.0);
  cam.TakePicture(kColor | kPosition);
  // the backend was asked for the mask; what it filled beyond it is dropped
  EXPECT_EQ(plane->last_outputs, unsigned{kColor | kPosition});
  EXPECT_EQ(cam.GetPictureData().outputs, unsigned{kColor | kPosition});
  EXPECT_EQ(cam.GetFloatPicture("Color").size(), 6u * 4 * 4);
  EXPECT_EQ(cam.GetFloatPicture("Position").size(), 6u * 4 * 4);
  EXPECT_FLOAT_EQ(cam.GetDepth()[1], 1.5f);
  EXPECT_EQ(cam.GetColorRGBA8()[4 * 1], 188);
  EXPECT_TRUE(cam.GetPictureData().normal.empty());
  EXPECT_TRUE(cam.GetPictureData().segmentation.empty());
  for (const char* name : {"Normal", "Albedo"}) {
    try {
      cam.GetFloatPicture(name);
      ADD_FAILURE() << name << " did not throw";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), std::string("camera 'c': picture '") + name +
                                           "' was not taken: TakePicture was asked for Color, "
                                           "Position");
    }
  }
  EXPECT_THROW(cam.GetUintPicture("Segmentation"), Error);
  // a point cloud needs Position only: colours come along, ids do not
  PointCloud cloud = MakePointCloud(cam);
  EXPECT_EQ(cloud.Size(), 5u * 4);  // the left column sees nothing
  EXPECT_EQ(cloud.colors.size(), 4 * cloud.Size());
  EXPECT_TRUE(cloud.visual_ids.empty());
  // Position alone: colour is not there
  cam.TakePicture(kPosition);
  EXPECT_THROW(cam.GetColorRGBA8(), Error);
  EXPECT_EQ(cam.GetDepth().size(), 6u * 4);
  cam.TakePicture(kSegmentation);
  try {
    cam.GetDepth();
    ADD_FAILURE() << "GetDepth did not throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("picture 'Position' was not taken"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("asked for Segmentation"), std::string::npos) << e.what();
  }
  // all outputs again by default; an empty or unknown mask is refused
  cam.TakePicture();
  EXPECT_EQ(cam.GetFloatPicture("Normal").size(), 6u * 4 * 4);
  EXPECT_THROW(cam.TakePicture(0), Error);
  EXPECT_THROW(cam.TakePicture(64), Error);
  EXPECT_EQ(PictureOutputFromName("Segmentation"), unsigned{kSegmentation});
  EXPECT_THROW(PictureOutputFromName("Depth"), Error);
  EXPECT_EQ(PictureOutputNames(kAllOutputs), "Color, Albedo, Normal, Position, Segmentation");
}

TEST_F(CameraTest, SharedPictureSurvivesTheNextPicture) {
  auto backend = std::make_unique<PlaneBackend>(1.0);
  PlaneBackend* plane = backend.get();
  SetRenderBackend(scene_, std::move(backend));
  Camera cam = AddCamera(scene_, "c", 4, 4, 1.0, 0.1, 10.0);
  cam.TakePicture();
  std::shared_ptr<const Picture> first = cam.GetSharedPicture();
  const float* first_data = first->position.data();
  cam.TakePicture();
  // the held picture is untouched, the camera has a new one
  EXPECT_NE(cam.GetSharedPicture().get(), first.get());
  EXPECT_EQ(first->position.data(), first_data);
  EXPECT_EQ(first->position[4 * 1 + 3], 1.0f);
  EXPECT_EQ(plane->renders, 2);
  // with nothing held the picture is reused
  first.reset();
  const Picture* current = &cam.GetPictureData();
  cam.TakePicture();
  EXPECT_EQ(&cam.GetPictureData(), current);
}

// PlaneBackend that, when `fail` is set, overwrites part of the picture and then throws
class FailingBackend : public PlaneBackend {
 public:
  bool fail = false;

 protected:
  void DoRender(const RenderWorld& world, const CameraParams& camera, Picture* out,
                unsigned outputs) override {
    PlaneBackend::DoRender(world, camera, out, outputs);
    if (!fail) return;
    out->color.assign(out->color.size(), -1.0f);
    throw Error("test backend lost its device");
  }
};

TEST_F(CameraTest, RefusedOutputsKeepTheLastPictureAndAFailedRenderDropsIt) {
  auto backend = std::make_unique<FailingBackend>();
  FailingBackend* failing = backend.get();
  SetRenderBackend(scene_, std::move(backend));
  Camera cam = AddCamera(scene_, "c", 4, 3, 1.0, 0.1, 10.0);
  cam.TakePicture(kColor);
  const std::vector<float> color = cam.GetFloatPicture("Color");
  // the backend's Render refuses the outputs before it renders: the last picture stays
  for (unsigned outputs : {0u, 64u}) {
    try {
      cam.TakePicture(outputs);
      ADD_FAILURE() << "no error for outputs " << outputs;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("outputs must name at least one of"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(failing->renders, 1);
  EXPECT_EQ(cam.GetFloatPicture("Color"), color);
  // the backend fails halfway through the reused picture: no picture rather than a torn one
  failing->fail = true;
  EXPECT_THROW(cam.TakePicture(kColor), Error);
  EXPECT_EQ(failing->renders, 2);
  EXPECT_THROW(cam.GetPictureData(), Error);
}

TEST_F(CameraTest, RemovedCameraHandleThrows) {
  Camera cam = AddCamera(scene_, "c", 4, 4, 1.0, 0.1, 10.0);
  Camera other = AddCamera(scene_, "d", 4, 4, 1.0, 0.1, 10.0);
  EXPECT_NE(cam.GetId(), other.GetId());
  RemoveCamera(scene_, cam);
  EXPECT_THROW(cam.GetName(), Error);
  EXPECT_THROW(RemoveCamera(scene_, cam), Error);
  EXPECT_THROW(Camera().GetWidth(), Error);
  ASSERT_EQ(GetCameras(scene_).size(), 1u);
  EXPECT_EQ(GetCameras(scene_)[0].GetName(), "d");
}

TEST_F(CameraTest, CloneKeepsCameras) {
  Camera cam = AddCamera(scene_, "c", 40, 30, 0.8, 0.1, 10.0);
  cam.SetLocalPose(Pose(Eigen::Vector3d(1, 2, 3)));
  std::unique_ptr<Scene> copy = scene_.Clone();
  ASSERT_EQ(GetCameras(*copy).size(), 1u);
  Camera c2 = GetCameras(*copy)[0];
  EXPECT_EQ(c2.GetName(), "c");
  EXPECT_NEAR(c2.GetFovy(), 0.8, 1e-12);
  ExpectPoseNear(c2.GetPose(), cam.GetPose());
  SetRenderBackend(*copy, "null");
  c2.TakePicture();
  EXPECT_EQ(c2.GetDepth().size(), 1200u);
}

}  // namespace
}  // namespace partsim

namespace partsim {
namespace {

// LookAt: the view axis goes through the target, z follows `up`, and a mounted camera takes
// eye and target in its mount's frame.
TEST_F(CameraTest, LookAtPointsTheCameraAtTheTarget) {
  Camera cam = AddCamera(scene_, "c", 64, 48, 1.0, 0.01, 10.0);
  const Eigen::Vector3d eye(1.0, -2.0, 1.5), target(0.2, 0.3, 0.4);
  cam.LookAt(eye, target);
  Pose X = cam.GetPose();
  EXPECT_LT((X.p - eye).norm(), 1e-12);
  const Eigen::Matrix3d R = X.q.toRotationMatrix();
  EXPECT_LT((R.col(0) - (target - eye).normalized()).norm(), 1e-12);
  EXPECT_NEAR(R.col(1).z(), 0.0, 1e-12);  // no roll: y horizontal
  EXPECT_GT(R.col(2).z(), 0.0);           // z up
  ExpectPoseNear(X, LookAt(eye, target));
  // the target projects onto the principal point
  Eigen::Vector3d t_C = X.q.inverse() * (target - X.p);
  EXPECT_NEAR(t_C.y(), 0.0, 1e-12);
  EXPECT_NEAR(t_C.z(), 0.0, 1e-12);

  // another up: z as close to world x as possible
  cam.LookAt(Eigen::Vector3d(0, 0, 3), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  Eigen::Matrix3d Rx = cam.GetPose().q.toRotationMatrix();
  EXPECT_LT((Rx.col(0) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
  EXPECT_LT((Rx.col(2) - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  // straight down with z up: y is the world's y (as before up was an argument)
  cam.LookAt(Eigen::Vector3d(0, 0, 3), Eigen::Vector3d::Zero());
  Eigen::Matrix3d Rd = cam.GetPose().q.toRotationMatrix();
  EXPECT_LT((Rd.col(1) - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_NEAR(Rd.determinant(), 1.0, 1e-12);

  // mounted: in the mount's frame
  Actor crate = AddCrate(scene_, Eigen::Vector3d(3, 0, 1));
  Camera wrist = AddMountedCamera(scene_, "m", crate, Pose(), 16, 16, 1.0, 0.01, 5.0);
  wrist.LookAt(Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d::Zero());
  ExpectPoseNear(wrist.GetLocalPose(), LookAt(Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d::Zero()));
  ExpectPoseNear(wrist.GetPose(), crate.GetPose() * wrist.GetLocalPose());

  // bad input names the camera and what is wrong, and leaves the pose as it was
  Pose before = cam.GetLocalPose();
  auto message = [&](const Eigen::Vector3d& e, const Eigen::Vector3d& t, const Eigen::Vector3d& u) {
    try {
      cam.LookAt(e, t, u);
    } catch (const Error& err) {
      return std::string(err.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(message(eye, eye, Eigen::Vector3d::UnitZ()).find("same point"), std::string::npos);
  EXPECT_NE(message(eye, target, Eigen::Vector3d::Zero()).find("up"), std::string::npos);
  std::string m = message(Eigen::Vector3d(kNaN, 0, 0), target, Eigen::Vector3d::UnitZ());
  EXPECT_NE(m.find("camera 'c'"), std::string::npos) << m;
  EXPECT_NE(m.find("finite"), std::string::npos) << m;
  ExpectPoseNear(cam.GetLocalPose(), before);
}

}  // namespace
}  // namespace partsim
