// The rasterizer's programs: the built-in ones are assembled from shaders/*.glsl (embedded at build
// time), custom ones come whole from RasterOptions.
#include "render/raster/program.h"

#include <string>
#include <utility>

#include "render/shaders_embedded.h"

namespace partsim::internal::raster {

namespace {

// locations of the G-buffer pass's uniforms in `program`; the diffuse texture on unit 0
GbufferLocations GbufferUniforms(GLuint program) {
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
LightingLocations LightingUniforms(GLuint program) {
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

}  // namespace

void Programs::Build() {
  bool custom_vs = !options_.gbuffer_vertex_shader.empty();
  bool custom_fs = !options_.gbuffer_fragment_shader.empty();
  bool custom_ls = !options_.lighting_fragment_shader.empty();
  gbuffer_program_ =
      BuildProgram("gbuffer", custom_vs ? options_.gbuffer_vertex_shader : kGbufferVertexGlsl,
                   custom_vs ? "custom RasterOptions::gbuffer_vertex_shader" : "built-in",
                   custom_fs ? options_.gbuffer_fragment_shader
                             : std::string("#version 450 core\n") + kSurfaceGlsl + kGbufferMainGlsl,
                   custom_fs ? "custom RasterOptions::gbuffer_fragment_shader" : "built-in");
  // the built-in lighting pass is compiled for each set of lights; this one has none
  LightingProgram(custom_ls ? "" : "#define LIGHTS\n");
  shadow_program_ = BuildProgram("shadow", kShadowVertexGlsl, "built-in", "", "none");

  gbuffer_loc_ = GbufferUniforms(gbuffer_program_);
  shadow_mvp_ = glGetUniformLocation(shadow_program_, "u_mvp");
}

void Programs::Delete() {
  glDeleteProgram(gbuffer_program_);
  for (auto& [key, lighting] : lighting_) glDeleteProgram(lighting.program);
  lighting_.clear();
  for (auto& [key, forward] : forward_) glDeleteProgram(forward.program);
  forward_.clear();
  glDeleteProgram(shadow_program_);
  gbuffer_program_ = shadow_program_ = 0;
}

const Programs::Forward& Programs::ForwardProgram(const std::string& defines) {
  auto it = forward_.find(defines);
  if (it != forward_.end()) return it->second;
  Forward out;
  out.program = BuildProgram(
      "forward", kGbufferVertexGlsl, "built-in",
      std::string("#version 450 core\n") + defines + kShadingGlsl + kSurfaceGlsl + kForwardMainGlsl,
      "built-in");
  out.gbuffer = GbufferUniforms(out.program);
  out.lighting = LightingUniforms(out.program);
  return forward_.emplace(defines, out).first->second;
}

const Programs::Lighting& Programs::LightingProgram(const std::string& defines) {
  bool custom = !options_.lighting_fragment_shader.empty();
  std::string key = custom ? "" : defines;
  auto it = lighting_.find(key);
  if (it != lighting_.end()) return it->second;
  Lighting out;
  out.program = BuildProgram(
      "lighting", kFullscreenVertexGlsl, "built-in",
      custom ? options_.lighting_fragment_shader
             : std::string("#version 450 core\n") + defines + kShadingGlsl + kLightingMainGlsl,
      custom ? "custom RasterOptions::lighting_fragment_shader" : "built-in");
  out.loc = LightingUniforms(out.program);
  return lighting_.emplace(key, out).first->second;
}

}  // namespace partsim::internal::raster
