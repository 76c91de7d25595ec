// The built-in G-buffer fragment shader: "#version 450 core", surface.glsl, then this.
uniform uvec2 u_ids;          // visual id, entity id
layout(location = 0) out vec4 o_albedo;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_position;
layout(location = 3) out uvec4 o_segmentation;
layout(location = 4) out vec4 o_material;
void main() {
  o_albedo = SurfaceAlbedo();
  o_normal = vec4(SurfaceNormal(), 0.0);
  o_position = vec4(v_position, -v_position.z);
  o_segmentation = uvec4(u_ids, 0u, 0u);
  o_material = vec4(u_roughness, u_metallic, 0.0, 1.0);
}
