#include "render/depth_to_position.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <random>
#include <vector>

namespace partsim::internal {
namespace {

// a perspective projection as cameras build it (rows flipped), with a principal point off the
// centre and a little skew
Eigen::Matrix4d Perspective(double near, double far) {
  const double f = 1.0 / std::tan(0.5);
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = 0.9 * f;
  P(0, 1) = 0.03;
  P(0, 2) = 0.01;
  P(1, 1) = -f;
  P(1, 2) = -0.02;
  P(2, 2) = -(far + near) / (far - near);
  P(2, 3) = -2 * far * near / (far - near);
  P(3, 2) = -1;
  return P;
}

// the window depth in [0, 1] of a point at depth z (> 0) along the view axis, rounded to float
// as the depth buffer stores it
float WindowDepth(const Eigen::Matrix4d& P, const Eigen::Vector3d& p) {
  Eigen::Vector4d clip = P * p.homogeneous();
  return static_cast<float>(0.5 * clip.z() / clip.w() + 0.5);
}

// the camera-frame point of pixel (u, v) at window depth d, by a 3 x 3 solve in long double
Eigen::Vector3d Reference(const Eigen::Matrix4d& P, int w, int h, int u, int v, float d) {
  using M3 = Eigen::Matrix<long double, 3, 3>;
  using V3 = Eigen::Matrix<long double, 3, 1>;
  V3 ndc((u + 0.5L) * 2 / w - 1, (v + 0.5L) * 2 / h - 1, 2.0L * d - 1);
  M3 A;
  V3 b;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) A(r, c) = P(r, c) - ndc(r) * P(3, c);
    b(r) = ndc(r) * P(3, 3) - P(r, 3);
  }
  V3 p = A.fullPivLu().solve(b);
  return p.cast<double>();
}

struct Errors {
  double worst = 0;  // largest error over its bound
  int background_wrong = 0;
};

// random depths (a few at the clear value 1) in a w x h image; the error of every output
// against Reference() for the same depth values, over a bound: 0.6 of the depth buffer's
// resolution there (one float step of the depth, about z^2 / near * 6e-8 m) plus two float steps
// of the largest coordinate. (Without the split arithmetic the error reaches 0.8 of a depth step.)
Errors Check(const Eigen::Matrix4d& P, int w, int h, double near, double far) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> depth(near, far);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<float> d(static_cast<size_t>(w) * h);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      size_t i = static_cast<size_t>(v) * w + u;
      d[i] =
          (i % 37 == 5) ? 1.0f : WindowDepth(P, Eigen::Vector3d(unit(rng), unit(rng), -depth(rng)));
    }
  }
  std::vector<float> out(4 * d.size(), -7.0f);
  PositionFromDepth(P, w, h, d.data(), out.data());
  Errors e;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      size_t i = static_cast<size_t>(v) * w + u;
      const float* o = &out[4 * i];
      if (!(d[i] < 1.0f)) {
        e.background_wrong += o[0] != 0 || o[1] != 0 || o[2] != 0 || o[3] != 0;
        continue;
      }
      Eigen::Vector3d p = Reference(P, w, h, u, v, d[i]);
      double z = -p.z();
      for (int c = 0; c < 3; ++c) {
        double bound = z * z / near * 3.6e-8 + 2.4e-7 * p.cwiseAbs().maxCoeff() + 1e-12;
        e.worst = std::max(e.worst, std::abs(o[c] - p(c)) / bound);
      }
      e.worst = std::max(e.worst, std::abs(o[3] - z) / (2.4e-7 * z + z * z / near * 3.6e-8));
    }
  }
  return e;
}

TEST(DepthToPositionTest, PerspectiveMatchesAnExactSolveWithinTheDepthResolution) {
  // widths that are and are not multiples of four (the vector loop and its scalar tail)
  for (int w : {64, 61}) {
    for (double near : {0.01, 0.05}) {
      for (double far : {10.0, 100.0}) {
        Errors e = Check(Perspective(near, far), w, 48, near, far);
        EXPECT_LE(e.worst, 1.0) << "w " << w << " near " << near << " far " << far;
        EXPECT_EQ(e.background_wrong, 0);
      }
    }
  }
}

TEST(DepthToPositionTest, EveryKernelGivesTheSameFloats) {
  // the scalar and SSE2 loops on a row length that leaves a tail
  const int w = 45, h = 9;
  Eigen::Matrix4d P = Perspective(0.05, 10.0);
  std::vector<float> d(w * h);
  for (int i = 0; i < w * h; ++i) d[i] = (i % 11 == 3) ? 1.0f : 0.95f + 0.0049f * (i % 10);
  std::vector<float> scalar(4 * w * h, -1.0f);
  PositionFromDepth(P, w, h, d.data(), scalar.data(), 0, -1, PositionKernel::kScalar);
  std::vector<float> vector(4 * w * h, -1.0f);
  PositionFromDepth(P, w, h, d.data(), vector.data(), 0, -1, PositionKernel::kVector);
#if defined(__x86_64__)
  EXPECT_EQ(vector, scalar);
#else
  for (size_t i = 0; i < vector.size(); ++i)
    ASSERT_NEAR(vector[i], scalar[i], 1e-6 * std::abs(scalar[i]));
#endif
  std::vector<float> by_default(4 * w * h, -1.0f);
  PositionFromDepth(P, w, h, d.data(), by_default.data());
  EXPECT_EQ(by_default, vector);
  // rows can be filled in pieces
  std::vector<float> pieces(4 * w * h, -1.0f);
  PositionFromDepth(P, w, h, d.data(), pieces.data(), 0, 4, PositionKernel::kScalar);
  PositionFromDepth(P, w, h, d.data(), pieces.data(), 4, h, PositionKernel::kScalar);
  EXPECT_EQ(pieces, scalar);
}

TEST(DepthToPositionTest, OrthographicProjection) {
  // z's denominator is constant (P(3, 2) = 0): the other branch of the split arithmetic
  Eigen::Matrix4d P = Eigen::Matrix4d::Identity();
  const double near = 0.1, far = 5.0;
  P(0, 0) = 1.0 / 1.5;
  P(1, 1) = -1.0 / 1.2;
  P(2, 2) = -2.0 / (far - near);
  P(2, 3) = -(far + near) / (far - near);
  Errors e = Check(P, 37, 20, near, far);
  EXPECT_LE(e.worst, 1.0);
  EXPECT_EQ(e.background_wrong, 0);
}

TEST(DepthToPositionTest, OtherProjectionsTakeTheExactPath) {
  // w depends on x: not the separable form the fast path needs
  Eigen::Matrix4d P = Perspective(0.05, 10.0);
  P(3, 0) = 0.05;
  Errors e = Check(P, 23, 17, 0.05, 10.0);
  EXPECT_LE(e.worst, 1.0);
  EXPECT_EQ(e.background_wrong, 0);
}

TEST(DepthToPositionTest, PointsProjectBackOntoTheirPixels) {
  // every output point lies on its pixel's centre ray: projecting it gives the pixel back
  const int w = 40, h = 30;
  Eigen::Matrix4d P = Perspective(0.05, 20.0);
  std::vector<float> d(w * h);
  for (int i = 0; i < w * h; ++i) d[i] = 0.9f + 0.099f * static_cast<float>(i) / (w * h);
  std::vector<float> out(4 * w * h);
  PositionFromDepth(P, w, h, d.data(), out.data());
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const float* o = &out[4 * (v * w + u)];
      Eigen::Vector4d clip = P * Eigen::Vector4d(o[0], o[1], o[2], 1.0);
      EXPECT_NEAR((clip.x() / clip.w() + 1) * 0.5 * w - 0.5, u, 1e-3);
      EXPECT_NEAR((clip.y() / clip.w() + 1) * 0.5 * h - 0.5, v, 1e-3);
      EXPECT_NEAR(0.5 * clip.z() / clip.w() + 0.5, d[v * w + u], 1e-6);
    }
  }
}

}  // namespace
}  // namespace partsim::internal
