// The rasterizer: OpenGL 4.5 core on a headless EGL context (a GPU when there is one, else Mesa's
// llvmpipe). Deferred shading in three steps per picture:
//   1. shadow maps: depth of every instance seen from each directional or spot light with
//      shadow = true (up to kMaxShadows of them), layers of one depth array texture;
//   2. geometry pass: every instance into the G-buffer (albedo, normal, position + depth,
//      segmentation ids, material parameters), one draw call per instance with its uniforms;
//   3. lighting pass: a full-screen triangle reads the G-buffer and shades every pixel
//      (Oren-Nayar diffuse + GGX specular, ambient, directional, point and spot lights, PCF
//      shadows) into the colour target.
// Then glReadPixels copies each target asked for into the Picture.
// Pictures that ask only for Color and Position (with the built-in shaders) take a forward path
// instead of steps 2 and 3: one pass draws every instance with the G-buffer vertex shader and a
// fragment shader that computes the G-buffer's material inputs and shades them with the lighting
// pass's code, writing the lit colour and the depth buffer; Position is rebuilt from the depth
// buffer and the projection on the CPU. This spares the five-target G-buffer and the full-screen
// pass. (A second float target for the view depth made the pass markedly slower on llvmpipe:
// bench/README.md.)
// The projection is flipped vertically so that framebuffer row 0 is the top row of the image:
// the read-back needs no flip.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <system_error>
#include <thread>
#include <unordered_map>

#include "core/worker_pool.h"
#include "partsim/core/error.h"
#include "partsim/render/backend.h"
#include "render/depth_to_position.h"
#include "render/gl_util.h"
#include "render/picture_internal.h"
#include "render/shaders_embedded.h"

namespace partsim {
namespace {

constexpr int kMaxLights = 32;
constexpr int kMaxShadows = 4;

// built-in shaders: shaders/*.glsl, embedded at build time (shaders/README.md documents what
// custom ones must declare)
using internal::kForwardMainGlsl;
using internal::kFullscreenVertexGlsl;
using internal::kGbufferMainGlsl;
using internal::kGbufferVertexGlsl;
using internal::kLightingMainGlsl;
using internal::kShadingGlsl;
using internal::kShadowVertexGlsl;
using internal::kSurfaceGlsl;

struct GpuMesh {
  std::weak_ptr<const MeshData> owner;  // guards against a new mesh at a freed mesh's address
  GLuint vao = 0;
  GLuint vbo = 0;
  GLuint ebo = 0;
  GLsizei index_count = 0;
  Eigen::AlignedBox3f box;  // in the visual frame
  uint64_t last_used = 0;   // geometry version that last used it
};

struct GpuTexture {
  GLuint id = 0;
  uint64_t last_used = 0;
};

struct GbufferLocations {
  GLint model_view = -1, normal_matrix = -1, projection = -1, base_color = -1, roughness = -1,
        metallic = -1, has_texture = -1, diffuse = -1, ids = -1;
};

struct LightingLocations {
  GLint ambient = -1, num_lights = -1, light_type = -1, light_color = -1, light_position = -1,
        light_direction = -1, light_cos_cone = -1, light_shadow = -1, shadow_matrix = -1,
        shadow_texel = -1;
};

// the lights of a picture in the OpenGL camera frame, and the program defines for them
struct LightUniforms {
  int n = 0;
  std::array<GLint, kMaxLights> type{}, shadow{};
  std::array<Eigen::Vector3f, kMaxLights> color, position, direction;
  std::array<Eigen::Vector2f, kMaxLights> cone;
  std::string defines;  // "#define LIGHTS ..." and a newline
};

// texture units of the lighting pass
enum Unit : GLint {
  kUnitAlbedo = 0,
  kUnitNormal,
  kUnitPosition,
  kUnitSegmentation,
  kUnitMaterial,
  kUnitShadow
};

Eigen::Matrix4f ToFloat(const Eigen::Matrix4d& m) { return m.cast<float>(); }

// a right-handed look-at view matrix (world -> eye, eye looks along -z)
Eigen::Matrix4d LookAlong(const Eigen::Vector3d& eye, const Eigen::Vector3d& forward) {
  Eigen::Vector3d f = forward.normalized();
  Eigen::Vector3d up = std::abs(f.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  Eigen::Vector3d x = f.cross(up).normalized();
  Eigen::Vector3d y = x.cross(f);
  Eigen::Matrix4d v = Eigen::Matrix4d::Identity();
  v.block<1, 3>(0, 0) = x.transpose();
  v.block<1, 3>(1, 0) = y.transpose();
  v.block<1, 3>(2, 0) = -f.transpose();
  v(0, 3) = -x.dot(eye);
  v(1, 3) = -y.dot(eye);
  v(2, 3) = f.dot(eye);
  return v;
}

Eigen::Matrix4d Ortho(double l, double r, double b, double t, double n, double f) {
  Eigen::Matrix4d p = Eigen::Matrix4d::Identity();
  p(0, 0) = 2 / (r - l);
  p(1, 1) = 2 / (t - b);
  p(2, 2) = -2 / (f - n);
  p(0, 3) = -(r + l) / (r - l);
  p(1, 3) = -(t + b) / (t - b);
  p(2, 3) = -(f + n) / (f - n);
  return p;
}

Eigen::Matrix4d Perspective(double fovy, double n, double f) {
  double c = 1 / std::tan(fovy / 2);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = c;
  p(1, 1) = c;
  p(2, 2) = -(f + n) / (f - n);
  p(2, 3) = -2 * f * n / (f - n);
  p(3, 2) = -1;
  return p;
}

class RasterBackend final : public RenderBackend {
 public:
  explicit RasterBackend(const RasterOptions& options) : options_(options) {
    if (options_.shadow_map_size < 16 || options_.shadow_map_size > 16384) {
      throw Error("RasterOptions::shadow_map_size must be in [16, 16384], got " +
                  std::to_string(options_.shadow_map_size));
    }
    context_ = std::make_unique<internal::EglContext>();
    internal::CurrentContextScope current(*context_);
    static std::once_flag logged;
    std::call_once(logged, [&] {
      std::fprintf(stderr, "partsim: rasterizer on %s\n", context_->Renderer().c_str());
    });
    try {
      BuildPrograms();
    } catch (...) {
      DeleteGlObjects();
      throw;
    }
    glCreateVertexArrays(1, &empty_vao_);
    glCreateFramebuffers(1, &shadow_fbo_);
    glCreateTextures(GL_TEXTURE_2D, 1, &white_texture_);
    const uint8_t white[4] = {255, 255, 255, 255};
    glTextureStorage2D(white_texture_, 1, GL_RGBA8, 1, 1);
    glTextureSubImage2D(white_texture_, 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white);
  }

  ~RasterBackend() override {
    try {
      internal::CurrentContextScope current(*context_);
      DeleteGlObjects();
    } catch (...) {
      // the context cannot be made current here: its objects die with it
    }
  }

  std::string Name() const override { return "rasterizer"; }
  std::string Device() const override { return context_->Renderer(); }

 protected:
  void DoRender(const RenderWorld& world, const CameraParams& camera, Picture* out,
                unsigned outputs) override {
    internal::CurrentContextScope current(*context_);
    EnsureTargets(camera.width, camera.height);
    SyncResources(world);

    // world bounds of every instance, for the shadow cameras
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

    // shadows and lights only matter for colour
    int num_shadows = 0;
    if (outputs & kColor) {
      num_shadows = RenderShadowMaps(world, camera, scene_box);
    } else {
      shadow_layer_.assign(world.lights.size(), -1);
    }
    LightUniforms lights = PrepareLights(world, camera);
    if (UsesForwardPath(outputs)) {
      RenderForward(world, camera, lights, num_shadows);
      ReadBackForward(camera, outputs, out);
    } else {
      RenderGbuffer(world, camera);
      if (outputs & kColor) RenderLighting(world, lights, num_shadows);
      ReadBack(outputs, out);
    }
  }

 private:
  // the forward path: only Color and Position asked for, and the built-in shaders
  bool UsesForwardPath(unsigned outputs) const {
    return (outputs & ~unsigned{kColor | kPosition}) == 0 &&
           options_.gbuffer_vertex_shader.empty() && options_.gbuffer_fragment_shader.empty() &&
           options_.lighting_fragment_shader.empty();
  }

  void BuildPrograms() {
    bool custom_vs = !options_.gbuffer_vertex_shader.empty();
    bool custom_fs = !options_.gbuffer_fragment_shader.empty();
    bool custom_ls = !options_.lighting_fragment_shader.empty();
    gbuffer_program_ = internal::BuildProgram(
        "gbuffer", custom_vs ? options_.gbuffer_vertex_shader : kGbufferVertexGlsl,
        custom_vs ? "custom RasterOptions::gbuffer_vertex_shader" : "built-in",
        custom_fs ? options_.gbuffer_fragment_shader
                  : std::string("#version 450 core\n") + kSurfaceGlsl + kGbufferMainGlsl,
        custom_fs ? "custom RasterOptions::gbuffer_fragment_shader" : "built-in");
    // the built-in lighting pass is compiled for each set of lights; this one has none
    LightingProgram(custom_ls ? "" : "#define LIGHTS\n");
    shadow_program_ = internal::BuildProgram("shadow", kShadowVertexGlsl, "built-in", "", "none");

    gl_ = GbufferUniforms(gbuffer_program_);
    shadow_mvp_ = glGetUniformLocation(shadow_program_, "u_mvp");
  }

  // locations of the G-buffer pass's uniforms in `program`; the diffuse texture on unit 0
  static GbufferLocations GbufferUniforms(GLuint program) {
    GbufferLocations out;
    auto g = [&](const char* name) { return glGetUniformLocation(program, name); };
    out.model_view = g("u_model_view");
    out.normal_matrix = g("u_normal_matrix");
    out.projection = g("u_projection");
    out.base_color = g("u_base_color");
    out.roughness = g("u_roughness");
    out.metallic = g("u_metallic");
    out.has_texture = g("u_has_texture");
    out.diffuse = g("u_diffuse");
    out.ids = g("u_ids");
    if (out.diffuse >= 0) glProgramUniform1i(program, out.diffuse, 0);
    return out;
  }

  // locations of the lighting uniforms in `program`; samplers bound to their units
  static LightingLocations LightingUniforms(GLuint program) {
    LightingLocations out;
    auto l = [&](const char* name) { return glGetUniformLocation(program, name); };
    out.ambient = l("u_ambient");
    out.num_lights = l("u_num_lights");
    out.light_type = l("u_light_type");
    out.light_color = l("u_light_color");
    out.light_position = l("u_light_position");
    out.light_direction = l("u_light_direction");
    out.light_cos_cone = l("u_light_cos_cone");
    out.light_shadow = l("u_light_shadow");
    out.shadow_matrix = l("u_shadow_matrix");
    out.shadow_texel = l("u_shadow_texel");
    const std::pair<const char*, GLint> samplers[] = {
        {"u_albedo", kUnitAlbedo},     {"u_normal", kUnitNormal},
        {"u_position", kUnitPosition}, {"u_segmentation", kUnitSegmentation},
        {"u_material", kUnitMaterial}, {"u_shadow_maps", kUnitShadow}};
    for (const auto& [name, unit] : samplers) {
      GLint loc = l(name);
      if (loc >= 0) glProgramUniform1i(program, loc, unit);
    }
    return out;
  }

  // the forward program for a set of lights (`defines`, as for the lighting pass), compiled on
  // first use
  struct Forward {
    GLuint program = 0;
    GbufferLocations gbuffer;
    LightingLocations lighting;
  };
  const Forward& ForwardProgram(const std::string& defines) {
    auto it = forward_.find(defines);
    if (it != forward_.end()) return it->second;
    Forward out;
    out.program = internal::BuildProgram("forward", kGbufferVertexGlsl, "built-in",
                                         std::string("#version 450 core\n") + defines +
                                             kShadingGlsl + kSurfaceGlsl + kForwardMainGlsl,
                                         "built-in");
    out.gbuffer = GbufferUniforms(out.program);
    out.lighting = LightingUniforms(out.program);
    return forward_.emplace(defines, out).first->second;
  }

  // the lighting program for a set of lights (`defines`, after the #version line), compiled on
  // first use; a custom lighting shader is one program for every set
  struct Lighting {
    GLuint program = 0;
    LightingLocations loc;
  };
  const Lighting& LightingProgram(const std::string& defines) {
    bool custom = !options_.lighting_fragment_shader.empty();
    std::string key = custom ? "" : defines;
    auto it = lighting_.find(key);
    if (it != lighting_.end()) return it->second;
    Lighting out;
    out.program = internal::BuildProgram(
        "lighting", kFullscreenVertexGlsl, "built-in",
        custom ? options_.lighting_fragment_shader
               : std::string("#version 450 core\n") + defines + kShadingGlsl + kLightingMainGlsl,
        custom ? "custom RasterOptions::lighting_fragment_shader" : "built-in");
    out.loc = LightingUniforms(out.program);
    return lighting_.emplace(key, out).first->second;
  }

  void DeleteGlObjects() {
    for (auto& [key, mesh] : meshes_) DeleteMesh(&mesh);
    meshes_.clear();
    for (auto& [key, tex] : textures_) glDeleteTextures(1, &tex.id);
    textures_.clear();
    DeleteTargets();
    glDeleteTextures(1, &shadow_maps_);
    glDeleteTextures(1, &white_texture_);
    glDeleteFramebuffers(1, &shadow_fbo_);
    glDeleteVertexArrays(1, &empty_vao_);
    glDeleteProgram(gbuffer_program_);
    for (auto& [key, lighting] : lighting_) glDeleteProgram(lighting.program);
    lighting_.clear();
    for (auto& [key, forward] : forward_) glDeleteProgram(forward.program);
    forward_.clear();
    glDeleteProgram(shadow_program_);
    shadow_maps_ = white_texture_ = shadow_fbo_ = empty_vao_ = 0;
    gbuffer_program_ = shadow_program_ = 0;
  }

  static void DeleteMesh(GpuMesh* m) {
    glDeleteVertexArrays(1, &m->vao);
    glDeleteBuffers(1, &m->vbo);
    glDeleteBuffers(1, &m->ebo);
  }

  void DeleteTargets() {
    glDeleteFramebuffers(1, &gbuffer_fbo_);
    glDeleteFramebuffers(1, &color_fbo_);
    glDeleteFramebuffers(1, &forward_fbo_);
    glDeleteTextures(static_cast<GLsizei>(targets_.size()), targets_.data());
    glDeleteTextures(1, &depth_);
    gbuffer_fbo_ = color_fbo_ = forward_fbo_ = depth_ = 0;
    targets_.fill(0);
    width_ = height_ = 0;
  }

  // G-buffer and colour targets of the picture's size, re-created when it changes
  void EnsureTargets(int width, int height) {
    if (width == width_ && height == height_) return;
    DeleteTargets();
    const GLenum formats[kNumTargets] = {GL_RGBA32F, GL_RGBA32F, GL_RGBA32F,
                                         GL_RG32UI,  GL_RGBA8,   GL_RGBA32F};
    glCreateTextures(GL_TEXTURE_2D, kNumTargets, targets_.data());
    for (int i = 0; i < kNumTargets; ++i) {
      glTextureStorage2D(targets_[i], 1, formats[i], width, height);
      glTextureParameteri(targets_[i], GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTextureParameteri(targets_[i], GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glCreateTextures(GL_TEXTURE_2D, 1, &depth_);
    glTextureStorage2D(depth_, 1, GL_DEPTH_COMPONENT32F, width, height);

    glCreateFramebuffers(1, &gbuffer_fbo_);
    GLenum draw_buffers[kNumGbuffer];
    for (int i = 0; i < kNumGbuffer; ++i) {
      glNamedFramebufferTexture(gbuffer_fbo_, GL_COLOR_ATTACHMENT0 + i, targets_[i], 0);
      draw_buffers[i] = GL_COLOR_ATTACHMENT0 + i;
    }
    glNamedFramebufferTexture(gbuffer_fbo_, GL_DEPTH_ATTACHMENT, depth_, 0);
    glNamedFramebufferDrawBuffers(gbuffer_fbo_, kNumGbuffer, draw_buffers);
    CheckFramebuffer(gbuffer_fbo_, "G-buffer");

    glCreateFramebuffers(1, &color_fbo_);
    glNamedFramebufferTexture(color_fbo_, GL_COLOR_ATTACHMENT0, targets_[kTargetColor], 0);
    glNamedFramebufferDrawBuffer(color_fbo_, GL_COLOR_ATTACHMENT0);
    CheckFramebuffer(color_fbo_, "colour");

    // forward path: lit colour, the G-buffer's depth buffer
    glCreateFramebuffers(1, &forward_fbo_);
    glNamedFramebufferTexture(forward_fbo_, GL_COLOR_ATTACHMENT0, targets_[kTargetColor], 0);
    glNamedFramebufferTexture(forward_fbo_, GL_DEPTH_ATTACHMENT, depth_, 0);
    glNamedFramebufferDrawBuffer(forward_fbo_, GL_COLOR_ATTACHMENT0);
    CheckFramebuffer(forward_fbo_, "forward");
    width_ = width;
    height_ = height;
  }

  static void CheckFramebuffer(GLuint fbo, const char* what) {
    GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "0x%x", status);
      throw Error(std::string("rasterizer: the ") + what + " framebuffer is incomplete (" + buf +
                  ")");
    }
  }

  // GPU meshes and textures of this world's instances (uploaded on first use, kept per MeshData
  // pointer and texture path); when the geometry version changes, unused ones are freed
  void SyncResources(const RenderWorld& world) {
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

  static GpuMesh UploadMesh(const std::shared_ptr<const MeshData>& data) {
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

  static GLuint UploadTexture(const std::string& path) {
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

  // depth maps of the shadow-casting lights; fills shadow_light_ (light index -> layer) and the
  // matrices; returns the number of maps
  int RenderShadowMaps(const RenderWorld& world, const CameraParams& camera,
                       const Eigen::AlignedBox3d& scene_box) {
    int count = 0;
    shadow_layer_.assign(world.lights.size(), -1);
    if (scene_box.isEmpty()) return 0;
    Eigen::Matrix4d X_WG = camera.view.inverse();

    // receivers: the scene's box cut by the box of the view frustum
    Eigen::AlignedBox3d frustum_box;
    double far = std::min(camera.far, 1e4);
    for (int c = 0; c < 8; ++c) {
      double z = (c & 4) ? far : camera.near;
      double u = (c & 1) ? camera.width - 0.5 : -0.5;
      double v = (c & 2) ? camera.height - 0.5 : -0.5;
      // OpenCV ray through the image corner, into G (y and z flip)
      Eigen::Vector3d ray = camera.K.inverse() * Eigen::Vector3d(u, v, 1.0);
      Eigen::Vector3d p_G(ray.x() * z, -ray.y() * z, -z);
      frustum_box.extend((X_WG * p_G.homogeneous()).head<3>());
    }
    Eigen::AlignedBox3d receivers = scene_box.intersection(frustum_box);
    if (receivers.isEmpty()) receivers = scene_box;

    for (size_t li = 0; li < world.lights.size() && count < kMaxShadows; ++li) {
      const LightDesc& light = world.lights[li];
      if (!light.shadow || light.type == LightType::kPoint) continue;
      Eigen::Vector3d dir = light.direction.normalized();
      if (!dir.allFinite()) continue;
      Eigen::Matrix4d view, proj;
      Eigen::Vector2d texel;
      if (light.type == LightType::kDirectional) {
        Eigen::Vector3d c = receivers.center();
        double r = std::max(0.5 * receivers.diagonal().norm(), 1e-3);
        view = LookAlong(c, dir);
        // depth range over every caster: all corners of the scene box
        double zmin = std::numeric_limits<double>::max(), zmax = -zmin;
        for (int k = 0; k < 8; ++k) {
          double z = (view * scene_box.corner(Eigen::AlignedBox3d::CornerType(k)).homogeneous())(2);
          zmin = std::min(zmin, z);
          zmax = std::max(zmax, z);
        }
        double margin = 0.01 * (zmax - zmin) + 1e-3;
        proj = Ortho(-r, r, -r, r, -zmax - margin, -zmin + margin);
        texel = Eigen::Vector2d(2 * r / options_.shadow_map_size, 0);
      } else {
        view = LookAlong(light.position, dir);
        double dmax = 0;
        for (int k = 0; k < 8; ++k) {
          dmax = std::max(
              dmax, (scene_box.corner(Eigen::AlignedBox3d::CornerType(k)) - light.position).norm());
        }
        double fovy = std::min(2 * std::max(light.outer_angle, light.inner_angle) + 0.05, 3.0);
        double f = dmax * 1.01 + 1e-3;
        double n = std::max(f * 1e-4, 1e-3);
        proj = Perspective(fovy, n, f);
        texel = Eigen::Vector2d(0, 2 * std::tan(fovy / 2) / options_.shadow_map_size);
      }
      Eigen::Matrix4d view_proj = proj * view;
      EnsureShadowMaps();
      glNamedFramebufferTextureLayer(shadow_fbo_, GL_DEPTH_ATTACHMENT, shadow_maps_, 0, count);
      glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo_);
      glViewport(0, 0, options_.shadow_map_size, options_.shadow_map_size);
      glEnable(GL_DEPTH_TEST);
      glDepthFunc(GL_LESS);
      glDepthMask(GL_TRUE);
      glDisable(GL_CULL_FACE);
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.5f, 2.0f);
      const float one = 1.0f;
      glClearNamedFramebufferfv(shadow_fbo_, GL_DEPTH, 0, &one);
      glUseProgram(shadow_program_);
      for (size_t i = 0; i < world.instances.size(); ++i) {
        const GpuMesh* mesh = draw_meshes_[i];
        if (mesh == nullptr) continue;
        Eigen::Matrix4f mvp = ToFloat(view_proj * world.instances[i].X_WV);
        glUniformMatrix4fv(shadow_mvp_, 1, GL_FALSE, mvp.data());
        glBindVertexArray(mesh->vao);
        glDrawElements(GL_TRIANGLES, mesh->index_count, GL_UNSIGNED_INT, nullptr);
      }
      glDisable(GL_POLYGON_OFFSET_FILL);
      // camera G -> light clip -> [0, 1]^3
      Eigen::Matrix4d bias = Eigen::Matrix4d::Identity() * 0.5;
      bias(3, 3) = 1;
      bias.block<3, 1>(0, 3).setConstant(0.5);
      shadow_matrix_[count] = ToFloat(bias * view_proj * X_WG);
      shadow_texel_[count] = texel.cast<float>();
      shadow_layer_[li] = count;
      ++count;
    }
    return count;
  }

  void EnsureShadowMaps() {
    if (shadow_maps_ != 0) return;
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &shadow_maps_);
    glTextureStorage3D(shadow_maps_, 1, GL_DEPTH_COMPONENT32F, options_.shadow_map_size,
                       options_.shadow_map_size, kMaxShadows);
    glTextureParameteri(shadow_maps_, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(shadow_maps_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(shadow_maps_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(shadow_maps_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(shadow_maps_, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTextureParameteri(shadow_maps_, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  }

  void RenderGbuffer(const RenderWorld& world, const CameraParams& camera) {
    glBindFramebuffer(GL_FRAMEBUFFER, gbuffer_fbo_);
    glViewport(0, 0, camera.width, camera.height);
    const float zeros[4] = {0, 0, 0, 0};
    const GLuint uzeros[4] = {0, 0, 0, 0};
    const float one = 1.0f;
    for (int i = 0; i < kNumGbuffer; ++i) {
      if (i == kTargetSegmentation) {
        glClearNamedFramebufferuiv(gbuffer_fbo_, GL_COLOR, i, uzeros);
      } else {
        glClearNamedFramebufferfv(gbuffer_fbo_, GL_COLOR, i, zeros);
      }
    }
    glClearNamedFramebufferfv(gbuffer_fbo_, GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    // the vertical flip of the projection reverses the winding of front faces
    glFrontFace(GL_CW);
    glUseProgram(gbuffer_program_);
    DrawInstances(world, camera, gl_);
    glFrontFace(GL_CCW);
  }

  // the projection of the passes, rows flipped so that framebuffer row 0 is the image's top row
  static Eigen::Matrix4d FlippedProjection(const CameraParams& camera) {
    Eigen::Matrix4d flip = Eigen::Matrix4d::Identity();
    flip(1, 1) = -1;
    return flip * camera.projection;
  }

  // every instance with the current program (the G-buffer vertex shader's uniforms at `loc`)
  void DrawInstances(const RenderWorld& world, const CameraParams& camera,
                     const GbufferLocations& loc) {
    Eigen::Matrix4f projection = ToFloat(FlippedProjection(camera));
    glUniformMatrix4fv(loc.projection, 1, GL_FALSE, projection.data());
    // front to back (by the nearest point of each bounding box), so that the early depth test
    // spares hidden G-buffer writes
    draw_order_.clear();
    Eigen::Vector3d eye = camera.X_WC.p;
    for (size_t i = 0; i < world.instances.size(); ++i) {
      if (draw_meshes_[i] == nullptr) continue;
      const Eigen::AlignedBox3d& box = instance_bounds_[i];
      double d = box.isEmpty() ? 0.0 : box.squaredExteriorDistance(eye);
      draw_order_.emplace_back(d, i);
    }
    std::sort(draw_order_.begin(), draw_order_.end());
    GLuint bound_texture = std::numeric_limits<GLuint>::max();
    for (const auto& [distance, i] : draw_order_) {
      const GpuMesh* mesh = draw_meshes_[i];
      const RenderInstance& inst = world.instances[i];
      Eigen::Matrix4d mv = camera.view * inst.X_WV;
      Eigen::Matrix4f mv_f = ToFloat(mv);
      Eigen::Matrix3f normal_matrix = mv.topLeftCorner<3, 3>().inverse().transpose().cast<float>();
      glUniformMatrix4fv(loc.model_view, 1, GL_FALSE, mv_f.data());
      glUniformMatrix3fv(loc.normal_matrix, 1, GL_FALSE, normal_matrix.data());
      glUniform4fv(loc.base_color, 1, inst.material.base_color.data());
      glUniform1f(loc.roughness, inst.material.roughness);
      glUniform1f(loc.metallic, inst.material.metallic);
      GLuint tex = draw_textures_[i];
      glUniform1i(loc.has_texture, tex != 0);
      if (tex != bound_texture) {
        glBindTextureUnit(0, tex != 0 ? tex : white_texture_);
        bound_texture = tex;
      }
      glUniform2ui(loc.ids, inst.visual_id, inst.entity_id);
      glBindVertexArray(mesh->vao);
      glDrawElements(GL_TRIANGLES, mesh->index_count, GL_UNSIGNED_INT, nullptr);
    }
  }

  // the forward path: every instance shaded straight into the colour target and depth buffer
  void RenderForward(const RenderWorld& world, const CameraParams& camera,
                     const LightUniforms& lights, int num_shadows) {
    glBindFramebuffer(GL_FRAMEBUFFER, forward_fbo_);
    glViewport(0, 0, camera.width, camera.height);
    const float zeros[4] = {0, 0, 0, 0};
    const float one = 1.0f;
    glClearNamedFramebufferfv(forward_fbo_, GL_COLOR, 0, zeros);
    glClearNamedFramebufferfv(forward_fbo_, GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glFrontFace(GL_CW);  // the flipped projection, as in the G-buffer pass
    const Forward& forward = ForwardProgram(lights.defines);
    glUseProgram(forward.program);
    EnsureShadowMaps();  // the sampler needs a texture even without shadows
    glBindTextureUnit(kUnitShadow, shadow_maps_);
    UploadLights(forward.lighting, world, lights, num_shadows);
    DrawInstances(world, camera, forward.gbuffer);
    glFrontFace(GL_CCW);
  }

  LightUniforms PrepareLights(const RenderWorld& world, const CameraParams& camera) const {
    LightUniforms out;
    int n = std::min<int>(static_cast<int>(world.lights.size()), kMaxLights);
    out.n = n;
    Eigen::Matrix3d R_GW = camera.view.topLeftCorner<3, 3>();
    out.defines = "#define LIGHTS ";
    for (int i = 0; i < n; ++i) {
      const LightDesc& light = world.lights[i];
      out.type[i] = light.type == LightType::kDirectional ? 0
                    : light.type == LightType::kPoint     ? 1
                                                          : 2;
      out.color[i] = light.color;
      out.position[i] = (camera.view * light.position.homogeneous()).head<3>().cast<float>();
      Eigen::Vector3d d = R_GW * light.direction;
      out.direction[i] = (d.norm() > 0 ? Eigen::Vector3d(d.normalized()) : d).cast<float>();
      double inner = std::min(light.inner_angle, light.outer_angle);
      double outer = std::max(light.outer_angle, inner + 1e-4);
      out.cone[i] = Eigen::Vector2f(std::cos(inner), std::cos(outer));
      out.shadow[i] = shadow_layer_[i];
      out.defines += "color += Light(" + std::to_string(i) + ", " + std::to_string(out.type[i]) +
                     ", " + std::to_string(out.shadow[i]) + "); ";
    }
    out.defines += "\n";
    return out;
  }

  // the lights, ambient and shadow matrices into the current program's uniforms at `loc`
  void UploadLights(const LightingLocations& loc, const RenderWorld& world,
                    const LightUniforms& lights, int num_shadows) {
    int n = lights.n;
    glUniform3fv(loc.ambient, 1, world.ambient.data());
    glUniform1i(loc.num_lights, n);
    if (n > 0) {
      glUniform1iv(loc.light_type, n, lights.type.data());
      glUniform3fv(loc.light_color, n, lights.color[0].data());
      glUniform3fv(loc.light_position, n, lights.position[0].data());
      glUniform3fv(loc.light_direction, n, lights.direction[0].data());
      glUniform2fv(loc.light_cos_cone, n, lights.cone[0].data());
      glUniform1iv(loc.light_shadow, n, lights.shadow.data());
    }
    if (num_shadows > 0) {
      glUniformMatrix4fv(loc.shadow_matrix, num_shadows, GL_FALSE, shadow_matrix_[0].data());
      glUniform2fv(loc.shadow_texel, num_shadows, shadow_texel_[0].data());
    }
  }

  void RenderLighting(const RenderWorld& world, const LightUniforms& lights, int num_shadows) {
    glBindFramebuffer(GL_FRAMEBUFFER, color_fbo_);
    glViewport(0, 0, width_, height_);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    for (int u = 0; u < kNumGbuffer; ++u) glBindTextureUnit(u, targets_[u]);
    EnsureShadowMaps();  // the sampler needs a texture even without shadows
    glBindTextureUnit(kUnitShadow, shadow_maps_);
    const Lighting& lighting = LightingProgram(lights.defines);
    glUseProgram(lighting.program);
    UploadLights(lighting.loc, world, lights, num_shadows);
    const float zeros[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(color_fbo_, GL_COLOR, 0, zeros);
    glBindVertexArray(empty_vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthMask(GL_TRUE);
  }

  // one target of `fbo` into `dst` (`bytes` long)
  void Read(GLuint fbo, GLenum attachment, GLenum format, GLenum type, void* dst, size_t bytes) {
    glNamedFramebufferReadBuffer(fbo, attachment);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glReadnPixels(0, 0, width_, height_, format, type, static_cast<GLsizei>(bytes), dst);
  }

  // the outputs of the forward path: colour, and Position rebuilt from the depth buffer. The
  // depth buffer is read back first and converted on worker threads while this thread reads the
  // colour back (on a GPU the conversion would otherwise be most of the frame's time at 512 x 512:
  // bench/README.md).
  void ReadBackForward(const CameraParams& camera, unsigned outputs, Picture* out) {
    size_t n = static_cast<size_t>(width_) * height_;
    out->width = width_;
    out->height = height_;
    internal::KeepOutputs(outputs, out);
    if (outputs & kColor) out->color.resize(n * 4);
    if (outputs & kPosition) {
      out->position.resize(n * 4);
      window_depth_.resize(n);
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    const Eigen::Matrix4d P = FlippedProjection(camera);
    const int parts = (outputs & kPosition) ? ConversionParts(n) : 0;
    auto convert = [&](int part) {
      internal::PositionFromDepth(
          P, width_, height_, window_depth_.data(), out->position.data(),
          static_cast<int>(static_cast<int64_t>(height_) * part / parts),
          static_cast<int>(static_cast<int64_t>(height_) * (part + 1) / parts));
    };
    bool started = false;
    if (outputs & kPosition) {
      Read(forward_fbo_, GL_COLOR_ATTACHMENT0, GL_DEPTH_COMPONENT, GL_FLOAT, window_depth_.data(),
           window_depth_.size() * sizeof(float));
      if (parts > 1) {
        try {
          conversion_workers_.Start(parts, convert);
          started = true;
        } catch (const std::system_error&) {
          // no thread to be had: this thread converts after the colour
        }
      }
    }
    if (outputs & kColor) {
      Read(forward_fbo_, GL_COLOR_ATTACHMENT0, GL_RGBA, GL_FLOAT, out->color.data(),
           out->color.size() * sizeof(float));
    }
    if (started) {
      conversion_workers_.Wait();
    } else if (outputs & kPosition) {
      for (int part = 0; part < parts; ++part) convert(part);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    GLenum err = glGetError();
    if (err == GL_OUT_OF_MEMORY) throw Error("rasterizer: out of GPU memory");
  }

  // the parts the depth of n pixels is converted in: one below 64 x 64 (converted on this
  // thread), else one per 16k pixels, from 2 to twice the workers. (Converting 128 x 128 on this
  // thread instead made the frame slower on a GPU machine: bench/README.md.)
  int ConversionParts(size_t n) const {
    if (n < 64 * 64) return 1;
    return std::clamp(static_cast<int>(n / 16384), 2, 2 * conversion_workers_.size());
  }

  // threads converting the depth buffer to Position while this one reads the colour back: at most
  // 4, one fewer than the cores
  static int ConversionWorkers() {
    int cores = static_cast<int>(std::thread::hardware_concurrency());
    return std::clamp(cores - 1, 1, 4);
  }

  // the outputs of the deferred path asked for, from the G-buffer and colour targets
  void ReadBack(unsigned outputs, Picture* out) {
    size_t n = static_cast<size_t>(width_) * height_;
    out->width = width_;
    out->height = height_;
    internal::KeepOutputs(outputs, out);
    if (outputs & kColor) out->color.resize(n * 4);
    if (outputs & kAlbedo) out->albedo.resize(n * 4);
    if (outputs & kNormal) out->normal.resize(n * 4);
    if (outputs & kPosition) out->position.resize(n * 4);
    if (outputs & kSegmentation) out->segmentation.resize(n * 2);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    if (outputs & kColor) {
      Read(color_fbo_, GL_COLOR_ATTACHMENT0, GL_RGBA, GL_FLOAT, out->color.data(),
           out->color.size() * sizeof(float));
    }
    if (outputs & kAlbedo) {
      Read(gbuffer_fbo_, GL_COLOR_ATTACHMENT0 + kTargetAlbedo, GL_RGBA, GL_FLOAT,
           out->albedo.data(), out->albedo.size() * sizeof(float));
    }
    if (outputs & kNormal) {
      Read(gbuffer_fbo_, GL_COLOR_ATTACHMENT0 + kTargetNormal, GL_RGBA, GL_FLOAT,
           out->normal.data(), out->normal.size() * sizeof(float));
    }
    if (outputs & kPosition) {
      Read(gbuffer_fbo_, GL_COLOR_ATTACHMENT0 + kTargetPosition, GL_RGBA, GL_FLOAT,
           out->position.data(), out->position.size() * sizeof(float));
    }
    if (outputs & kSegmentation) {
      Read(gbuffer_fbo_, GL_COLOR_ATTACHMENT0 + kTargetSegmentation, GL_RG_INTEGER, GL_UNSIGNED_INT,
           out->segmentation.data(), out->segmentation.size() * sizeof(uint32_t));
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    GLenum err = glGetError();
    if (err == GL_OUT_OF_MEMORY) throw Error("rasterizer: out of GPU memory");
  }

  // render targets: G-buffer attachments 0..4, then the lit colour
  enum Target {
    kTargetAlbedo = 0,
    kTargetNormal,
    kTargetPosition,
    kTargetSegmentation,
    kTargetMaterial,
    kTargetColor,
    kNumTargets
  };
  static constexpr int kNumGbuffer = 5;

  RasterOptions options_;
  std::unique_ptr<internal::EglContext> context_;

  GLuint gbuffer_program_ = 0, shadow_program_ = 0;
  GbufferLocations gl_;
  std::unordered_map<std::string, Lighting> lighting_;
  std::unordered_map<std::string, Forward> forward_;
  GLint shadow_mvp_ = -1;

  int width_ = 0, height_ = 0;
  std::array<GLuint, kNumTargets> targets_{};
  GLuint depth_ = 0, gbuffer_fbo_ = 0, color_fbo_ = 0, forward_fbo_ = 0;
  std::vector<float> window_depth_;  // forward path: the depth buffer read back
  internal::WorkerPool conversion_workers_{ConversionWorkers()};
  GLuint empty_vao_ = 0, white_texture_ = 0;
  GLuint shadow_fbo_ = 0, shadow_maps_ = 0;
  std::array<Eigen::Matrix4f, kMaxShadows> shadow_matrix_;
  std::array<Eigen::Vector2f, kMaxShadows> shadow_texel_;
  std::vector<int> shadow_layer_;

  std::unordered_map<const MeshData*, GpuMesh> meshes_;
  std::unordered_map<std::string, GpuTexture> textures_;
  uint64_t synced_version_ = 0;
  bool first_sync_ = true;
  uint64_t frame_ = 0;
  std::vector<GpuMesh*> draw_meshes_;
  std::vector<GLuint> draw_textures_;
  std::vector<Eigen::AlignedBox3d> instance_bounds_;
  std::vector<std::pair<double, size_t>> draw_order_;
};

}  // namespace

std::unique_ptr<RenderBackend> MakeRasterBackend(const RasterOptions& options) {
  return std::make_unique<RasterBackend>(options);
}

}  // namespace partsim
