#version 450 core
// Deferred path, pass 2: for every pixel of the visibility buffer, intersect the camera ray through
// the pixel centre with the triangle it names (exact, perspective-correct barycentrics, as the CPU
// reference does), interpolate position and normal, and run shade() from shading.glsl.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 2) uniform usampler2D u_visibility;
layout(rgba32f, binding = 0) writeonly uniform image2D u_out;
struct MaterialGpu {
  vec4 albedo;          // rgb, w = layer of the prefiltered glossy map or −1
  vec4 specular;        // rgb, w = Phong exponent
  float glossy_zh[12];  // ρ̂_l(s) for l < SH_BANDS (≤ 12), s the material's environment exponent
  vec4 extra;           // x: albedo texture layer or −1, y: lobe (0 Phong, 1 Blinn-Phong)
};
struct ObjectGpu {
  uint first_vertex;  // into positions/normals (in vertices)
  uint first_index;   // into indices
  uint pad0, pad1;
};
layout(std430, binding = 2) readonly buffer Materials { MaterialGpu materials[]; };
layout(std430, binding = 3) readonly buffer Objects { ObjectGpu objects[]; };
layout(std430, binding = 4) readonly buffer Positions { float positions[]; };
layout(std430, binding = 5) readonly buffer Normals { float normals[]; };
layout(std430, binding = 6) readonly buffer Indices { uint indices[]; };
layout(std430, binding = 10) readonly buffer Uvs { float uvs[]; };
uniform vec3 u_background;
// Camera ray through pixel (x, y): normalize(u_ray00 + (x + ½)·u_ray_dx + (y + ½)·u_ray_dy).
uniform vec3 u_ray00;
uniform vec3 u_ray_dx;
uniform vec3 u_ray_dy;

int g_material = 0;
float glossy_factor(int l) { return materials[g_material].glossy_zh[l]; }
int glossy_layer() { return int(materials[g_material].albedo.w); }

vec3 fetch3(uint v, bool normal) {
  return normal ? vec3(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u])
                : vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

void main() {
  ivec2 q = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = imageSize(u_out);
  if (any(greaterThanEqual(q, size))) return;
  // q is in GL's bottom-up rows (like the visibility buffer and the output); the camera rays count
  // rows from the top, like the CPU renderer.
  uint id = texelFetch(u_visibility, q, 0).r;
  float row_from_top = float(size.y - 1 - q.y);
  if (id == 0u) {
    imageStore(u_out, q, vec4(u_background, 0.0));
    return;
  }
  uint obj = (id >> 24) - 1u, tri = id & 0xFFFFFFu;
  g_material = int(obj);
  ObjectGpu o = objects[obj];
  uint i0 = o.first_vertex + indices[o.first_index + 3u * tri];
  uint i1 = o.first_vertex + indices[o.first_index + 3u * tri + 1u];
  uint i2 = o.first_vertex + indices[o.first_index + 3u * tri + 2u];
  vec3 p0 = fetch3(i0, false), p1 = fetch3(i1, false), p2 = fetch3(i2, false);
  vec3 dir = normalize(u_ray00 + (float(q.x) + 0.5) * u_ray_dx + (row_from_top + 0.5) * u_ray_dy);
  // Möller–Trumbore, without culling (the rasteriser already chose this triangle).
  vec3 e1 = p1 - p0, e2 = p2 - p0, pv = cross(dir, e2);
  float det = dot(e1, pv);
  vec3 tv = u_eye - p0;
  float b1 = dot(tv, pv) / det;
  vec3 qv = cross(tv, e1);
  float b2 = dot(dir, qv) / det;
  b1 = clamp(b1, 0.0, 1.0);
  b2 = clamp(b2, 0.0, 1.0 - b1);
  float b0 = 1.0 - b1 - b2;
  vec3 p = b0 * p0 + b1 * p1 + b2 * p2;
  vec3 n = b0 * fetch3(i0, true) + b1 * fetch3(i1, true) + b2 * fetch3(i2, true);
  MaterialGpu m = materials[g_material];
  vec3 albedo = m.albedo.rgb;
  int layer = int(m.extra.x);
  if (layer >= 0) {
    vec2 uv = b0 * vec2(uvs[2u * i0], uvs[2u * i0 + 1u]) + b1 * vec2(uvs[2u * i1], uvs[2u * i1 + 1u]) +
              b2 * vec2(uvs[2u * i2], uvs[2u * i2 + 1u]);
    albedo *= albedo_texture(uv, layer);
  }
  imageStore(u_out, q, vec4(shade(p, n, albedo, m.specular.rgb, m.specular.w, int(m.extra.y)), 1.0));
}
