#version 450 core
// Toon lighting for partsim's rasterizer: a custom lighting pass (see ../README.md).
// Diffuse light is quantised into three bands plus a dark one, and silhouettes (surfaces seen
// at grazing angles) are outlined in black. Use it with
//   RasterOptions options;
//   options.lighting_fragment_shader = <the contents of this file>;
//   auto backend = MakeRasterBackend(options);

#define MAX_LIGHTS 32

// G-buffer of the geometry pass (OpenGL camera frame: x right, y up, z backward)
uniform sampler2D u_albedo;    // linear RGBA surface colour
uniform sampler2D u_normal;    // xyz unit normal
uniform sampler2D u_position;  // xyz position (m), w depth (m); 0 where nothing is seen

// lights, in the OpenGL camera frame
uniform vec3 u_ambient;
uniform int u_num_lights;
uniform int u_light_type[MAX_LIGHTS];  // 0 directional, 1 point, 2 spot
uniform vec3 u_light_color[MAX_LIGHTS];
uniform vec3 u_light_position[MAX_LIGHTS];
uniform vec3 u_light_direction[MAX_LIGHTS];
uniform vec2 u_light_cos_cone[MAX_LIGHTS];  // cos(inner), cos(outer)

layout(location = 0) out vec4 o_color;

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 position = texelFetch(u_position, px, 0);
  if (position.w <= 0.0) {
    o_color = vec4(0.0);
    return;
  }
  vec3 albedo = texelFetch(u_albedo, px, 0).rgb;
  vec3 n = normalize(texelFetch(u_normal, px, 0).xyz);
  vec3 v = normalize(-position.xyz);

  // the brightest light decides the band
  float intensity = 0.0;
  for (int i = 0; i < u_num_lights; ++i) {
    vec3 l;
    float attenuation = 1.0;
    if (u_light_type[i] == 0) {
      l = -u_light_direction[i];
    } else {
      vec3 d = u_light_position[i] - position.xyz;
      float dist = length(d);
      l = d / max(dist, 1e-6);
      attenuation = 1.0 / max(dist * dist, 1e-6);
      if (u_light_type[i] == 2) {
        attenuation *= step(u_light_cos_cone[i].y, dot(-l, u_light_direction[i]));
      }
    }
    float luminance = dot(u_light_color[i], vec3(0.2126, 0.7152, 0.0722));
    intensity = max(intensity, max(dot(n, l), 0.0) * attenuation * luminance);
  }
  float band = intensity > 0.6 ? 1.0 : intensity > 0.3 ? 0.7 : intensity > 0.05 ? 0.4 : 0.15;
  vec3 color = albedo * band + albedo * u_ambient * 0.5;
  // outline: surfaces seen edge-on
  if (dot(n, v) < 0.2) color = vec3(0.0);
  o_color = vec4(clamp(color, 0.0, 1.0), 1.0);
}
