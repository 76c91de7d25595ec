// The surface a fragment sees, as the G-buffer pass stores it and the forward pass shades it:
// the inputs of both built-in fragment shaders ("#version 450 core" goes before it).
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
uniform vec4 u_base_color;   // linear RGBA
uniform float u_roughness;
uniform float u_metallic;
uniform bool u_has_texture;
uniform sampler2D u_diffuse;  // sRGB texture, sampled as linear
vec4 SurfaceAlbedo() {
  vec4 albedo = u_base_color;
  if (u_has_texture) albedo *= texture(u_diffuse, v_uv);
  return albedo;
}
vec3 SurfaceNormal() {
  vec3 n = normalize(v_normal);
  return gl_FrontFacing ? n : -n;  // two-sided: thin surfaces seen from behind
}
