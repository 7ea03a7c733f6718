#include "iblkit/augment/composite.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "iblkit/augment/split_light.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/geometry/raytracer.h"

namespace ibl::augment {

namespace {

constexpr double kRayEpsilon = 1e-4;       // metres: secondary rays start this far off the surface
constexpr double kShadowShorten = 1e-3;    // relative: rays towards a patch stop this short of it
constexpr double kUnlitIrradiance = 1e-9;  // W/m²: below this the albedo is unknown
constexpr double kInsideShare = 0.5;       // camera inside the proxy: this share of its rays hit back faces

// SplitMix64 (Steele, Lea & Flood 2014): counter-based streams keyed by (seed, pixel, purpose).
uint64_t mix(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
struct Rng {
  uint64_t s;
  Rng(uint64_t seed, uint64_t a, uint64_t b) : s(mix(mix(mix(seed) ^ a) ^ b)) {}
  double uniform() {
    s += 0x9e3779b97f4a7c15ull;
    return static_cast<double>(mix(s) >> 11) * 0x1.0p-53;
  }
};

struct Sphere {
  Vec3 c;
  double r = 0;
  // Does the segment x + t·w, t in (0, tfar), come within r of c?
  bool meets(Vec3 x, Vec3 w, double tfar) const {
    Vec3 v = c - x;
    double t = std::clamp(dot(v, w), 0.0, tfar), d2 = dot(v, v) - 2 * t * dot(v, w) + t * t;
    return d2 <= r * r;
  }
};

struct Scene {
  const geometry::TriMesh& proxy;
  const geometry::TriMesh& object;
  geometry::RayTracer proxy_rt, object_rt, both_rt;  // both: proxy = mesh 0, object = mesh 1
  Sphere bound;
  const LightField* light = nullptr;
};

double patch_tfar(double dist) {
  return std::isinf(dist) ? std::numeric_limits<double>::infinity() : dist * (1 - kShadowShorten) - kRayEpsilon;
}

// E at x (normal n) from `count` stratified patch samples, visibility against `rt`; `shadowed`: the proxy's
// patches darkened by the object's shadow on them (the light an object point receives).
Vec3 irradiance(const Scene& s, const geometry::RayTracer& rt, Vec3 x, Vec3 n, int count, Rng& rng,
                bool shadowed = false) {
  Vec3 e;
  for (int k = 0; k < count; ++k) {
    double pmf;
    size_t i = s.light->sample((k + rng.uniform()) / count, &pmf);
    Vec3 w;
    double dist;
    Vec3 c = s.light->contribution(i, x, n, &w, &dist, shadowed);
    if (max_component(c) <= 0 || rt.occluded(x, w, kRayEpsilon, patch_tfar(dist))) continue;
    e += c / pmf;
  }
  return e / count;
}

// The object's outgoing radiance towards v at z (normal n, diffuse albedo rho): ρ/π E + specular·G, E and G
// from the same `count` patch samples, occluded by `rt` (proxy and object), the proxy's patches near the object
// darkened by its shadow.
Vec3 object_radiance(const Scene& s, Vec3 z, Vec3 n, Vec3 v, Vec3 rho, const render::Material& m, int count, Rng& rng) {
  const bool glossy = max_component(m.specular) > 0;
  const Vec3 r = normalize(n * (2 * dot(n, v)) - v);
  Vec3 e, g;
  for (int k = 0; k < count; ++k) {
    double pmf;
    size_t i = s.light->sample((k + rng.uniform()) / count, &pmf);
    Vec3 w;
    double dist;
    Vec3 c = s.light->contribution(i, z, n, &w, &dist, true);
    if (max_component(c) <= 0 || s.both_rt.occluded(z, w, kRayEpsilon, patch_tfar(dist))) continue;
    c = c / pmf;
    e += c;
    if (glossy)
      g += c * (render::glossy_lobe(m, n, v, r, w) / dot(n, w));  // c / cos: the irradiance at normal incidence
  }
  return (rho * e / kPi + m.specular * g) / count;
}

// The diffuse albedo at a point of object triangle `tri` with barycentrics b1, b2 (the texture at its UVs).
Vec3 object_albedo(const geometry::TriMesh& o, const render::Material& m, uint32_t tri, double b1, double b2) {
  if (!m.texture) return m.albedo;
  Vec2 uv{0, 0};
  if (o.has_uvs()) {
    const auto& t = o.triangles[tri];
    uv = o.uvs[t[0]] * (1 - b1 - b2) + o.uvs[t[1]] * b1 + o.uvs[t[2]] * b2;
  }
  return m.albedo * render::texture_albedo(*m.texture, uv);
}

// The cone of directions from y (normal n) that can meet the object: its bounding sphere's, or the hemisphere
// about n when y lies inside that sphere. Uniform in it: pdf 1/solid_angle.
struct Cone {
  Frame f;
  double cos_max = 0, solid_angle = 0;
  bool hemisphere = false;
  Cone(const Sphere& b, Vec3 y, Vec3 n) : f(Frame::from_normal(n)) {
    Vec3 axis = b.c - y;
    double d = length(axis);
    hemisphere = d <= b.r;
    cos_max = hemisphere ? 0 : std::sqrt(std::max(0.0, 1 - (b.r / d) * (b.r / d)));
    if (!hemisphere) f = Frame::from_normal(axis / d);
    solid_angle = 2 * kPi * (1 - cos_max);
  }
  bool contains(Vec3 w) const { return dot(w, f.n) >= cos_max; }
  Vec3 direction(double u1, double u2) const {
    double ct = 1 - u1 * (1 - cos_max), st = std::sqrt(std::max(0.0, 1 - ct * ct)), phi = 2 * kPi * u2;
    return f.from_local({st * std::cos(phi), st * std::sin(phi), ct});
  }
};

// At proxy point y (normal n): E₀, the irradiance the object blocks, and (with tri_radiance) the object's
// light on y. The blocked light is the integral over the object's silhouette of the patches' radiance; it is
// estimated from two strategies with the balance heuristic (Veach 1997): the `count` patch samples E₀ uses
// (good for the sun, lamps and any small bright source) and `cone` directions uniform in the cone towards the
// object (good where the object covers a small share of a broad sky: a far pixel's faint soft shadow); lamps
// (free emitters) come from patch samples alone. The cone samples also give the object's light on y. Only
// samples that meet the object add to `blocked` and `bounce`.
void proxy_terms(const Scene& s, const std::vector<Vec3>* tri_radiance, Vec3 y, Vec3 n, int count, int cone_count,
                 Rng& rng, Vec3* e0, Vec3* blocked, Vec3* bounce) {
  const LightField& L = *s.light;
  const Cone cone(s.bound, y, n);
  const double n1 = count, n2 = cone_count, pc = cone_count > 0 ? 1 / cone.solid_angle : 0;
  const int table = L.table_for(n);
  Vec3 a, b;
  // The patches are drawn a batch at a time and their records fetched ahead: each is a cache miss in a map
  // of 10⁴–10⁶ patches, and fetched together they overlap.
  constexpr int kBatch = 32;
  std::array<size_t, kBatch> drawn;
  std::array<double, kBatch> drawn_pmf;
  for (int k = 0; k < count; ++k) {
    if (k % kBatch == 0)
      for (int j = 0; j < kBatch && k + j < count; ++j) {
        drawn[static_cast<size_t>(j)] =
            L.sample((k + j + rng.uniform()) / count, &drawn_pmf[static_cast<size_t>(j)], table);
        L.prefetch(drawn[static_cast<size_t>(j)]);
      }
    const size_t i = drawn[static_cast<size_t>(k % kBatch)];
    const double pmf = drawn_pmf[static_cast<size_t>(k % kBatch)];
    Vec3 w;
    double dist;
    Vec3 c = L.contribution(i, y, n, &w, &dist);
    double tfar = patch_tfar(dist);
    if (max_component(c) <= 0 || s.proxy_rt.occluded(y, w, kRayEpsilon, tfar)) continue;
    c = c / pmf;
    a += c;
    if (s.bound.meets(y, w, tfar) && s.object_rt.occluded(y, w, kRayEpsilon, tfar)) {
      double weight = 1;
      if (cone_count > 0 && !L.lamp(i) && cone.contains(w)) {
        double pp = pmf / L.solid_angle_at(i, y);  // this sample's density per steradian
        weight = n1 * pp / (n1 * pp + n2 * pc);
      }
      b += c * weight;
    }
  }
  *e0 = a / n1;
  *blocked = b / n1;
  // A cone direction meets the object first (object_rt) and then, behind it, the proxy (proxy_rt): the proxy
  // nearer than the object hides it; otherwise that proxy hit is the patch whose light the object blocks.
  Vec3 bl, li;
  auto m = static_cast<int>(std::lround(std::sqrt(n2)));
  for (int k = 0; k < cone_count; ++k) {
    double u1 = rng.uniform(), u2 = rng.uniform();
    if (m * m == cone_count) {
      u1 = (k % m + u1) / m;
      u2 = (k / m + u2) / m;
    }
    Vec3 w = cone.direction(u1, u2);
    double cn = dot(w, n);
    if (cn <= 0) continue;
    geometry::Hit ho = s.object_rt.intersect(y, w, kRayEpsilon);
    if (!ho.hit) continue;
    geometry::Hit hp = s.proxy_rt.intersect(y, w, kRayEpsilon);
    if (hp.hit && hp.t < ho.t) continue;  // the proxy is in front of the object along w
    if (tri_radiance) li += (*tri_radiance)[ho.triangle] * cn;
    long i = L.patch_along(y, w, hp);
    if (i < 0) continue;
    double pp = L.pmf(static_cast<size_t>(i), table) / std::max(L.solid_angle_at(static_cast<size_t>(i), y), 1e-300);
    bl += L.radiance(static_cast<size_t>(i)) * (cn / (n1 * pp + n2 * pc));
  }
  *blocked += bl;
  *bounce = cone_count > 0 ? li / (n2 * pc) : Vec3{};
}

// The object's shadow on the proxy patches near it (within kShadowReach bounding radii of its centre),
// as factors E_with / E₀ of their radiance: the floor under an object does not light its underside.
constexpr double kShadowReach = 4;
void shadow_patches(const Scene& s, LightField& field, int count, int cone_count, uint64_t seed) {
  std::vector<size_t> near;
  for (size_t i = 0; i < field.size(); ++i)
    if (field.local(i) && length(field.point(i) - s.bound.c) < kShadowReach * s.bound.r) near.push_back(i);
  std::vector<Vec3> factor(near.size(), Vec3{1, 1, 1});
  parallel_for(
      0, static_cast<int64_t>(near.size()),
      [&](int64_t k) {
        size_t i = near[static_cast<size_t>(k)];
        Vec3 n = field.normal(i), e0, blocked;
        Rng rng(seed, 0x706174 /* "pat" */, i);
        Vec3 unused;
        proxy_terms(s, nullptr, field.point(i) + n * kRayEpsilon, n, count, cone_count, rng, &e0, &blocked, &unused);
        for (int c = 0; c < 3; ++c)
          if (e0[c] > kUnlitIrradiance)
            factor[static_cast<size_t>(k)][c] = std::clamp(1 - blocked[c] / e0[c], 0.0, 1.0);
      },
      64);
  for (size_t k = 0; k < near.size(); ++k) field.set_shadow(near[k], factor[k]);
}

// The tracers and the object's bounding sphere.
void build(Scene& s) {
  s.proxy_rt.add(s.proxy);
  s.proxy_rt.commit();
  s.object_rt.add(s.object);
  s.object_rt.commit();
  s.both_rt.add(s.proxy);
  s.both_rt.add(s.object);
  s.both_rt.commit();
  Vec3 lo, hi;
  s.object.bounds(&lo, &hi);
  s.bound.c = (lo + hi) * 0.5;
  for (const Vec3& p : s.object.positions) s.bound.r = std::max(s.bound.r, length(p - s.bound.c));
  s.bound.r *= 1 + 1e-6;
}

void check_geometry(const Scene& s, const geometry::Camera& cam) {
  // The camera inside a closed proxy (or a solid part of it): most of its rays meet back faces.
  int back = 0, hits = 0;
  constexpr int kGrid = 16;
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j) {
      Vec3 d = cam.ray_direction((j + 0.5) * cam.width / kGrid, (i + 0.5) * cam.height / kGrid);
      geometry::Hit h = s.proxy_rt.intersect(cam.eye, d);
      if (!h.hit) continue;
      ++hits;
      if (dot(s.proxy.normal(h.triangle), d) > 0) ++back;
    }
  if (hits > 0 && back > kInsideShare * kGrid * kGrid)
    fail(ErrorKind::Value,
         "the camera at ({:.3g}, {:.3g}, {:.3g}) is inside the proxy: {} of its {} rays meet the proxy's back faces "
         "(move the eye, or flip the proxy's triangles to face the camera)",
         cam.eye.x, cam.eye.y, cam.eye.z, back, kGrid * kGrid);
  // The object intersecting the proxy: an object edge crosses a proxy triangle.
  int64_t crossing = 0;
  for (const auto& t : s.object.triangles)
    for (int e = 0; e < 3; ++e) {
      Vec3 a = s.object.positions[t[e]], b = s.object.positions[t[(e + 1) % 3]];
      double len = length(b - a);
      if (len > 0 && s.proxy_rt.occluded(a, (b - a) / len, 0, len)) ++crossing;
    }
  if (crossing > 0)
    fail(ErrorKind::Value,
         "the object intersects the proxy ({} of its edges cross it): move it (at) or make it smaller (size)",
         crossing);
}

}  // namespace

CompositeResult composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                          const LocalLight& light, const geometry::TriMesh& object, const render::Material& material,
                          const CompositeDesc& desc) {
  auto t0 = std::chrono::steady_clock::now();
  const int W = photo.width(), H = photo.height(), n = desc.pixel_samples;
  if (photo.channels() < 3)
    fail(ErrorKind::Value, "the photograph has {} channels; an RGB image is needed", photo.channels());
  if (W != cam.width || H != cam.height)
    fail(ErrorKind::Value, "the photograph is {}x{} but the camera's frame is {}x{}", W, H, cam.width, cam.height);
  if (n < 1 || n > 8) fail(ErrorKind::Value, "pixel_samples {} must lie in 1..8", n);
  if (desc.light_samples < 1 || desc.object_samples < 1 || desc.triangle_samples < 1 || desc.bounce_samples < 0)
    fail(ErrorKind::Value, "sample counts must be ≥ 1 (bounce samples ≥ 0)");
  if (proxy.triangle_count() == 0) fail(ErrorKind::Value, "the proxy has no triangles");
  if (object.triangle_count() == 0) fail(ErrorKind::Value, "the object has no triangles");
  for (int c = 0; c < 3; ++c)
    if (!(material.albedo[c] >= 0 && material.albedo[c] <= 1 && material.specular[c] >= 0 && material.specular[c] <= 1))
      fail(ErrorKind::Value, "object albedo ({}, {}, {}) and gloss ({}, {}, {}) must lie in [0, 1]", material.albedo.x,
           material.albedo.y, material.albedo.z, material.specular.x, material.specular.y, material.specular.z);
  if (!(material.exponent >= 1 && material.exponent <= 1e4))
    fail(ErrorKind::Value, "glossy exponent {} must lie in 1..10000", material.exponent);
  if (material.texture && (material.texture->empty() || material.texture->channels() < 3))
    fail(ErrorKind::Value, "the object's texture must be an RGB image");
  Scene s{proxy, object, {}, {}, {}, {}, nullptr};
  build(s);
  if (desc.check_geometry) check_geometry(s, cam);
  LightField field(light, proxy, s.proxy_rt);
  s.light = &field;
  if (desc.shadows) shadow_patches(s, field, desc.light_samples, desc.bounce_samples, desc.seed);

  // The object's radiance per triangle (for its light on the proxy).
  std::vector<Vec3> tri_radiance(object.triangle_count());
  if (desc.bounce_samples > 0)
    parallel_for(
        0, static_cast<int64_t>(object.triangle_count()),
        [&](int64_t ti) {
          const auto& t = object.triangles[static_cast<size_t>(ti)];
          Vec3 nn = object.normal(static_cast<size_t>(ti));
          Vec3 c = (object.positions[t[0]] + object.positions[t[1]] + object.positions[t[2]]) / 3.0;
          Rng rng(desc.seed, 0x747269 /* "tri" */, static_cast<uint64_t>(ti));
          tri_radiance[static_cast<size_t>(ti)] =
              object_albedo(object, material, static_cast<uint32_t>(ti), 1.0 / 3, 1.0 / 3) *
              irradiance(s, s.both_rt, c + nn * kRayEpsilon, nn, desc.triangle_samples, rng, true) / kPi;
        },
        256);
  report(desc.progress, "object", 1.0);

  CompositeResult r;
  r.composite = Image(W, H, 3);
  r.mask = Image(W, H, 1);
  r.difference = Image(W, H, 3);
  r.albedo = Image(W, H, 3);
  r.render_without = Image(W, H, 3);
  r.render_with = Image(W, H, 3);
  std::atomic<int64_t> proxy_px{0}, object_px{0}, changed{0}, over{0}, unlit{0};
  std::atomic<int> rows{0};
  const int obj_per_ray = std::max(1, desc.object_samples / (n * n));
  parallel_for(0, H, [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < W; ++x) {
      const uint64_t pixel = static_cast<uint64_t>(y) * W + x;
      Vec3 obj_sum, proxy_dir;
      int obj_hits = 0;
      bool have_proxy = false;
      double proxy_t = 0;
      uint32_t proxy_tri = 0;
      for (int k = 0; k < n * n; ++k) {
        int kk = (k + (n * n) / 2) % (n * n);  // the centre-most ray first (proxy lookups prefer it)
        Vec3 d = cam.ray_direction(x + (kk % n + 0.5) / n, y + (kk / n + 0.5) / n);
        geometry::Hit h = s.both_rt.intersect(cam.eye, d);
        if (!h.hit) continue;
        if (h.mesh == 1) {
          Vec3 nn = object.normal(h.triangle);
          if (dot(nn, d) > 0) nn = -nn;
          Vec3 z = cam.eye + d * h.t;
          Rng rng(desc.seed, 0x6f626a /* "obj" */, pixel * 64 + static_cast<uint64_t>(kk));
          obj_sum +=
              object_radiance(s, z + nn * kRayEpsilon, nn, -d, object_albedo(object, material, h.triangle, h.b1, h.b2),
                              material, obj_per_ray, rng);
          ++obj_hits;
        } else if (!have_proxy) {
          have_proxy = true;
          proxy_dir = d;
          proxy_t = h.t;
          proxy_tri = h.triangle;
        }
      }
      const Vec3 ph = photo.rgb(x, y);
      Vec3 comp = ph, without, with, rho;
      if (have_proxy) ++proxy_px;
      if (have_proxy && desc.shadows) {
        Vec3 nn = proxy.normal(proxy_tri);
        if (dot(nn, proxy_dir) > 0) nn = -nn;
        Vec3 yp = cam.eye + proxy_dir * proxy_t + nn * kRayEpsilon;
        Rng rng(desc.seed, 0x707278 /* "prx" */, pixel);
        Vec3 e0, blocked, bounce;
        proxy_terms(s, &tri_radiance, yp, nn, desc.light_samples, desc.bounce_samples, rng, &e0, &blocked, &bounce);
        Vec3 dE = bounce - blocked;
        bool bad = false, lit = true;
        for (int c = 0; c < 3; ++c) {
          if (e0[c] > kUnlitIrradiance) {
            rho[c] = kPi * ph[c] / e0[c];
            comp[c] = std::max(
                0.0, ph[c] + std::min(rho[c], 1.0) * dE[c] / kPi);  // a reflectance > 1 changes no more than 1 would
            bad = bad || rho[c] > 1;
          } else {
            lit = false;
          }
        }
        if (!lit) ++unlit;
        if (bad) ++over;
        if (dE.x != 0 || dE.y != 0 || dE.z != 0) ++changed;
        without = rho * e0 / kPi;
        with = rho * (e0 + dE) / kPi;
        for (int c = 0; c < 3; ++c) with[c] = std::max(0.0, with[c]);
      }
      double f = static_cast<double>(obj_hits) / (n * n);
      if (obj_hits > 0) {
        ++object_px;
        Vec3 lo_ = obj_sum / obj_hits;
        comp = comp * (1 - f) + lo_ * f;
        with = with * (1 - f) + lo_ * f;
      }
      r.composite.set_rgb(x, y, comp);
      r.mask.at(x, y, 0) = static_cast<float>(f);
      r.difference.set_rgb(x, y, comp - ph);
      r.albedo.set_rgb(x, y, rho);
      r.render_without.set_rgb(x, y, without);
      r.render_with.set_rgb(x, y, with);
    }
    report(desc.progress, "composite", static_cast<double>(++rows) / H);
  });
  r.stats = {proxy_px, object_px, changed,
             over,     unlit,     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()};
  if (r.stats.albedo_over_one > 0)
    r.warnings.push_back(
        fmt::format("{} proxy pixels ({:.1f} %) have an estimated albedo > 1: the captured light is weaker there than "
                    "the photograph says (a light the probe misses, or a wrong proxy); kept as photographed",
                    r.stats.albedo_over_one, 100.0 * r.stats.albedo_over_one / std::max<int64_t>(1, proxy_px)));
  if (r.stats.unlit > 0)
    r.warnings.push_back(
        fmt::format("{} proxy pixels receive no captured light in some channel: their albedo is unknown and they "
                    "keep the photograph's value",
                    r.stats.unlit));
  if (r.stats.object_pixels == 0)
    r.warnings.push_back("no pixel of the photograph sees the object: check at, the eye and the target");
  return r;
}

constexpr double kMaxSoftFactor = 16;  // composite.h: soft_visibility's f
constexpr int kMaxPoolRings = 3;

std::vector<Vec3> soft_visibility(const LocalLight& light, const geometry::TriMesh& proxy,
                                  const geometry::TriMesh& object, const SoftVisibilityDesc& desc) {
  if (desc.samples < 1 || desc.samples > 65536)
    fail(ErrorKind::Value, "soft visibility samples {} must lie in 1..65536", desc.samples);
  if (desc.shadow_samples < 1 || desc.shadow_cone < 0)
    fail(ErrorKind::Value, "shadow samples must be ≥ 1 (cone samples ≥ 0)");
  if (!(desc.threshold >= 0) || !std::isfinite(desc.threshold))
    fail(ErrorKind::Value, "soft threshold {} must be ≥ 0", desc.threshold);
  if (proxy.triangle_count() == 0) fail(ErrorKind::Value, "the proxy has no triangles");
  if (object.triangle_count() == 0) fail(ErrorKind::Value, "the object has no triangles");
  Scene s{proxy, object, {}, {}, {}, {}, nullptr};
  build(s);
  LightField field(light, proxy, s.proxy_rt);
  s.light = &field;
  if (desc.proxy) shadow_patches(s, field, desc.shadow_samples, desc.shadow_cone, desc.seed);
  const double limit =
      desc.threshold > 0 ? desc.threshold * field.total_power() / (4 * kPi) : std::numeric_limits<double>::infinity();
  const geometry::RayTracer& rt = desc.proxy ? s.both_rt : s.object_rt;
  const int count = desc.samples;
  const size_t T = object.triangle_count();
  std::vector<Vec3> nums(T), dens(T);
  parallel_for(
      0, static_cast<int64_t>(T),
      [&](int64_t ti) {
        const auto& t = object.triangles[static_cast<size_t>(ti)];
        const Vec3 n = object.normal(static_cast<size_t>(ti));
        const Vec3 z =
            (object.positions[t[0]] + object.positions[t[1]] + object.positions[t[2]]) / 3.0 + n * kRayEpsilon;
        Rng rng(desc.seed, 0x766973 /* "vis" */, static_cast<uint64_t>(ti));
        Vec3 num, den;
        for (int k = 0; k < count; ++k) {
          double pmf;
          size_t i = field.sample((k + rng.uniform()) / count, &pmf);
          if (split_measure(field.radiance(i)) > limit) continue;  // a hard light's texel: the shadow maps' part
          Vec3 w;
          double dist;
          if (desc.proxy)
            den += field.contribution(i, light.centre, n, &w, &dist) / pmf;  // E_c(n), what the shader has
          Vec3 c = field.contribution(i, z, n, &w, &dist);
          if (max_component(c) <= 0) continue;
          if (!desc.proxy) den += c / pmf;
          if (rt.occluded(z, w, kRayEpsilon, patch_tfar(dist))) continue;
          num += (desc.proxy ? field.contribution(i, z, n, &w, &dist, true) : c) / pmf;
        }
        nums[static_cast<size_t>(ti)] = num;
        dens[static_cast<size_t>(ti)] = den;
      },
      256);
  // Each triangle's factor pools the sums of the triangles around it (rings of shared vertices, at most
  // kMaxPoolRings) until they hold desc.pool_rays rays: the rasterised object shows one triangle's factor per
  // sample, so its grain depends on the rays per triangle, and a dense mesh's neighbours see nearly what it sees.
  std::vector<uint32_t> first(object.vertex_count() + 1, 0), incident;
  for (const auto& t : object.triangles)
    for (uint32_t v : t) ++first[v + 1];
  for (size_t v = 0; v < object.vertex_count(); ++v) first[v + 1] += first[v];
  incident.resize(first.back());
  {
    std::vector<uint32_t> at(first.begin(), first.end() - 1);
    for (uint32_t ti = 0; ti < T; ++ti)
      for (uint32_t v : object.triangles[ti]) incident[at[v]++] = ti;
  }
  const size_t want = static_cast<size_t>(std::max(desc.pool_rays, count)) / static_cast<size_t>(count);  // triangles
  std::vector<Vec3> f(T, Vec3{1, 1, 1});
  parallel_for(
      0, static_cast<int64_t>(T),
      [&](int64_t ti) {
        std::vector<uint32_t> pool{static_cast<uint32_t>(ti)},
            verts(object.triangles[static_cast<size_t>(ti)].begin(), object.triangles[static_cast<size_t>(ti)].end());
        for (int ring = 0; ring < kMaxPoolRings && pool.size() < want; ++ring) {
          std::vector<uint32_t> next;
          for (uint32_t v : verts)
            for (uint32_t k = first[v]; k < first[v + 1]; ++k) {
              const uint32_t u = incident[k];
              if (std::find(pool.begin(), pool.end(), u) != pool.end()) continue;
              pool.push_back(u);
              for (uint32_t w : object.triangles[u]) next.push_back(w);
            }
          verts.swap(next);
        }
        Vec3 num, den;
        for (uint32_t u : pool) {
          num += nums[u];
          den += dens[u];
        }
        for (int c = 0; c < 3; ++c)
          if (den[c] > 0) f[static_cast<size_t>(ti)][c] = std::clamp(num[c] / den[c], 0.0, kMaxSoftFactor);
      },
      256);
  return f;
}

}  // namespace ibl::augment
