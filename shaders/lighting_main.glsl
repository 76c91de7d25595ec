// The built-in lighting pass's fragment shader: "#version 450 core", the LIGHTS define,
// shading.glsl, then this.
uniform sampler2D u_albedo;
uniform sampler2D u_normal;
uniform sampler2D u_position;
uniform usampler2D u_segmentation;
uniform sampler2D u_material;
layout(location = 0) out vec4 o_color;
void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 position = texelFetch(u_position, px, 0);
  if (position.w <= 0.0) {  // background
    o_color = vec4(0.0);
    return;
  }
  vec4 material = texelFetch(u_material, px, 0);
  o_color = vec4(Shade(texelFetch(u_albedo, px, 0).rgb, normalize(texelFetch(u_normal, px, 0).xyz),
                       position.xyz, material.x, material.y),
                 1.0);
}
