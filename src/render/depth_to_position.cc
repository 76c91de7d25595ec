// Camera-frame positions from a depth buffer.
//
// For the projections cameras use (x and y clip coordinates linear in x, y, z; z and w clip
// coordinates depending on z alone) the depth along the view axis of a pixel follows from its
// depth value d alone, z = (a1 d + a0) / (b1 d + b0), and then x and y are affine in z with
// coefficients that depend on the pixel's column and row. The inner loop computes that in float,
// four pixels at a time where SSE2 is there. Float keeps the depth buffer's resolution because
// the numerator and denominator are evaluated as a1 * (d - m), with m = -a0 / a1 split into two
// floats: near the far plane, where d and m are close, d - m.hi is exact (Sterbenz) and the
// second float restores the bits that one float of m would lose.
#include "render/depth_to_position.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace partsim::internal {
namespace {

// x as the sum of two floats, hi + lo, about 48 bits of its mantissa
struct SplitFloat {
  float hi = 0, lo = 0;
};
SplitFloat Split(double x) {
  SplitFloat s;
  s.hi = static_cast<float>(x);
  s.lo = static_cast<float>(x - s.hi);
  return s;
}

// the OpenGL NDC coordinate of the centre of pixel i of `size`
double Ndc(int i, int size) { return (i + 0.5) * 2.0 / size - 1.0; }

// any projection: a 3 x 3 solve per pixel, in double
void GeneralPositionFromDepth(const Eigen::Matrix4d& P, int w, int h, const float* depth,
                              float* position, int row_begin, int row_end) {
  for (int v = row_begin; v < row_end; ++v) {
    for (int u = 0; u < w; ++u) {
      size_t i = static_cast<size_t>(v) * w + u;
      float* out = position + 4 * i;
      if (!(depth[i] < 1.0f)) {
        out[0] = out[1] = out[2] = out[3] = 0.0f;
        continue;
      }
      Eigen::Vector3d p_ndc(Ndc(u, w), Ndc(v, h), 2.0 * depth[i] - 1.0);
      Eigen::Matrix3d A;
      Eigen::Vector3d b;
      for (int r = 0; r < 3; ++r) {
        Eigen::Vector4d row = P.row(r).transpose() - p_ndc(r) * P.row(3).transpose();
        A.row(r) = row.head<3>().transpose();
        b(r) = -row(3);
      }
      Eigen::Vector3d p = A.partialPivLu().solve(b);
      out[0] = static_cast<float>(p.x());
      out[1] = static_cast<float>(p.y());
      out[2] = static_cast<float>(p.z());
      out[3] = static_cast<float>(-p.z());
    }
  }
}

}  // namespace

void PositionFromDepth(const Eigen::Matrix4d& P, int w, int h, const float* depth, float* position,
                       int row_begin, int row_end) {
  if (row_end < 0 || row_end > h) row_end = h;
  row_begin = std::max(row_begin, 0);
  Eigen::Matrix2d A;
  A << P(0, 0), P(0, 1), P(1, 0), P(1, 1);
  bool separable = P(2, 0) == 0 && P(2, 1) == 0 && P(3, 0) == 0 && P(3, 1) == 0;
  if (!separable || A.determinant() == 0) {
    GeneralPositionFromDepth(P, w, h, depth, position, row_begin, row_end);
    return;
  }
  // rows 2 and 3 of P give z from the NDC depth 2 d - 1: z = (a1 d + a0) / (b1 d + b0)
  const double a1 = 2 * P(3, 3), a0 = -P(3, 3) - P(2, 3);
  const double b1 = -2 * P(3, 2), b0 = P(2, 2) + P(3, 2);
  // a1 d + a0 = a1 (d - m) when a1 != 0 (else a0, with num_on = 0), likewise b1 d + b0
  const float num_on = a1 != 0 ? 1.0f : 0.0f, den_on = b1 != 0 ? 1.0f : 0.0f;
  const SplitFloat m = Split(a1 != 0 ? -a0 / a1 : 0.0);
  const SplitFloat k = Split(b1 != 0 ? -b0 / b1 : 0.0);
  const float scale = static_cast<float>((a1 != 0 ? a1 : a0) / (b1 != 0 ? b1 : b0));

  // rows 0 and 1: A [x y]^T = z c1 + c0 with c's rows depending on the column (x) or the row
  // (y) alone, so [x y] = z (column term + row term) + (column term + row term)
  Eigen::Matrix2d A_inv = A.inverse();
  std::vector<float> cx1(w), cx0(w), cy1(w), cy0(w);
  for (int u = 0; u < w; ++u) {
    double c1 = Ndc(u, w) * P(3, 2) - P(0, 2), c0 = Ndc(u, w) * P(3, 3) - P(0, 3);
    cx1[u] = static_cast<float>(A_inv(0, 0) * c1);
    cx0[u] = static_cast<float>(A_inv(0, 0) * c0);
    cy1[u] = static_cast<float>(A_inv(1, 0) * c1);
    cy0[u] = static_cast<float>(A_inv(1, 0) * c0);
  }

  for (int v = row_begin; v < row_end; ++v) {
    double r1 = Ndc(v, h) * P(3, 2) - P(1, 2), r0 = Ndc(v, h) * P(3, 3) - P(1, 3);
    const float rx1 = static_cast<float>(A_inv(0, 1) * r1);
    const float rx0 = static_cast<float>(A_inv(0, 1) * r0);
    const float ry1 = static_cast<float>(A_inv(1, 1) * r1);
    const float ry0 = static_cast<float>(A_inv(1, 1) * r0);
    const float* d = depth + static_cast<size_t>(v) * w;
    float* out = position + 4 * static_cast<size_t>(v) * w;
    int u = 0;
#if defined(__SSE2__)
    const __m128 one = _mm_set1_ps(1.0f), zero = _mm_setzero_ps();
    const __m128 v_num_on = _mm_set1_ps(num_on), v_num_off = _mm_set1_ps(1.0f - num_on);
    const __m128 v_den_on = _mm_set1_ps(den_on), v_den_off = _mm_set1_ps(1.0f - den_on);
    const __m128 m_hi = _mm_set1_ps(m.hi), m_lo = _mm_set1_ps(m.lo);
    const __m128 k_hi = _mm_set1_ps(k.hi), k_lo = _mm_set1_ps(k.lo);
    const __m128 v_scale = _mm_set1_ps(scale);
    const __m128 v_rx1 = _mm_set1_ps(rx1), v_rx0 = _mm_set1_ps(rx0);
    const __m128 v_ry1 = _mm_set1_ps(ry1), v_ry0 = _mm_set1_ps(ry0);
    for (; u + 4 <= w; u += 4) {
      __m128 dd = _mm_loadu_ps(d + u);
      __m128 num =
          _mm_add_ps(_mm_mul_ps(v_num_on, _mm_sub_ps(_mm_sub_ps(dd, m_hi), m_lo)), v_num_off);
      __m128 den =
          _mm_add_ps(_mm_mul_ps(v_den_on, _mm_sub_ps(_mm_sub_ps(dd, k_hi), k_lo)), v_den_off);
      __m128 valid = _mm_cmplt_ps(dd, one);
      // where there is no surface den may be 0: the division's result is masked out
      __m128 z = _mm_and_ps(valid, _mm_div_ps(_mm_mul_ps(v_scale, num), den));
      __m128 x = _mm_add_ps(_mm_mul_ps(z, _mm_add_ps(_mm_loadu_ps(&cx1[u]), v_rx1)),
                            _mm_add_ps(_mm_loadu_ps(&cx0[u]), v_rx0));
      __m128 y = _mm_add_ps(_mm_mul_ps(z, _mm_add_ps(_mm_loadu_ps(&cy1[u]), v_ry1)),
                            _mm_add_ps(_mm_loadu_ps(&cy0[u]), v_ry0));
      x = _mm_and_ps(valid, x);
      y = _mm_and_ps(valid, y);
      __m128 w_axis = _mm_sub_ps(zero, z);
      _MM_TRANSPOSE4_PS(x, y, z, w_axis);  // now one pixel's x y z w per register
      _mm_storeu_ps(out + 4 * u, x);
      _mm_storeu_ps(out + 4 * u + 4, y);
      _mm_storeu_ps(out + 4 * u + 8, z);
      _mm_storeu_ps(out + 4 * u + 12, w_axis);
    }
#endif
    for (; u < w; ++u) {
      float* o = out + 4 * u;
      if (!(d[u] < 1.0f)) {
        o[0] = o[1] = o[2] = o[3] = 0.0f;
        continue;
      }
      float num = num_on * ((d[u] - m.hi) - m.lo) + (1.0f - num_on);
      float den = den_on * ((d[u] - k.hi) - k.lo) + (1.0f - den_on);
      float z = scale * num / den;
      o[0] = z * (cx1[u] + rx1) + (cx0[u] + rx0);
      o[1] = z * (cy1[u] + ry1) + (cy0[u] + ry0);
      o[2] = z;
      o[3] = -z;
    }
  }
}

}  // namespace partsim::internal
