// The shading shared by the lighting pass and the forward pass; "#version 450 core" and
// "#define LIGHTS ..." go before it: one Light(index, type, shadow layer) call per light with
// literal arguments, so that the compiler drops the branches a light does not need (software
// rasterizers run both sides of a branch). MAX_LIGHTS and MAX_SHADOWS match the rasterizer's
// kMaxLights and kMaxShadows.
#define MAX_LIGHTS 32
#define MAX_SHADOWS 4
uniform sampler2DArrayShadow u_shadow_maps;
uniform vec3 u_ambient;
uniform int u_num_lights;
uniform int u_light_type[MAX_LIGHTS];        // 0 directional, 1 point, 2 spot
uniform vec3 u_light_color[MAX_LIGHTS];
uniform vec3 u_light_position[MAX_LIGHTS];   // OpenGL camera frame (m)
uniform vec3 u_light_direction[MAX_LIGHTS];  // OpenGL camera frame, where the light travels
uniform vec2 u_light_cos_cone[MAX_LIGHTS];   // spot: cos(inner), cos(outer)
uniform int u_light_shadow[MAX_LIGHTS];      // shadow map layer, -1 for none
uniform mat4 u_shadow_matrix[MAX_SHADOWS];   // OpenGL camera frame -> shadow map [0,1]^3
uniform vec2 u_shadow_texel[MAX_SHADOWS];    // texel size (m) = x + y * distance to the light

const float PI = 3.14159265358979;

// the surface being shaded
vec3 p, n, v, f0, albedo;
float n_v, metallic, on_a, on_b, alpha2, k;

float Shadow(int layer, float dist) {
  vec2 texel = u_shadow_texel[layer];
  float world_texel = texel.x + texel.y * dist;
  vec4 s = u_shadow_matrix[layer] * vec4(p + n * (1.5 * world_texel), 1.0);
  s.xyz /= s.w;
  if (s.x <= 0.0 || s.x >= 1.0 || s.y <= 0.0 || s.y >= 1.0 || s.z >= 1.0) return 1.0;
  vec2 step = 1.0 / vec2(textureSize(u_shadow_maps, 0).xy);
  float lit = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      lit += texture(u_shadow_maps, vec4(s.xy + vec2(dx, dy) * step, float(layer), s.z));
  return lit / 9.0;
}

// light i of `type` (0 directional, 1 point, 2 spot), shadowed by map `layer` (-1: none)
vec3 Light(int i, int type, int layer) {
  vec3 l;
  float attenuation = 1.0;
  float dist = 0.0;
  if (type == 0) {
    l = -u_light_direction[i];
  } else {
    vec3 d = u_light_position[i] - p;
    dist = length(d);
    l = d / max(dist, 1e-6);
    attenuation = 1.0 / max(dist * dist, 1e-6);
    if (type == 2) {
      float c = dot(-l, u_light_direction[i]);
      attenuation *= smoothstep(u_light_cos_cone[i].y, u_light_cos_cone[i].x, c);
    }
  }
  float n_l = dot(n, l);
  if (n_l <= 0.0) return vec3(0.0);
  if (layer >= 0) attenuation *= Shadow(layer, dist);
  // Oren-Nayar diffuse (sigma = roughness), GGX specular (alpha = roughness^2, Smith-Schlick G,
  // Schlick Fresnel)
  vec3 h = normalize(l + v);
  float n_h = max(dot(n, h), 0.0);
  float v_h = max(dot(v, h), 0.0);
  vec3 f = f0 + (1.0 - f0) * pow(1.0 - v_h, 5.0);
  float dd = n_h * n_h * (alpha2 - 1.0) + 1.0;
  float d_ggx = alpha2 / (PI * dd * dd);
  float g = (n_l / (n_l * (1.0 - k) + k)) * (n_v / (n_v * (1.0 - k) + k));
  vec3 specular = f * (d_ggx * g / (4.0 * n_l * n_v));
  float s = dot(l, v) - n_l * n_v;
  float on = on_a + (s > 0.0 ? on_b * s / max(n_l, n_v) : 0.0);
  vec3 diffuse = (1.0 - f) * (1.0 - metallic) * albedo / PI * on;
  // as in the path tracer: a light's colour is the irradiance at normal incidence
  // (directional) or the intensity (point and spot, divided by the squared distance)
  return (diffuse + specular) * (n_l * attenuation) * u_light_color[i];
}

// lit colour of a surface point: albedo (linear RGB), unit normal and position (OpenGL camera
// frame), roughness and metallic as the G-buffer stores them
vec3 Shade(vec3 surface_albedo, vec3 normal, vec3 position, float surface_roughness,
           float surface_metallic) {
  albedo = surface_albedo;
  n = normal;
  float roughness = clamp(surface_roughness, 0.05, 1.0);
  metallic = clamp(surface_metallic, 0.0, 1.0);
  p = position;
  v = normalize(-p);
  n_v = max(dot(n, v), 1e-4);
  float sigma2 = roughness * roughness;
  on_a = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
  on_b = 0.45 * sigma2 / (sigma2 + 0.09);
  float alpha = roughness * roughness;
  alpha2 = alpha * alpha;
  k = alpha * 0.5;
  f0 = mix(vec3(0.04), albedo, metallic);
  // ambient: a uniform environment of radiance u_ambient, unoccluded
  vec3 color = albedo * u_ambient * (1.0 - metallic) + f0 * u_ambient * metallic;
  LIGHTS
  return clamp(color, 0.0, 1.0);
}
