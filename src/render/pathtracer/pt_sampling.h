// Internal to the path tracer: random numbers, direction sampling and the material model
// (Oren-Nayar diffuse + GGX specular, the metallic/roughness model of the rasterizer).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace partsim::internal {

constexpr float kPi = 3.14159265358979323846f;

/// SplitMix64 finaliser: a bijective 64-bit mix.
inline uint64_t Mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// PCG32 (O'Neill), seeded per (seed, pixel, sample) so that an image does not depend on how
/// pixels are spread over threads.
class Pcg32 {
 public:
  Pcg32(uint64_t seed, uint64_t pixel, uint64_t sample) {
    uint64_t s = Mix64(seed ^ Mix64(pixel ^ Mix64(sample + 0x632be59bd9b4e019ull)));
    inc_ = (Mix64(s ^ 0xda3e39cb94b95bdbull) << 1u) | 1u;
    state_ = 0;
    Next();
    state_ += s;
    Next();
  }
  uint32_t Next() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  /// Uniform in [0, 1).
  float Uniform() { return static_cast<float>(Next() >> 8) * (1.0f / 16777216.0f); }

 private:
  uint64_t state_ = 0;
  uint64_t inc_ = 1;
};

using Vec3 = Eigen::Vector3f;

inline float Luminance(const Vec3& c) {
  return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
}

/// An orthonormal basis (t, b, n) around unit n (Duff et al. 2017).
inline void OrthoBasis(const Vec3& n, Vec3* t, Vec3* b) {
  float sign = std::copysign(1.0f, n.z());
  float a = -1.0f / (sign + n.z());
  float c = n.x() * n.y() * a;
  *t = Vec3(1.0f + sign * n.x() * n.x() * a, sign * c, -sign * n.x());
  *b = Vec3(c, sign + n.y() * n.y() * a, -n.y());
}

/// Local (x, y, z) around n to world.
inline Vec3 FromLocal(const Vec3& n, const Vec3& local) {
  Vec3 t, b;
  OrthoBasis(n, &t, &b);
  return t * local.x() + b * local.y() + n * local.z();
}

/// Cosine-weighted direction about +z; pdf = cos / pi.
inline Vec3 SampleCosineLocal(float u1, float u2) {
  float r = std::sqrt(u1);
  float phi = 2.0f * kPi * u2;
  return Vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1)));
}

/// Uniform direction in a cone of half angle acos(cos_max) about +z.
inline Vec3 SampleConeLocal(float u1, float u2, float cos_max) {
  float c = 1.0f - u1 * (1.0f - cos_max);
  float s = std::sqrt(std::max(0.0f, 1.0f - c * c));
  float phi = 2.0f * kPi * u2;
  return Vec3(s * std::cos(phi), s * std::sin(phi), c);
}

/// Uniform point on the unit disk.
inline Eigen::Vector2f SampleDisk(float u1, float u2) {
  float r = std::sqrt(u1);
  float phi = 2.0f * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi)};
}

/// A surface point's material, ready to shade: the rasterizer's model, i.e. Oren-Nayar diffuse
/// (sigma = roughness) weighted by (1 - F) (1 - metallic), GGX specular (alpha = roughness^2,
/// Smith-Schlick G with k = alpha / 2, Schlick Fresnel with F0 = mix(0.04, base, metallic)),
/// roughness clamped to [0.05, 1].
struct Bsdf {
  Vec3 base;
  float metallic;
  Vec3 f0;       ///< specular reflectance at normal incidence
  float alpha;   ///< GGX alpha = roughness^2
  float on_a;    ///< Oren-Nayar A
  float on_b;    ///< Oren-Nayar B
  float p_spec;  ///< probability of sampling the specular lobe

  Bsdf(const Vec3& base_color, float roughness, float metallic_in, float n_dot_v) {
    base = base_color;
    metallic = std::clamp(metallic_in, 0.0f, 1.0f);
    float r = std::clamp(roughness, 0.05f, 1.0f);
    alpha = r * r;
    float sigma2 = r * r;
    on_a = 1.0f - 0.5f * sigma2 / (sigma2 + 0.33f);
    on_b = 0.45f * sigma2 / (sigma2 + 0.09f);
    f0 = Vec3::Constant(0.04f) * (1.0f - metallic) + base * metallic;
    float ws = Luminance(Fresnel(n_dot_v));
    float wd = Luminance(base) * (1.0f - metallic);
    p_spec = ws + wd > 0.0f ? std::clamp(ws / (ws + wd), 0.1f, 1.0f) : 0.5f;
    if (wd <= 0.0f) p_spec = 1.0f;
  }

  Vec3 Fresnel(float cos_theta) const {
    float m = std::clamp(1.0f - cos_theta, 0.0f, 1.0f);
    float m5 = (m * m) * (m * m) * m;
    return f0 + (Vec3::Ones() - f0) * m5;
  }

  float D(float n_dot_h) const {
    float a2 = alpha * alpha;
    float d = n_dot_h * n_dot_h * (a2 - 1.0f) + 1.0f;
    return a2 / (kPi * d * d);
  }

  /// Smith-Schlick G(l, v) / (4 NoL NoV).
  float Visibility(float n_dot_l, float n_dot_v) const {
    float k = 0.5f * alpha;
    float gl = n_dot_l * (1.0f - k) + k;
    float gv = n_dot_v * (1.0f - k) + k;
    return 0.25f / std::max(gl * gv, 1e-12f);
  }

  /// f(wo, wi) * cos(wi), all vectors unit, n the shading normal.
  Vec3 EvalCos(const Vec3& n, const Vec3& wo, const Vec3& wi) const {
    float n_dot_l = n.dot(wi);
    float n_dot_v = n.dot(wo);
    if (n_dot_l <= 0.0f || n_dot_v <= 0.0f) return Vec3::Zero();
    Vec3 h = (wo + wi).normalized();
    float n_dot_h = std::max(n.dot(h), 0.0f);
    float v_dot_h = std::max(wo.dot(h), 0.0f);
    Vec3 f = Fresnel(v_dot_h);
    Vec3 spec = f * (D(n_dot_h) * Visibility(n_dot_l, n_dot_v));
    float s = wi.dot(wo) - n_dot_l * n_dot_v;
    float on = on_a + (s > 0.0f ? on_b * s / std::max(n_dot_l, n_dot_v) : 0.0f);
    Vec3 diffuse = (Vec3::Ones() - f).cwiseProduct(base) * ((1.0f - metallic) * on / kPi);
    return (diffuse + spec) * n_dot_l;
  }

  /// Density of Sample() for wi (solid angle).
  float Pdf(const Vec3& n, const Vec3& wo, const Vec3& wi) const {
    float n_dot_l = n.dot(wi);
    if (n_dot_l <= 0.0f) return 0.0f;
    Vec3 h = (wo + wi).normalized();
    float n_dot_h = std::max(n.dot(h), 0.0f);
    float v_dot_h = std::max(wo.dot(h), 1e-6f);
    float pdf_spec = D(n_dot_h) * n_dot_h / (4.0f * v_dot_h);
    float pdf_diff = n_dot_l / kPi;
    return p_spec * pdf_spec + (1.0f - p_spec) * pdf_diff;
  }

  /// Picks a lobe, then a direction from it; returns false when the direction goes below the
  /// surface. The caller weights with EvalCos / Pdf (one-sample mixture of both lobes).
  bool Sample(const Vec3& n, const Vec3& wo, float u_lobe, float u1, float u2, Vec3* wi) const {
    if (u_lobe < p_spec) {
      // GGX distribution of normals
      float a2 = alpha * alpha;
      float cos2 = (1.0f - u1) / (1.0f + (a2 - 1.0f) * u1);
      float c = std::sqrt(std::max(cos2, 0.0f));
      float s = std::sqrt(std::max(0.0f, 1.0f - cos2));
      float phi = 2.0f * kPi * u2;
      Vec3 h = FromLocal(n, Vec3(s * std::cos(phi), s * std::sin(phi), c));
      *wi = 2.0f * wo.dot(h) * h - wo;
    } else {
      *wi = FromLocal(n, SampleCosineLocal(u1, u2));
    }
    return n.dot(*wi) > 0.0f;
  }
};

}  // namespace partsim::internal
