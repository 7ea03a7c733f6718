#version 450 core
// Differential rendering over the proxy's pixels: ΔE = E_with − E_without, written as the sum of what
// the object changes — the hard lights it blocks (shadow maps) and, from its equivalent sphere, the soft
// light it hides less the light it reflects (one bounce) — so that ΔE is exactly 0 wherever none of them
// touches the pixel; composite = photo + min(ρ, 1)/π · ΔE.
uniform sampler2D u_photo, u_albedo, u_gpos, u_gnormal, u_soft;
uniform sampler2D u_facing_irradiance;  // augment::facing_irradiance: the soft light on the object's side facing each way
uniform vec4 u_sphere;        // the object's equivalent sphere: centre (moved), radius
uniform vec3 u_object_albedo;
uniform float u_cut;          // cosine-weighted share of the hemisphere below which the soft term is 0 (faded in up to 2×)
uniform float u_soft_texel;   // solid angle of a soft-map texel at the equator, sr
uniform int u_bounce, u_shadows;
layout(location = 0) out vec4 o_composite;
void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec3 photo = texelFetch(u_photo, px, 0).rgb;
  vec4 g = texelFetch(u_gpos, px, 0);
  if (g.w < 0.5 || u_shadows == 0) {
    o_composite = vec4(photo, 1.0);
    return;
  }
  vec3 y = g.xyz, n = texelFetch(u_gnormal, px, 0).xyz, dE = vec3(0.0);
  for (int l = 0; l < u_light_count; ++l) {
    vec2 s = shadow(l, y, n, 1.0);
    if (s.x == 0.0 && s.y > 0.0) dE -= s.y * light_at(l, y, n);
  }
  vec3 a = u_sphere.xyz - y;
  float d2 = dot(a, a), s2 = u_sphere.w * u_sphere.w / d2;
  if (s2 < 1.0) {
    // Faded out between twice the cut-off share and the cut-off (exactly 0 below it).
    float om = cap_cosine_integral(dot(n, a) * inversesqrt(d2), s2);
    om *= smoothstep(u_cut, 2.0 * u_cut, om / PI);
    if (om > 0.0) {
      vec3 w = a * inversesqrt(d2);
      float cap = 2.0 * PI * (1.0 - sqrt(1.0 - s2));
      vec3 hidden = textureLod(u_soft, latlong(w), 0.5 * log2(max(cap / u_soft_texel, 1.0))).rgb, reflected = vec3(0.0);
      if (u_bounce != 0) {
        // The sphere's side that faces y, as y sees it (its points weighted by their projected area): the soft
        // light it receives by the way it faces, and of each hard light the mean of max(0, n·l) over that side,
        // (2/3π)((π − γ) cos γ + sin γ) for γ between the side and the light (2/3 when it faces the light),
        // where the proxy does not hide it from the object's centre.
        vec3 face = -w, c = u_sphere.xyz, e = textureLod(u_facing_irradiance, latlong(face), 0.0).rgb;
        for (int l = 0; l < u_light_count; ++l) {
          vec3 to_light = u_light_dir[l].w < 0.5 ? u_light_dir[l].xyz : normalize(u_light_pos[l].xyz - c);
          float cg = clamp(dot(face, to_light), -1.0, 1.0), gamma = acos(cg);
          float hidden_c = shadow(l, c, to_light, 0.0).x;  // a lamp the proxy hides from the object
          e += light_at(l, c, to_light) * (1.0 - hidden_c) * (2.0 / (3.0 * PI)) * ((PI - gamma) * cg + sin(gamma));
        }
        reflected = u_object_albedo / PI * e;
      }
      dE += om * (reflected - hidden);
    }
  }
  vec3 rho = min(texelFetch(u_albedo, px, 0).rgb, vec3(1.0));
  o_composite = vec4(max(photo + rho / PI * dE, vec3(0.0)), 1.0);
}
