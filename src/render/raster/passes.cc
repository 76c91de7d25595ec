// The rasterizer's passes. Deferred: the G-buffer pass draws every instance into five targets
// (albedo, normal, position + depth, segmentation ids, material parameters), one draw call per
// instance with its uniforms; the lighting pass reads them in a full-screen triangle and shades
// every pixel. Forward (only Color and Position asked for, built-in shaders): one pass draws
// every instance with the G-buffer vertex shader and a fragment shader that computes the
// G-buffer's material inputs and shades them with the lighting pass's code, writing the lit colour
// and the depth buffer. This spares the five-target G-buffer and the full-screen pass. (A second
// float target for the view depth made the pass markedly slower on llvmpipe: bench/README.md.)
#include "render/raster/passes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "partsim/core/error.h"

namespace partsim::internal::raster {

namespace {

Eigen::Matrix4f ToFloat(const Eigen::Matrix4d& m) { return m.cast<float>(); }

void CheckFramebuffer(GLuint fbo, const char* what) {
  GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%x", status);
    throw Error(std::string("rasterizer: the ") + what + " framebuffer is incomplete (" + buf +
                ")");
  }
}

}  // namespace

Eigen::Matrix4d FlippedProjection(const CameraParams& camera) {
  Eigen::Matrix4d flip = Eigen::Matrix4d::Identity();
  flip(1, 1) = -1;
  return flip * camera.projection;
}

void Targets::Delete() {
  glDeleteFramebuffers(1, &gbuffer_fbo_);
  glDeleteFramebuffers(1, &color_fbo_);
  glDeleteFramebuffers(1, &forward_fbo_);
  glDeleteTextures(static_cast<GLsizei>(targets_.size()), targets_.data());
  glDeleteTextures(1, &depth_);
  gbuffer_fbo_ = color_fbo_ = forward_fbo_ = depth_ = 0;
  targets_.fill(0);
  width_ = height_ = 0;
}

void Targets::Ensure(int width, int height) {
  if (width == width_ && height == height_) return;
  Delete();
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

void Passes::Create() { glCreateVertexArrays(1, &empty_vao_); }

void Passes::Delete() {
  targets_.Delete();
  glDeleteVertexArrays(1, &empty_vao_);
  empty_vao_ = 0;
}

LightUniforms Passes::PrepareLights(const RenderWorld& world, const CameraParams& camera) const {
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
    out.shadow[i] = shadows_.layer(i);
    out.defines += "color += Light(" + std::to_string(i) + ", " + std::to_string(out.type[i]) +
                   ", " + std::to_string(out.shadow[i]) + "); ";
  }
  out.defines += "\n";
  return out;
}

void Passes::Gbuffer(const RenderWorld& world, const CameraParams& camera) {
  glBindFramebuffer(GL_FRAMEBUFFER, targets_.gbuffer_fbo());
  glViewport(0, 0, camera.width, camera.height);
  const float zeros[4] = {0, 0, 0, 0};
  const GLuint uzeros[4] = {0, 0, 0, 0};
  const float one = 1.0f;
  for (int i = 0; i < kNumGbuffer; ++i) {
    if (i == kTargetSegmentation) {
      glClearNamedFramebufferuiv(targets_.gbuffer_fbo(), GL_COLOR, i, uzeros);
    } else {
      glClearNamedFramebufferfv(targets_.gbuffer_fbo(), GL_COLOR, i, zeros);
    }
  }
  glClearNamedFramebufferfv(targets_.gbuffer_fbo(), GL_DEPTH, 0, &one);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  // the vertical flip of the projection reverses the winding of front faces
  glFrontFace(GL_CW);
  glUseProgram(programs_.gbuffer());
  DrawInstances(world, camera, programs_.gbuffer_locations());
  glFrontFace(GL_CCW);
}

// every instance with the current program (the G-buffer vertex shader's uniforms at `loc`)
void Passes::DrawInstances(const RenderWorld& world, const CameraParams& camera,
                           const GbufferLocations& loc) {
  Eigen::Matrix4f projection = ToFloat(FlippedProjection(camera));
  glUniformMatrix4fv(loc.projection, 1, GL_FALSE, projection.data());
  // front to back (by the nearest point of each bounding box), so that the early depth test
  // spares hidden G-buffer writes
  draw_order_.clear();
  Eigen::Vector3d eye = camera.X_WC.p;
  for (size_t i = 0; i < world.instances.size(); ++i) {
    if (resources_.mesh(i) == nullptr) continue;
    const Eigen::AlignedBox3d& box = resources_.bounds(i);
    double d = box.isEmpty() ? 0.0 : box.squaredExteriorDistance(eye);
    draw_order_.emplace_back(d, i);
  }
  std::sort(draw_order_.begin(), draw_order_.end());
  GLuint bound_texture = std::numeric_limits<GLuint>::max();
  for (const auto& [distance, i] : draw_order_) {
    const GpuMesh* mesh = resources_.mesh(i);
    const RenderInstance& inst = world.instances[i];
    Eigen::Matrix4d mv = camera.view * inst.X_WV;
    Eigen::Matrix4f mv_f = ToFloat(mv);
    Eigen::Matrix3f normal_matrix = mv.topLeftCorner<3, 3>().inverse().transpose().cast<float>();
    glUniformMatrix4fv(loc.model_view, 1, GL_FALSE, mv_f.data());
    glUniformMatrix3fv(loc.normal_matrix, 1, GL_FALSE, normal_matrix.data());
    glUniform4fv(loc.base_color, 1, inst.material.base_color.data());
    glUniform1f(loc.roughness, inst.material.roughness);
    glUniform1f(loc.metallic, inst.material.metallic);
    GLuint tex = resources_.texture(i);
    glUniform1i(loc.has_texture, tex != 0);
    if (tex != bound_texture) {
      glBindTextureUnit(0, tex != 0 ? tex : resources_.white_texture());
      bound_texture = tex;
    }
    glUniform2ui(loc.ids, inst.visual_id, inst.entity_id);
    glBindVertexArray(mesh->vao);
    glDrawElements(GL_TRIANGLES, mesh->index_count, GL_UNSIGNED_INT, nullptr);
  }
}

void Passes::Lighting(const RenderWorld& world, const LightUniforms& lights, int num_shadows) {
  glBindFramebuffer(GL_FRAMEBUFFER, targets_.color_fbo());
  glViewport(0, 0, targets_.width(), targets_.height());
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  for (int u = 0; u < kNumGbuffer; ++u) glBindTextureUnit(u, targets_.texture(u));
  glBindTextureUnit(kUnitShadow, shadows_.Texture());  // a texture even without shadows
  const Programs::Lighting& lighting = programs_.LightingProgram(lights.defines);
  glUseProgram(lighting.program);
  UploadLights(lighting.loc, world, lights, num_shadows);
  const float zeros[4] = {0, 0, 0, 0};
  glClearNamedFramebufferfv(targets_.color_fbo(), GL_COLOR, 0, zeros);
  glBindVertexArray(empty_vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDepthMask(GL_TRUE);
}

void Passes::Forward(const RenderWorld& world, const CameraParams& camera,
                     const LightUniforms& lights, int num_shadows) {
  glBindFramebuffer(GL_FRAMEBUFFER, targets_.forward_fbo());
  glViewport(0, 0, camera.width, camera.height);
  const float zeros[4] = {0, 0, 0, 0};
  const float one = 1.0f;
  glClearNamedFramebufferfv(targets_.forward_fbo(), GL_COLOR, 0, zeros);
  glClearNamedFramebufferfv(targets_.forward_fbo(), GL_DEPTH, 0, &one);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glFrontFace(GL_CW);  // the flipped projection, as in the G-buffer pass
  const Programs::Forward& forward = programs_.ForwardProgram(lights.defines);
  glUseProgram(forward.program);
  glBindTextureUnit(kUnitShadow, shadows_.Texture());  // a texture even without shadows
  UploadLights(forward.lighting, world, lights, num_shadows);
  DrawInstances(world, camera, forward.gbuffer);
  glFrontFace(GL_CCW);
}

// the lights, ambient and shadow matrices into the current program's uniforms at `loc`
void Passes::UploadLights(const LightingLocations& loc, const RenderWorld& world,
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
    glUniformMatrix4fv(loc.shadow_matrix, num_shadows, GL_FALSE, shadows_.matrices()[0].data());
    glUniform2fv(loc.shadow_texel, num_shadows, shadows_.texels()[0].data());
  }
}

}  // namespace partsim::internal::raster
