#include "partsim/render/camera_math.h"

#include <cmath>

#include "partsim/core/error.h"

namespace partsim {

Eigen::Matrix3d RotationCameraToGl() {
  Eigen::Matrix3d r;
  // columns: G's x (right) = -y_C, G's y (up) = z_C, G's z (backward) = -x_C
  r << 0, 0, -1,  //
      -1, 0, 0,   //
      0, 1, 0;
  return r;
}

Eigen::Matrix3d RotationCameraToCv() {
  Eigen::Matrix3d r;
  // columns: O's x (right) = -y_C, O's y (down) = -z_C, O's z (forward) = x_C
  r << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return r;
}

Eigen::Matrix3d IntrinsicsFromFovy(int width, int height, double fovy) {
  double f = 0.5 * height / std::tan(0.5 * fovy);
  Eigen::Matrix3d K;
  K << f, 0, 0.5 * (width - 1),  //
      0, f, 0.5 * (height - 1),  //
      0, 0, 1;
  return K;
}

Eigen::Matrix4d ProjectionFromIntrinsics(const Eigen::Matrix3d& K, int width, int height,
                                         double near, double far) {
  // OpenCV pixel centres sit at integers, OpenGL's at half-integers: shift by half a pixel
  double fx = K(0, 0), fy = K(1, 1), cx = K(0, 2) + 0.5, cy = K(1, 2) + 0.5;
  double w = width, h = height;
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = 2 * fx / w;
  p(0, 1) = 2 * K(0, 1) / w;  // skew
  p(0, 2) = 1 - 2 * cx / w;
  p(1, 1) = 2 * fy / h;
  p(1, 2) = 2 * cy / h - 1;
  p(2, 2) = -(far + near) / (far - near);
  p(2, 3) = -2 * far * near / (far - near);
  p(3, 2) = -1;
  return p;
}

CameraParams MakeCameraParams(int width, int height, const Eigen::Matrix3d& K, double near,
                              double far, const Pose& X_WC) {
  CameraParams c;
  c.width = width;
  c.height = height;
  c.K = K;
  c.near = near;
  c.far = far;
  c.X_WC = X_WC;
  Eigen::Matrix4d X_WG = X_WC.ToMatrix();
  X_WG.topLeftCorner<3, 3>() = X_WG.topLeftCorner<3, 3>() * RotationCameraToGl();
  c.view = X_WG.inverse();
  c.projection = ProjectionFromIntrinsics(K, width, height, near, far);
  return c;
}

Pose CameraLookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                  const Eigen::Vector3d& up) {
  if (!eye.allFinite() || !target.allFinite() || !up.allFinite())
    throw Error("look_at: eye, target and up must be finite");
  const Eigen::Vector3d forward = target - eye;
  if (!(forward.norm() > 1e-9))
    throw Error("look_at: eye and target are the same point; the view direction is undefined");
  if (!(up.norm() > 1e-9)) throw Error("look_at: up must not be the zero vector");
  const Eigen::Vector3d x = forward.normalized();
  Eigen::Vector3d y = up.normalized().cross(x);
  if (y.norm() < 1e-9) {
    // looking along up: y is the first of the world's y, x, z not close to the view, made
    // orthogonal to it (looking straight down with z up: y is the world's y)
    for (int k : {1, 0, 2}) {
      const Eigen::Vector3d c = Eigen::Vector3d::Unit(k);
      if (std::abs(c.dot(x)) < 0.9) {
        y = c - c.dot(x) * x;
        break;
      }
    }
  }
  y.normalize();
  Eigen::Matrix3d R;
  R << x, y, x.cross(y);
  return Pose(eye, Eigen::Quaterniond(R));
}

}  // namespace partsim
