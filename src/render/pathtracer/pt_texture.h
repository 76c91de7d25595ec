// Internal to the path tracer: diffuse textures (PNG or JPEG, decoded as the rasterizer does).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace partsim::internal {

/// An RGBA image in linear colour, row 0 at the top of the file's image.
struct PtTexture {
  int width = 0;
  int height = 0;
  std::vector<Eigen::Vector4f> texels;  ///< width x height, linear RGB (sRGB decoded), alpha

  /// Bilinear lookup with wrap-around; uv (0, 0) is the bottom-left corner of the image (OpenGL
  /// and OBJ convention), so v = 1 is row 0 of the file.
  Eigen::Vector4f Sample(float u, float v) const;
};

/// Reads a PNG or JPEG file (sRGB) into linear colour; throws partsim::Error naming `path` when
/// it is missing or cannot be decoded.
std::shared_ptr<const PtTexture> LoadTexture(const std::string& path);

}  // namespace partsim::internal
