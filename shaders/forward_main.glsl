// The forward pass's fragment shader (after gbuffer_vertex.glsl): "#version 450 core", the
// LIGHTS define, shading.glsl, surface.glsl, then this. The material inputs are those the
// G-buffer pass writes, roughness and metallic rounded to 8 bits as its RGBA8 target stores them,
// so that both paths shade the same numbers.
layout(location = 0) out vec4 o_color;
float Unorm8(float x) { return round(clamp(x, 0.0, 1.0) * 255.0) / 255.0; }
void main() {
  o_color = vec4(Shade(SurfaceAlbedo().rgb, SurfaceNormal(), v_position, Unorm8(u_roughness),
                       Unorm8(u_metallic)),
                 1.0);
}
