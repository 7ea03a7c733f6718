// Shared by the compositor's passes (augment/gl/compositor.h): the hard lights with their two shadow maps
// (the object's and the proxy's, linear distances from the light, in one frustum fitted to the object),
// lat-long lookups, and the sphere cap's cosine integral (augment/sphere_occlusion.h's twin).
const float PI = 3.14159265358979;
// MAX_LIGHTS comes from the program's prelude (compositor.cpp: Compositor::kMaxLights).
uniform int u_light_count;
uniform vec4 u_light_dir[MAX_LIGHTS];   // xyz: unit, from the centre towards the light; w: 1 local, 0 distant
uniform vec4 u_light_pos[MAX_LIGHTS];   // xyz: position (local); w: |position − centre|²
uniform vec4 u_light_e[MAX_LIGHTS];     // rgb: irradiance at the centre, normal incidence
uniform mat4 u_light_vp[MAX_LIGHTS];    // world → the shadow maps' clip space
uniform vec4 u_light_eye[MAX_LIGHTS];   // xyz: the maps' eye; w: texel size per metre of distance (local), metres
                                        // (distant), < 0: no shadow map (the light inside the object's sphere)
uniform sampler2DArray u_object_map, u_proxy_map;
uniform int u_map_size, u_pcf;

vec3 light_at(int l, vec3 x, vec3 n) {
  if (u_light_dir[l].w < 0.5) return u_light_e[l].rgb * max(0.0, dot(n, u_light_dir[l].xyz));
  vec3 v = u_light_pos[l].xyz - x;
  float r2 = max(dot(v, v), 1e-12);
  return u_light_e[l].rgb * (u_light_pos[l].w / r2 * max(0.0, dot(n, v) * inversesqrt(r2)));
}

float light_distance(int l, vec3 x) {
  return u_light_dir[l].w > 0.5 ? length(x - u_light_eye[l].xyz) : dot(u_light_eye[l].xyz - x, u_light_dir[l].xyz);
}

// x: 1 when the proxy hides the light from p; y: the share of the (2·pcf+1)² taps around p the object
// blocks (exactly 0 outside the object's frustum and where no tap sees it nearer). p moves `offset`
// texels along n first (normal offset).
vec2 shadow(int l, vec3 p, vec3 n, float offset) {
  if (u_light_eye[l].w < 0.0) return vec2(0.0);
  float d0 = light_distance(l, p);
  float texel = u_light_dir[l].w > 0.5 ? u_light_eye[l].w * d0 : u_light_eye[l].w;
  p += n * (offset * texel);
  vec4 c = u_light_vp[l] * vec4(p, 1.0);
  if (c.w <= 0.0) return vec2(0.0);
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return vec2(0.0);
  float d = light_distance(l, p);
  ivec2 t = clamp(ivec2(uv * float(u_map_size)), ivec2(0), ivec2(u_map_size - 1));
  if (texelFetch(u_proxy_map, ivec3(t, l), 0).r < d - (0.05 * d + 4.0 * texel)) return vec2(1.0, 0.0);
  float bias = 2.0 * texel + 1e-4, blocked = 0.0;
  int taps = 0;
  for (int j = -u_pcf; j <= u_pcf; ++j)
    for (int i = -u_pcf; i <= u_pcf; ++i) {
      ivec2 q = clamp(t + ivec2(i, j), ivec2(0), ivec2(u_map_size - 1));
      blocked += texelFetch(u_object_map, ivec3(q, l), 0).r < d - bias ? 1.0 : 0.0;
      ++taps;
    }
  return vec2(0.0, blocked / float(taps));
}

// sphere/'s lat-long: θ = π v from +Y, φ = 2π u, d = (−sin θ cos φ, cos θ, −sin θ sin φ).
vec2 latlong(vec3 d) {
  float phi = atan(-d.z, -d.x);
  if (phi < 0.0) phi += 2.0 * PI;
  return vec2(phi / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
}

float cap_cosine_integral(float c, float s2) {
  s2 = clamp(s2, 0.0, 1.0 - 1e-6);
  c = clamp(c, -1.0, 1.0);
  if (c * c > s2) return c > 0.0 ? PI * s2 * c : 0.0;
  float st = sqrt(max(0.0, 1.0 - c * c)), x = sqrt(1.0 / s2 - 1.0), y = clamp(-x * c / st, -1.0, 1.0);
  float sy = st * sqrt(max(0.0, 1.0 - y * y));
  return max(0.0, (c * acos(y) - x * sy) * s2 + atan(sy / x));
}
