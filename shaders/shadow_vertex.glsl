#version 450 core
// Shadow maps: depth of every instance seen from a light (no fragment shader).
layout(location = 0) in vec3 a_position;
uniform mat4 u_mvp;
void main() { gl_Position = u_mvp * vec4(a_position, 1.0); }
