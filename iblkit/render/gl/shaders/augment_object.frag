#version 450 core
// The object: Lambertian, lit by the soft environment's irradiance (which holds the proxy's light as the
// probe saw it) and by the hard lights through both shadow maps (its own shadow, lamps the proxy hides).
in vec3 v_position;
in vec3 v_normal;
uniform sampler2D u_soft_irradiance;
uniform vec3 u_eye, u_object_albedo;
layout(location = 0) out vec4 o_color;
void main() {
  vec3 n = normalize(v_normal);
  if (dot(n, u_eye - v_position) < 0.0) n = -n;
  vec3 e = texture(u_soft_irradiance, latlong(n)).rgb;
  for (int l = 0; l < u_light_count; ++l) {
    vec2 s = shadow(l, v_position, n, 1.5);
    if (s.x == 0.0) e += (1.0 - s.y) * light_at(l, v_position, n);
  }
  o_color = vec4(u_object_albedo / PI * e, 1.0);
}
