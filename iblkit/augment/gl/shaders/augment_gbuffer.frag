#version 450 core
// The proxy seen from the photograph's camera: world position (w = 1: proxy) and the normal facing the camera.
in vec3 v_position;
in vec3 v_normal;
uniform vec3 u_eye;
layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_normal;
void main() {
  vec3 n = normalize(v_normal);
  if (dot(n, u_eye - v_position) < 0.0) n = -n;
  o_position = vec4(v_position, 1.0);
  o_normal = vec4(n, 0.0);
}
