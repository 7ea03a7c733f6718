#version 450 core
// The compositor's meshes (proxy and object, flat normals): world position, normal and UV for the
// G-buffer, the shadow maps and the object's shading; u_offset moves the object.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_view_projection;
uniform vec3 u_offset;
out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
void main() {
  v_position = a_position + u_offset;
  v_normal = a_normal;
  v_uv = a_uv;
  gl_Position = u_view_projection * vec4(v_position, 1.0);
}
