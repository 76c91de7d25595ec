// Camera frames and matrices shared by cameras and backends.
//
// Frames: C is partsim's camera frame (x forward, y left, z up, as SAPIEN); G is the OpenGL
// camera frame (x right, y up, z backward); O is the OpenCV camera frame (x right, y down,
// z forward). Intrinsics K follow OpenCV: pixel (u, v) has its centre at integer coordinates,
// u to the right, v down, row 0 at the top of the image.
#pragma once

#include <Eigen/Core>

#include "partsim/core/pose.h"
#include "partsim/render/backend.h"

namespace partsim {

/// R_CG: the OpenGL camera frame's axes in partsim's camera frame.
Eigen::Matrix3d RotationCameraToGl();
/// R_CO: the OpenCV camera frame's axes in partsim's camera frame.
Eigen::Matrix3d RotationCameraToCv();

/// Camera pose X_WC (x forward, y left, z up) at `eye` looking at `target`, with z as close to
/// `up` as possible (looking along `up`: y is taken from the world axis least aligned with the
/// view). Throws partsim::Error when an argument is not finite, eye and target coincide or up
/// is zero.
Pose CameraLookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                  const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

/// K for a vertical field of view (rad) with square pixels and a centred principal point
/// (cx = (width - 1) / 2, cy = (height - 1) / 2).
Eigen::Matrix3d IntrinsicsFromFovy(int width, int height, double fovy);

/// OpenGL projection (camera G -> clip) for K, image size and clipping distances, such that a
/// pixel centre of the framebuffer maps to the OpenCV pixel centre of the same row and column.
Eigen::Matrix4d ProjectionFromIntrinsics(const Eigen::Matrix3d& K, int width, int height,
                                         double near, double far);

/// Everything a backend needs, from size, K, clipping distances and the camera pose X_WC.
CameraParams MakeCameraParams(int width, int height, const Eigen::Matrix3d& K, double near,
                              double far, const Pose& X_WC);

}  // namespace partsim
