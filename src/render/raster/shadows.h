// The rasterizer's shadow maps: depth of every instance seen from each directional or spot light
// with shadow = true (up to kMaxShadows of them), layers of one depth array texture. A layer is
// drawn again only when what it would draw differs from what it holds (the casters' meshes and
// matrices from the light, which the light, the bodies' poses and, for a directional light, the
// camera's view decide), so a still scene's maps cost nothing after the first picture.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "partsim/render/backend.h"
#include "render/gl_util.h"
#include "render/raster/program.h"
#include "render/raster/resources.h"

namespace partsim::internal::raster {

/// The shadow maps of a picture and the matrices the lighting reads them with.
class ShadowMaps {
 public:
  /// `size`: width and height of a map (texels); 0 sizes each picture's maps by AutoSize.
  /// `reuse`: keep a layer whose draws are unchanged (else every layer is drawn every time).
  ShadowMaps(int size, bool reuse) : size_(size), reuse_(reuse) {}
  ShadowMaps(const ShadowMaps&) = delete;
  ShadowMaps& operator=(const ShadowMaps&) = delete;

  /// Makes the framebuffer the maps are drawn with.
  void Create();
  /// Deletes every GL object.
  void Delete();

  /// Depth maps of `world`'s shadow-casting lights, drawn with the shadow program (`program`, its
  /// matrix uniform at `mvp_location`); `scene_box` bounds every instance (m). Fills the layer of
  /// each light and the matrices; returns the number of maps. A layer whose draws (meshes and
  /// matrices) are those it was last drawn with is kept as it is.
  int Render(const RenderWorld& world, const CameraParams& camera,
             const Eigen::AlignedBox3d& scene_box, const Resources& resources, GLuint program,
             GLint mvp_location);
  /// The map side for a picture of `width` x `height` when the size is automatic: the power of
  /// two at or above twice the picture's larger side, in [512, 2048] (a map texel about half a
  /// pixel where the shadowed region fills the picture).
  static int AutoSize(int width, int height);
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
  /// Layers drawn and layers kept as they were, since the maps were made.
  uint64_t layers_drawn() const { return layers_drawn_; }
  uint64_t layers_reused() const { return layers_reused_; }

 private:
  /// One draw of a shadow pass: a mesh with its light-space matrix.
  struct Draw {
    GLuint vao;
    GLsizei count;
    Eigen::Matrix4f mvp;
    bool operator==(const Draw& o) const {
      return vao == o.vao && count == o.count && mvp == o.mvp;
    }
  };
  /// The maps of one side: the depth array texture, and what each layer was drawn with.
  struct MapSet {
    GLuint texture = 0;
    uint64_t geometry_version = 0;
    std::array<std::vector<Draw>, kMaxShadows> drawn;
    std::array<bool, kMaxShadows> valid{};
  };

  /// The maps of side `side`, made when a picture first draws one of that side.
  MapSet& Maps(int side, uint64_t geometry_version);

  int size_;
  bool reuse_;
  GLuint fbo_ = 0, stand_in_ = 0;
  std::map<int, MapSet> sets_;
  MapSet* current_ = nullptr;  ///< the set the last picture's maps are in
  std::vector<Draw> draws_;    ///< scratch: the draws of the layer being made
  std::array<Eigen::Matrix4f, kMaxShadows> matrix_;
  std::array<Eigen::Vector2f, kMaxShadows> texel_;
  std::vector<int> layer_;
  uint64_t layers_drawn_ = 0, layers_reused_ = 0;
};

}  // namespace partsim::internal::raster
