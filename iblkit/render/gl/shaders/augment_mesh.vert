#version 450 core
// The compositor's meshes (proxy and object, flat normals): world position and normal for the G-buffer,
// the shadow maps and the object's shading; u_offset moves the object.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_view_projection;
uniform vec3 u_offset;
out vec3 v_position;
out vec3 v_normal;
void main() {
  v_position = a_position + u_offset;
  v_normal = a_normal;
  gl_Position = u_view_projection * vec4(v_position, 1.0);
}
