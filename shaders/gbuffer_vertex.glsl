#version 450 core
// The built-in G-buffer vertex shader, also the forward pass's. A custom one
// (RasterOptions::gbuffer_vertex_shader) declares what shaders/README.md lists.
layout(location = 0) in vec3 a_position;  // visual frame (m)
layout(location = 1) in vec3 a_normal;    // visual frame
layout(location = 2) in vec2 a_uv;
uniform mat4 u_model_view;     // visual -> OpenGL camera frame
uniform mat3 u_normal_matrix;  // inverse transpose of u_model_view's 3x3
uniform mat4 u_projection;     // OpenGL camera frame -> clip (rows flipped: row 0 at the top)
out vec3 v_position;           // OpenGL camera frame (m)
out vec3 v_normal;             // OpenGL camera frame
out vec2 v_uv;
void main() {
  vec4 p = u_model_view * vec4(a_position, 1.0);
  v_position = p.xyz;
  v_normal = u_normal_matrix * a_normal;
  v_uv = a_uv;
  gl_Position = u_projection * p;
}
