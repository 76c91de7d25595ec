// The rasterizer's GPU meshes and textures: uploads, reuse across pictures, release.
#include "render/raster/resources.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace partsim::internal::raster {

void Resources::Create() {
  glCreateTextures(GL_TEXTURE_2D, 1, &white_texture_);
  const uint8_t white[4] = {255, 255, 255, 255};
  glTextureStorage2D(white_texture_, 1, GL_RGBA8, 1, 1);
  glTextureSubImage2D(white_texture_, 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white);
}

void Resources::Delete() {
  for (auto& [key, mesh] : meshes_) DeleteMesh(&mesh);
  meshes_.clear();
  for (auto& [key, tex] : textures_) glDeleteTextures(1, &tex.id);
  textures_.clear();
  glDeleteTextures(1, &white_texture_);
  white_texture_ = 0;
}

void Resources::DeleteMesh(GpuMesh* m) {
  glDeleteVertexArrays(1, &m->vao);
  glDeleteBuffers(1, &m->vbo);
  glDeleteBuffers(1, &m->ebo);
}

void Resources::Sync(const RenderWorld& world) {
  bool new_version = world.geometry_version != synced_version_ || first_sync_;
  first_sync_ = false;
  synced_version_ = world.geometry_version;
  ++frame_;
  draw_meshes_.assign(world.instances.size(), nullptr);
  draw_textures_.assign(world.instances.size(), 0);
  for (size_t i = 0; i < world.instances.size(); ++i) {
    const RenderInstance& inst = world.instances[i];
    if (inst.mesh) {
      GpuMesh& m = meshes_[inst.mesh.get()];
      bool same_owner = !m.owner.owner_before(inst.mesh) && !inst.mesh.owner_before(m.owner);
      if (m.vao == 0 || !same_owner || m.owner.expired()) {
        if (m.vao != 0) DeleteMesh(&m);
        m = UploadMesh(inst.mesh);
      }
      m.last_used = frame_;
      if (m.index_count > 0) draw_meshes_[i] = &m;
    }
    const std::string& path = inst.material.diffuse_texture;
    if (!path.empty()) {
      auto it = textures_.find(path);
      if (it == textures_.end()) {
        GLuint id = UploadTexture(path);  // throws naming the file
        it = textures_.emplace(path, GpuTexture{id, 0}).first;
      }
      it->second.last_used = frame_;
      draw_textures_[i] = it->second.id;
    }
  }
  if (!new_version) return;
  for (auto it = meshes_.begin(); it != meshes_.end();) {
    if (it->second.last_used != frame_) {
      DeleteMesh(&it->second);
      it = meshes_.erase(it);
    } else {
      ++it;
    }
  }
  for (auto it = textures_.begin(); it != textures_.end();) {
    if (it->second.last_used != frame_) {
      glDeleteTextures(1, &it->second.id);
      it = textures_.erase(it);
    } else {
      ++it;
    }
  }
}

Eigen::AlignedBox3d Resources::UpdateBounds(const RenderWorld& world) {
  instance_bounds_.resize(world.instances.size());
  Eigen::AlignedBox3d scene_box;
  for (size_t i = 0; i < world.instances.size(); ++i) {
    const RenderInstance& inst = world.instances[i];
    GpuMesh* mesh = draw_meshes_[i];
    Eigen::AlignedBox3d box;
    if (mesh != nullptr && !mesh->box.isEmpty()) {
      for (int c = 0; c < 8; ++c) {
        Eigen::Vector3d corner =
            mesh->box.corner(Eigen::AlignedBox3f::CornerType(c)).cast<double>();
        box.extend((inst.X_WV * corner.homogeneous()).head<3>());
      }
    }
    instance_bounds_[i] = box;
    if (!box.isEmpty()) scene_box.extend(box);
  }
  return scene_box;
}

GpuMesh Resources::UploadMesh(const std::shared_ptr<const MeshData>& data) {
  const MeshData& mesh = *data;
  GpuMesh m;
  m.owner = data;
  struct Vertex {
    float p[3];
    float n[3];
    float uv[2];
  };
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;
  const int nv = static_cast<int>(mesh.vertices.size());
  bool smooth = mesh.normals.size() == mesh.vertices.size() && nv > 0;
  bool has_uv = mesh.uvs.size() == mesh.vertices.size();
  auto make_vertex = [&](int v, const Eigen::Vector3f& n) {
    Vertex out;
    for (int k = 0; k < 3; ++k) out.p[k] = mesh.vertices[v][k];
    for (int k = 0; k < 3; ++k) out.n[k] = n[k];
    out.uv[0] = has_uv ? mesh.uvs[v].x() : 0.f;
    out.uv[1] = has_uv ? mesh.uvs[v].y() : 0.f;
    return out;
  };
  if (smooth) {
    vertices.reserve(nv);
    for (int v = 0; v < nv; ++v) vertices.push_back(make_vertex(v, mesh.normals[v]));
    indices.reserve(mesh.faces.size() * 3);
    for (const Eigen::Vector3i& f : mesh.faces) {
      if ((f.array() < 0).any() || (f.array() >= nv).any()) continue;
      for (int k = 0; k < 3; ++k) indices.push_back(static_cast<uint32_t>(f[k]));
    }
  } else {
    // flat normals: three vertices of its own per face
    vertices.reserve(mesh.faces.size() * 3);
    indices.reserve(mesh.faces.size() * 3);
    for (const Eigen::Vector3i& f : mesh.faces) {
      if ((f.array() < 0).any() || (f.array() >= nv).any()) continue;
      Eigen::Vector3f n = (mesh.vertices[f[1]] - mesh.vertices[f[0]])
                              .cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]);
      float len = n.norm();
      n = len > 0 ? Eigen::Vector3f(n / len) : Eigen::Vector3f::UnitZ();
      for (int k = 0; k < 3; ++k) {
        indices.push_back(static_cast<uint32_t>(vertices.size()));
        vertices.push_back(make_vertex(f[k], n));
      }
    }
  }
  for (const Eigen::Vector3f& v : mesh.vertices) m.box.extend(v);
  m.index_count = static_cast<GLsizei>(indices.size());
  if (m.index_count == 0) return m;

  glCreateBuffers(1, &m.vbo);
  glNamedBufferStorage(m.vbo, vertices.size() * sizeof(Vertex), vertices.data(), 0);
  glCreateBuffers(1, &m.ebo);
  glNamedBufferStorage(m.ebo, indices.size() * sizeof(uint32_t), indices.data(), 0);
  glCreateVertexArrays(1, &m.vao);
  glVertexArrayVertexBuffer(m.vao, 0, m.vbo, 0, sizeof(Vertex));
  glVertexArrayElementBuffer(m.vao, m.ebo);
  const GLuint offsets[3] = {offsetof(Vertex, p), offsetof(Vertex, n), offsetof(Vertex, uv)};
  const GLint sizes[3] = {3, 3, 2};
  for (GLuint a = 0; a < 3; ++a) {
    glEnableVertexArrayAttrib(m.vao, a);
    glVertexArrayAttribFormat(m.vao, a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a]);
    glVertexArrayAttribBinding(m.vao, a, 0);
  }
  return m;
}

GLuint Resources::UploadTexture(const std::string& path) {
  internal::Image8 image = internal::LoadImageRgba8(path);
  // rows go in bottom first, so that uv (0, 0) is the bottom-left corner of the image
  // (OpenGL's convention, which assimp follows)
  std::vector<uint8_t> flipped(image.rgba.size());
  size_t row = static_cast<size_t>(image.width) * 4;
  for (int y = 0; y < image.height; ++y) {
    std::copy_n(image.rgba.data() + y * row, row, flipped.data() + (image.height - 1 - y) * row);
  }
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  int levels = 1;
  for (int s = std::max(image.width, image.height); s > 1; s /= 2) ++levels;
  glTextureStorage2D(id, levels, GL_SRGB8_ALPHA8, image.width, image.height);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(id, 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE,
                      flipped.data());
  glGenerateTextureMipmap(id);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_REPEAT);
  return id;
}

}  // namespace partsim::internal::raster
