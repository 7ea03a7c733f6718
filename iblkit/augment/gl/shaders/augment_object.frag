#version 450 core
// The object: render::Material as on the CPU (augment/composite.cpp's object_radiance). Diffuse: the
// albedo (times the texture at the UVs) over π times the soft environment's irradiance (which holds the
// proxy's light as the probe saw it), times the factor that turns it into what reaches the triangle (occlusion, the object's shadow on the proxy
// it sees, the parallax from the map's centre), and the hard lights through both shadow maps (its own shadow, lamps
// the proxy hides). Glossy (u_specular > 0): the lobe of render::glossy_lobe per hard light, per unit
// irradiance at normal incidence, and the soft map's Phong-prefiltered value along the reflected ray.
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
in vec3 v_soft;  // that factor (augment::soft_visibility, ≤ 16)
uniform sampler2D u_soft_irradiance;
uniform sampler2D u_object_texture;  // linear RGB, uv (0,0) at the image's bottom-left, bilinear, repeating
uniform sampler2D u_object_glossy;   // G_s of the soft map (render/prefilter.h), lat-long
uniform vec3 u_eye, u_material_albedo, u_specular;
uniform int u_textured, u_blinn;
uniform float u_exponent;
layout(location = 0) out vec4 o_color;

// render::glossy_lobe: Phong (s+1)/2π max(0, r·l)^s, Blinn-Phong (s+8)/8π max(0, n·h)^s (n·l); 0 where n·l ≤ 0.
float lobe(vec3 n, vec3 v, vec3 r, vec3 l) {
  float ndl = dot(n, l);
  if (ndl <= 0.0) return 0.0;
  if (u_blinn != 0) {
    float ndh = dot(n, normalize(l + v));
    return ndh > 0.0 ? (u_exponent + 8.0) / (8.0 * PI) * pow(ndh, u_exponent) * ndl : 0.0;
  }
  float rdl = dot(r, l);
  return rdl > 0.0 ? (u_exponent + 1.0) / (2.0 * PI) * pow(rdl, u_exponent) : 0.0;
}

void main() {
  vec3 n = normalize(v_normal);
  vec3 v = normalize(u_eye - v_position);
  if (dot(n, v) < 0.0) n = -n;
  const bool glossy = max(u_specular.r, max(u_specular.g, u_specular.b)) > 0.0;
  vec3 r = reflect(-v, n);
  // Clamped: a multisampled edge pixel evaluates the attribute at its centre, which may lie outside the
  // triangle, where the corners' values extrapolate (below 0 next to a dark corner).
  vec3 e = texture(u_soft_irradiance, latlong(n)).rgb * clamp(v_soft, 0.0, 16.0);
  vec3 g = glossy ? texture(u_object_glossy, latlong(r)).rgb : vec3(0.0);
  for (int l = 0; l < u_light_count; ++l) {
    vec2 s = shadow(l, v_position, n, 1.5);
    if (s.x != 0.0) continue;
    e += (1.0 - s.y) * light_at(l, v_position, n);
    if (glossy) {
      vec3 w = u_light_dir[l].w > 0.5 ? normalize(u_light_pos[l].xyz - v_position) : u_light_dir[l].xyz;
      g += (1.0 - s.y) * light_at(l, v_position, w) * lobe(n, v, r, w);
    }
  }
  vec3 rho = u_material_albedo * (u_textured != 0 ? texture(u_object_texture, vec2(v_uv.x, 1.0 - v_uv.y)).rgb : vec3(1.0));
  o_color = vec4(rho / PI * e + u_specular * g, 1.0);
}
