#include "render/pathtracer/pt_texture.h"

#include <cmath>

#include "render/gl_util.h"

namespace partsim::internal {

namespace {

float SrgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

int Wrap(int i, int n) {
  int r = i % n;
  return r < 0 ? r + n : r;
}

}  // namespace

Eigen::Vector4f PtTexture::Sample(float u, float v) const {
  if (width <= 0 || height <= 0) return Eigen::Vector4f::Ones();
  // texel centres at half-integers; v up means rows counted from the bottom
  float x = u * width - 0.5f;
  float y = (1.0f - v) * height - 0.5f;
  if (!std::isfinite(x) || !std::isfinite(y)) return texels[0];
  float fx = std::floor(x), fy = std::floor(y);
  float tx = x - fx, ty = y - fy;
  int x0 = Wrap(static_cast<int>(fx), width), x1 = Wrap(static_cast<int>(fx) + 1, width);
  int y0 = Wrap(static_cast<int>(fy), height), y1 = Wrap(static_cast<int>(fy) + 1, height);
  const Eigen::Vector4f& a = texels[y0 * width + x0];
  const Eigen::Vector4f& b = texels[y0 * width + x1];
  const Eigen::Vector4f& c = texels[y1 * width + x0];
  const Eigen::Vector4f& d = texels[y1 * width + x1];
  return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

std::shared_ptr<const PtTexture> LoadTexture(const std::string& path) {
  // the rasterizer's decoder, so that both backends read the same files the same way
  Image8 image = LoadImageRgba8(path);
  auto tex = std::make_shared<PtTexture>();
  tex->width = image.width;
  tex->height = image.height;
  tex->texels.resize(static_cast<size_t>(tex->width) * tex->height);
  float lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = SrgbToLinear(i / 255.0f);
  for (size_t i = 0; i < tex->texels.size(); ++i) {
    const uint8_t* p = &image.rgba[4 * i];
    tex->texels[i] = Eigen::Vector4f(lut[p[0]], lut[p[1]], lut[p[2]], p[3] / 255.0f);
  }
  return tex;
}

}  // namespace partsim::internal
