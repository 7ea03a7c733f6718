// The shading model of iblkit/render/shading.h, formula for formula, shared by the forward
// fragment shader (shade.frag) and the deferred compute shader (shade.comp):
//   L_o = (albedo/π)·E(n) + specular·G(r)
//   E(n) = Σ Â_l c_lm Y_lm(n),  G(r) = Σ ρ̂_l(s) c_lm Y_lm(r)   (SH environment or SH grid at p)
//   + per directional light: V·E_i·max(0, n·l) and V·E_i·(s+1)/2π·max(0, r·l)^s where n·l > 0,
//     and the same per point light with l towards it and E_i = I_i/d², and per textured spotlight
//     with E_i·(n·l) = spot_irradiance() (nearfield/spotlight.h).
//   or G(r) from a prefiltered map of a distant probe (render/prefilter.h).
// Needs SH_BANDS, SH_K, sh_eval() and GLOSSY defined before it.
uniform vec3 u_eye;

uniform int u_sh_mode;  // 0: no SH light, 1: environment, 2: SH grid
uniform vec3 u_env[SH_K];
uniform float u_diffuse_zh[SH_BANDS];
// All coefficients in one RGBA16F 3D texture: coefficient k occupies slices [k·nz, (k+1)·nz).
// Lookups clamp z to the block's texel centres, so trilinear filtering never mixes coefficients.
uniform sampler3D u_grid;
uniform vec3 u_grid_min;
uniform vec3 u_grid_max;
uniform vec3 u_grid_res;

struct Light {
  vec4 direction;   // xyz: unit direction towards the light; w: shadow layer or −1
  vec4 irradiance;  // rgb
};
layout(std430, binding = 0) readonly buffer Lights { Light lights[]; };
layout(std430, binding = 1) readonly buffer ShadowMatrices { mat4 shadow_matrices[]; };
uniform int u_light_count;
struct PointLightGpu {
  vec4 position;   // xyz: world position; w: shadow layer or −1 (the first of six for a cube)
  vec4 intensity;  // rgb, W/sr; w: 1 for a cube shadow map (faces +X −X +Y −Y +Z −Z)
};
layout(std430, binding = 7) readonly buffer PointLights { PointLightGpu point_lights[]; };
uniform int u_point_light_count;
// Textured spotlights (nearfield/spotlight.h, formula for formula).
struct SpotGpu {
  vec4 position;  // xyz: filter centre; w: shadow layer in u_spot_shadows or −1
  vec4 right;     // xyz: s axis; w: tex_min.x
  vec4 up;        // xyz: t axis; w: tex_min.y
  vec4 forward;   // xyz: normal of S towards M; w: plane distance d
  vec4 extent;    // tex_max.x, tex_max.y, support area A, support width
  vec4 tex;       // x: level-0 texel size (m), y: mip levels, z: layer in u_spot_textures, w: the
                  // scale the layer was divided by (its largest |texel|: half floats stop at 65504)
};
layout(std430, binding = 8) readonly buffer Spots { SpotGpu spots[]; };
layout(std430, binding = 9) readonly buffer SpotShadowMatrices { mat4 spot_shadow_matrices[]; };
uniform int u_spot_count;
uniform sampler2DArray u_spot_textures;
uniform sampler2DArrayShadow u_spot_shadows;
uniform sampler2DArrayShadow u_shadow_maps;
uniform float u_shadow_bias;

const float PI = 3.14159265358979;

// ρ̂_l(s) of the material being shaded: defined by the including shader (a uniform array in the
// forward path, the material table in the deferred path).
float glossy_factor(int l);
// Layer of the material's prefiltered glossy map in u_glossy_maps, or −1 (same two sources).
int glossy_layer();
// Prefiltered Phong maps of a distant probe (render/prefilter.h): lat-long, u repeats, v clamps.
uniform sampler2DArray u_glossy_maps;

float visibility(vec3 p, vec3 n, int layer) {
  vec4 q = shadow_matrices[layer] * vec4(p + n * u_shadow_bias, 1.0);
  vec3 t = q.xyz / q.w * 0.5 + 0.5;
  if (any(lessThan(t.xy, vec2(0.0))) || any(greaterThan(t.xy, vec2(1.0)))) return 1.0;
  return texture(u_shadow_maps, vec4(t.xy, float(layer), t.z));
}

float spot_visibility(vec3 p, vec3 n, int layer) {
  vec4 q = spot_shadow_matrices[layer] * vec4(p + n * u_shadow_bias, 1.0);
  if (q.w <= 0.0) return 1.0;
  vec3 t = q.xyz / q.w * 0.5 + 0.5;
  if (any(lessThan(t, vec3(0.0))) || any(greaterThan(t, vec3(1.0)))) return 1.0;
  return texture(u_spot_shadows, vec4(t.xy, float(layer), t.z));
}

// A·cos θ·cos θ'/δ²·Ē'(p) of nearfield/spotlight.h (0 behind S or facing away).
vec3 spot_irradiance(SpotGpu L, vec3 p, vec3 n) {
  vec3 q = p - L.position.xyz;
  float z = dot(q, L.forward.xyz);
  if (z <= 0.0) return vec3(0.0);
  float d2 = dot(q, q), dl = sqrt(d2);
  float cos_l = z / dl, cos_r = -dot(n, q) / dl;
  if (cos_r <= 0.0) return vec3(0.0);
  float d = L.forward.w;
  float s = dot(q, L.right.xyz) * d / z, t = dot(q, L.up.xyz) * d / z;
  vec2 tmin = vec2(L.right.w, L.up.w), tmax = L.extent.xy;
  vec2 uv = vec2((s - tmin.x) / (tmax.x - tmin.x), (tmax.y - t) / (tmax.y - tmin.y));
  float footprint = L.extent.w * abs(1.0 - d / z);
  float lambda = footprint > 0.0 ? clamp(log2(footprint / L.tex.x), 0.0, L.tex.y - 1.0) : 0.0;
  vec3 e = textureLod(u_spot_textures, vec3(uv, L.tex.z), lambda).rgb * L.tex.w;
  return e * (L.extent.z * cos_l * cos_r / d2);
}

// Albedo textures (render::Material::texture), one layer each, all of one size: bilinear,
// repeating, uv (0,0) at the image's bottom-left (render::texture_albedo).
uniform sampler2DArray u_albedo_textures;
vec3 albedo_texture(vec2 uv, int layer) {
  return layer < 0 ? vec3(1.0) : texture(u_albedo_textures, vec3(uv.x, 1.0 - uv.y, float(layer))).rgb;
}

// lobe 0: Phong (s+1)/2π (r·l)^s; 1: Blinn-Phong (s+8)/8π (n·h)^s (n·l) for lights (render::Lobe).
vec3 shade(vec3 p, vec3 n_in, vec3 albedo, vec3 specular, float exponent, int lobe) {
  vec3 n = normalize(n_in);
  vec3 v = normalize(u_eye - p);
  vec3 r = normalize(2.0 * dot(n, v) * n - v);
  vec3 E = vec3(0.0), G = vec3(0.0);
  int gmap = u_sh_mode == 2 ? -1 : glossy_layer();
  if (gmap >= 0) {
    vec2 uv = vec2(atan(r.z, r.x) / (2.0 * PI) + 0.5, acos(clamp(r.y, -1.0, 1.0)) / PI);
    G += texture(u_glossy_maps, vec3(uv, float(gmap))).rgb;
  }
  if (u_sh_mode != 0) {
    float yn[SH_K], yr[SH_K];
    sh_eval(n, yn);
#if GLOSSY
    sh_eval(r, yr);
#endif
    vec3 tc = vec3(0.0);
    if (u_sh_mode == 2) {
      vec3 rel = clamp((p - u_grid_min) / (u_grid_max - u_grid_min), 0.0, 1.0);
      tc = rel * (u_grid_res - 1.0) + 0.5;  // in texels of one coefficient block
      tc.xy /= u_grid_res.xy;
    }
    float inv_depth = 1.0 / (u_grid_res.z * float(SH_K));
    for (int l = 0; l < SH_BANDS; ++l)
      for (int k = l * l; k < (l + 1) * (l + 1); ++k) {
        vec3 c = u_sh_mode == 2 ? texture(u_grid, vec3(tc.xy, (float(k) * u_grid_res.z + tc.z) * inv_depth)).rgb : u_env[k];
        E += c * (u_diffuse_zh[l] * yn[k]);
#if GLOSSY
        if (gmap < 0) G += c * (glossy_factor(l) * yr[k]);
#endif
      }
  }
  bool blinn = lobe == 1;
  float lobe_norm = blinn ? (exponent + 8.0) / (8.0 * PI) : (exponent + 1.0) / (2.0 * PI);
  for (int i = 0; i < u_light_count + u_point_light_count + u_spot_count; ++i) {
    vec3 l, irr;
    float layer;
    bool spot = i >= u_light_count + u_point_light_count;
    if (spot) {
      SpotGpu q = spots[i - u_light_count - u_point_light_count];
      vec3 to = q.position.xyz - p;
      float dl = length(to);
      if (!(dl > 0.0)) continue;
      l = to / dl;
      float ndl = dot(n, l);
      if (ndl <= 0.0) continue;
      irr = spot_irradiance(q, p, n) / ndl;
      if (irr == vec3(0.0)) continue;
      layer = q.position.w;
    } else if (i < u_light_count) {
      l = lights[i].direction.xyz;
      irr = lights[i].irradiance.rgb;
      layer = lights[i].direction.w;
    } else {
      PointLightGpu q = point_lights[i - u_light_count];
      vec3 to = q.position.xyz - p;
      float d2 = dot(to, to);
      if (!(d2 > 0.0)) continue;
      l = to * inversesqrt(d2);
      irr = q.intensity.rgb / d2;
      layer = q.position.w;
      if (layer >= 0.0 && q.intensity.w > 0.5) {  // cube: the face of the largest component of p − light
        vec3 a = abs(-to);
        int face = a.x >= a.y && a.x >= a.z ? (-to.x >= 0.0 ? 0 : 1) : (a.y >= a.z ? (-to.y >= 0.0 ? 2 : 3) : (-to.z >= 0.0 ? 4 : 5));
        layer += float(face);
      }
    }
    float ndl = dot(n, l);
    if (ndl <= 0.0) continue;
    if (layer >= 0.0) irr *= spot ? spot_visibility(p, n, int(layer)) : visibility(p, n, int(layer));
    E += irr * ndl;
    if (blinn) {
      float ndh = dot(n, normalize(l + v));
      if (ndh > 0.0) G += irr * (lobe_norm * pow(ndh, exponent) * ndl);
    } else {
      float rdl = dot(r, l);
      if (rdl > 0.0) G += irr * (lobe_norm * pow(rdl, exponent));
    }
  }
  return max(albedo * E / PI + specular * G, vec3(0.0));
}
