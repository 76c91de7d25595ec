// Camera-frame positions from a depth buffer: how the rasterizer's forward path fills "Position".
#pragma once

#include <Eigen/Core>

namespace partsim::internal {

/// Fills `position` (width * height * 4 floats, row-major, row 0 first) from `depth` (width *
/// height window depth values in [0, 1], as glReadPixels returns them with the projection's rows
/// flipped so that row 0 is the image's top row) and the projection `P` that drew them: for each
/// pixel the point (x, y, z) in the OpenGL camera frame whose projection is the pixel's centre at
/// that depth, and w = -z (the depth along the view axis). Pixels whose depth is not below 1 (the
/// clear value: no surface) get four zeros.
///
/// Accuracy: the depth buffer's own resolution, about z^2 / near * 6e-8 m for a perspective
/// projection, plus float rounding of the result. Projections whose x and y rows do not depend
/// on z the usual way (P(2, 0..1) or P(3, 0..1) non-zero) take a slower exact path.
///
/// Only rows [row_begin, row_end) are written (row_end < 0: to the last row), so that threads can
/// share an image; `depth` and `position` still point at the whole image.
///
/// `kernel` picks the inner loop, for tests: kVector (SSE2 where the build has it, else the
/// scalar loop) or kScalar. They do the same float operations in the same order, so on x86-64
/// they give the same bits.
enum class PositionKernel { kVector, kScalar };
void PositionFromDepth(const Eigen::Matrix4d& P, int width, int height, const float* depth,
                       float* position, int row_begin = 0, int row_end = -1,
                       PositionKernel kernel = PositionKernel::kVector);

}  // namespace partsim::internal
