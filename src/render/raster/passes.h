// The rasterizer's passes over the picture's render targets: the G-buffer pass (every instance's
// surface), the lighting pass (a full-screen triangle shading the G-buffer) and the forward pass
// (every instance shaded straight into the colour target, for pictures of Color and Position).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "partsim/render/backend.h"
#include "render/gl_util.h"
#include "render/raster/program.h"
#include "render/raster/resources.h"
#include "render/raster/shadows.h"

namespace partsim::internal::raster {

/// Render targets: G-buffer attachments 0..4, then the lit colour.
enum Target {
  kTargetAlbedo = 0,
  kTargetNormal,
  kTargetPosition,
  kTargetSegmentation,
  kTargetMaterial,
  kTargetColor,
  kNumTargets
};
constexpr int kNumGbuffer = 5;

/// The targets of a picture's size and their framebuffers: the G-buffer (5 colour targets and
/// depth), the colour (lit colour) and the forward one (lit colour and the G-buffer's depth).
class Targets {
 public:
  Targets() = default;
  Targets(const Targets&) = delete;
  Targets& operator=(const Targets&) = delete;

  /// Targets of `width` x `height` pixels, re-created when the size changes.
  void Ensure(int width, int height);
  /// Deletes every GL object.
  void Delete();

  int width() const { return width_; }
  int height() const { return height_; }
  GLuint texture(int target) const { return targets_[target]; }
  GLuint gbuffer_fbo() const { return gbuffer_fbo_; }
  GLuint color_fbo() const { return color_fbo_; }
  GLuint forward_fbo() const { return forward_fbo_; }

 private:
  std::array<GLuint, kNumTargets> targets_{};
  GLuint depth_ = 0, gbuffer_fbo_ = 0, color_fbo_ = 0, forward_fbo_ = 0;
  int width_ = 0, height_ = 0;
};

/// The lights of a picture in the OpenGL camera frame, and the program defines for them.
struct LightUniforms {
  int n = 0;
  std::array<GLint, kMaxLights> type{}, shadow{};
  std::array<Eigen::Vector3f, kMaxLights> color, position, direction;
  std::array<Eigen::Vector2f, kMaxLights> cone;
  std::string defines;  ///< "#define LIGHTS ..." and a newline
};

/// The camera's projection with its rows flipped, so that framebuffer row 0 is the image's top
/// row (the read-back needs no flip; front faces become clockwise).
Eigen::Matrix4d FlippedProjection(const CameraParams& camera);

/// The passes of a picture, drawing the resources with the programs into the targets.
class Passes {
 public:
  Passes(Programs& programs, const Resources& resources, ShadowMaps& shadows)
      : programs_(programs), resources_(resources), shadows_(shadows) {}
  Passes(const Passes&) = delete;
  Passes& operator=(const Passes&) = delete;

  /// Makes the vertex array of the full-screen triangle.
  void Create();
  /// Deletes every GL object, targets included.
  void Delete();

  Targets& targets() { return targets_; }
  const Targets& targets() const { return targets_; }

  /// The first kMaxLights lights of `world` seen from `camera`, with the shadow map layers of the
  /// last ShadowMaps::Render or Clear.
  LightUniforms PrepareLights(const RenderWorld& world, const CameraParams& camera) const;
  /// Every instance into the G-buffer.
  void Gbuffer(const RenderWorld& world, const CameraParams& camera);
  /// The G-buffer shaded into the colour target.
  void Lighting(const RenderWorld& world, const LightUniforms& lights, int num_shadows);
  /// Every instance shaded straight into the colour target and the depth buffer.
  void Forward(const RenderWorld& world, const CameraParams& camera, const LightUniforms& lights,
               int num_shadows);

 private:
  void DrawInstances(const RenderWorld& world, const CameraParams& camera,
                     const GbufferLocations& loc);
  void UploadLights(const LightingLocations& loc, const RenderWorld& world,
                    const LightUniforms& lights, int num_shadows);

  Programs& programs_;
  const Resources& resources_;
  ShadowMaps& shadows_;
  Targets targets_;
  GLuint empty_vao_ = 0;
  std::vector<std::pair<double, size_t>> draw_order_;
};

}  // namespace partsim::internal::raster
