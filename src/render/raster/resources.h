// What the rasterizer keeps on the GPU across pictures: meshes and textures of the render world's
// instances, uploaded on first use, and the world bounds of the instances of the current picture.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "partsim/render/backend.h"
#include "render/gl_util.h"

namespace partsim::internal::raster {

/// A mesh in GPU buffers: position, normal and uv per vertex (attributes 0, 1, 2), triangles.
struct GpuMesh {
  std::weak_ptr<const MeshData> owner;  ///< guards against a new mesh at a freed mesh's address
  GLuint vao = 0;
  GLuint vbo = 0;
  GLuint ebo = 0;
  GLsizei index_count = 0;
  Eigen::AlignedBox3f box;  ///< in the visual frame (m)
  uint64_t last_used = 0;   ///< Sync call that last used it
};

/// A diffuse texture (sRGB, mipmapped).
struct GpuTexture {
  GLuint id = 0;
  uint64_t last_used = 0;
};

/// GPU meshes and textures, kept per MeshData pointer and texture path; the draw lists of the
/// current picture index them by instance.
class Resources {
 public:
  Resources() = default;
  Resources(const Resources&) = delete;
  Resources& operator=(const Resources&) = delete;

  /// Makes the 1 x 1 white texture that untextured instances sample.
  void Create();
  /// Deletes every GL object.
  void Delete();

  /// Uploads the meshes and textures of `world`'s instances not yet on the GPU and fills the
  /// draw lists; when the geometry version changes, those no instance uses are freed. Throws
  /// partsim::Error naming a texture file that cannot be read.
  void Sync(const RenderWorld& world);
  /// World bounds (m) of every instance of `world` (after Sync), for the shadow cameras and the
  /// draw order; returns the box around all of them.
  Eigen::AlignedBox3d UpdateBounds(const RenderWorld& world);

  /// Mesh of instance i, null when it has nothing to draw.
  const GpuMesh* mesh(size_t i) const { return draw_meshes_[i]; }
  /// Diffuse texture of instance i, 0 for none.
  GLuint texture(size_t i) const { return draw_textures_[i]; }
  /// World bounds of instance i (empty when it has no mesh).
  const Eigen::AlignedBox3d& bounds(size_t i) const { return instance_bounds_[i]; }
  GLuint white_texture() const { return white_texture_; }

 private:
  static void DeleteMesh(GpuMesh* m);
  static GpuMesh UploadMesh(const std::shared_ptr<const MeshData>& data);
  static GLuint UploadTexture(const std::string& path);

  GLuint white_texture_ = 0;
  std::unordered_map<const MeshData*, GpuMesh> meshes_;
  std::unordered_map<std::string, GpuTexture> textures_;
  uint64_t synced_version_ = 0;
  bool first_sync_ = true;
  uint64_t frame_ = 0;
  std::vector<GpuMesh*> draw_meshes_;
  std::vector<GLuint> draw_textures_;
  std::vector<Eigen::AlignedBox3d> instance_bounds_;
};

}  // namespace partsim::internal::raster
