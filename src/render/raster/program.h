// The rasterizer's GLSL programs: built from the embedded shaders/*.glsl or from the custom
// sources of RasterOptions, and the locations of their uniforms.
#pragma once

#include <string>
#include <unordered_map>

#include "partsim/render/backend.h"
#include "render/gl_util.h"

namespace partsim::internal::raster {

/// Lights a picture is shaded with, and of those, lights with a shadow map (MAX_LIGHTS and
/// MAX_SHADOWS of shaders/shading.glsl).
constexpr int kMaxLights = 32;
constexpr int kMaxShadows = 4;

/// Texture units of the lighting pass (the G-buffer targets, then the shadow maps).
enum Unit : GLint {
  kUnitAlbedo = 0,
  kUnitNormal,
  kUnitPosition,
  kUnitSegmentation,
  kUnitMaterial,
  kUnitShadow
};

/// Locations of the G-buffer pass's uniforms (-1: not declared).
struct GbufferLocations {
  GLint model_view = -1, normal_matrix = -1, projection = -1, base_color = -1, roughness = -1,
        metallic = -1, has_texture = -1, diffuse = -1, ids = -1;
};

/// Locations of the lighting uniforms (-1: not declared).
struct LightingLocations {
  GLint ambient = -1, num_lights = -1, light_type = -1, light_color = -1, light_position = -1,
        light_direction = -1, light_cos_cone = -1, light_shadow = -1, shadow_matrix = -1,
        shadow_texel = -1;
};

/// The programs of the passes. The G-buffer and shadow programs are built once; the lighting and
/// forward programs once per set of lights (the "#define LIGHTS ..." line), on first use. GL
/// objects are made and deleted with the rasterizer's context current.
class Programs {
 public:
  /// A lighting program and its uniforms.
  struct Lighting {
    GLuint program = 0;
    LightingLocations loc;
  };
  /// A forward program (G-buffer vertex shader, shading fragment shader) and its uniforms.
  struct Forward {
    GLuint program = 0;
    GbufferLocations gbuffer;
    LightingLocations lighting;
  };

  explicit Programs(const RasterOptions& options) : options_(options) {}
  Programs(const Programs&) = delete;
  Programs& operator=(const Programs&) = delete;

  /// Compiles the G-buffer, shadow and (lightless) lighting programs; throws partsim::Error
  /// naming the pass and stage when one fails (Delete frees what was built).
  void Build();
  /// Deletes every program.
  void Delete();

  GLuint gbuffer() const { return gbuffer_program_; }
  const GbufferLocations& gbuffer_locations() const { return gbuffer_loc_; }
  GLuint shadow() const { return shadow_program_; }
  /// Location of the shadow program's model-view-projection matrix.
  GLint shadow_mvp() const { return shadow_mvp_; }

  /// The lighting program for a set of lights (`defines`, after the #version line), compiled on
  /// first use; a custom lighting shader is one program for every set.
  const Lighting& LightingProgram(const std::string& defines);
  /// The forward program for a set of lights (`defines`, as for the lighting pass), compiled on
  /// first use.
  const Forward& ForwardProgram(const std::string& defines);

 private:
  const RasterOptions options_;  // the custom sources, if any
  GLuint gbuffer_program_ = 0, shadow_program_ = 0;
  GbufferLocations gbuffer_loc_;
  GLint shadow_mvp_ = -1;
  std::unordered_map<std::string, Lighting> lighting_;
  std::unordered_map<std::string, Forward> forward_;
};

}  // namespace partsim::internal::raster
