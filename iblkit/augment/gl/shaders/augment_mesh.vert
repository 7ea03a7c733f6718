#version 450 core
// The compositor's meshes (proxy and object, flat normals): world position, normal and UV for the
// G-buffer, the shadow maps and the object's shading (with its soft light's share); u_offset moves the object.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec3 a_soft;  // the object's soft light share (1 for the proxy)
uniform mat4 u_view_projection;
uniform vec3 u_offset;
out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
out vec3 v_soft;
void main() {
  v_position = a_position + u_offset;
  v_normal = a_normal;
  v_uv = a_uv;
  v_soft = a_soft;
  gl_Position = u_view_projection * vec4(v_position, 1.0);
}
