// The rasterizer's shadow maps: depth of every instance seen from each directional or spot light
// with shadow = true (up to kMaxShadows of them), layers of one depth array texture.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "partsim/render/backend.h"
#include "render/gl_util.h"
#include "render/raster/program.h"
#include "render/raster/resources.h"

namespace partsim::internal::raster {

/// The shadow maps of a picture and the matrices the lighting reads them with.
class ShadowMaps {
 public:
  /// `size`: width and height of a map (texels).
  explicit ShadowMaps(int size) : size_(size) {}
  ShadowMaps(const ShadowMaps&) = delete;
  ShadowMaps& operator=(const ShadowMaps&) = delete;

  /// Makes the framebuffer the maps are drawn with.
  void Create();
  /// Deletes every GL object.
  void Delete();

  /// Depth maps of `world`'s shadow-casting lights, drawn with the shadow program (`program`, its
  /// matrix uniform at `mvp_location`); `scene_box` bounds every instance (m). Fills the layer of
  /// each light and the matrices; returns the number of maps.
  int Render(const RenderWorld& world, const CameraParams& camera,
             const Eigen::AlignedBox3d& scene_box, const Resources& resources, GLuint program,
             GLint mvp_location);
  /// No maps for this picture: every one of `num_lights` lights is unshadowed.
  void Clear(size_t num_lights) { layer_.assign(num_lights, -1); }

  /// The texture for the lighting's shadow sampler: the depth maps once a picture has drawn
  /// any, else a 1 x 1 stand-in (the sampler needs a texture even without shadows, and the
  /// maps, `size` squared times kMaxShadows depths, cost time to make that unshadowed pictures
  /// need not spend).
  GLuint Texture();
  /// Map layer of light `i` of the last picture, -1 for none.
  int layer(size_t i) const { return layer_[i]; }
  /// G -> shadow map [0, 1]^3, per layer.
  const std::array<Eigen::Matrix4f, kMaxShadows>& matrices() const { return matrix_; }
  /// Texel size (m) = x + y * distance to the light, per layer.
  const std::array<Eigen::Vector2f, kMaxShadows>& texels() const { return texel_; }

 private:
  /// The depth maps, made when a picture first draws one.
  GLuint Maps();

  int size_;
  GLuint fbo_ = 0, maps_ = 0, stand_in_ = 0;
  std::array<Eigen::Matrix4f, kMaxShadows> matrix_;
  std::array<Eigen::Vector2f, kMaxShadows> texel_;
  std::vector<int> layer_;
};

}  // namespace partsim::internal::raster
