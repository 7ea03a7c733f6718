#include "iblkit/augment/composite.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "iblkit/augment/proxy_light.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/geometry/raytracer.h"

namespace ibl::augment {

namespace {

constexpr double kInsideShare = 0.5;  // camera inside the proxy: this share of its rays hit back faces

void check_geometry(const Tracers& s, const geometry::Camera& cam) {
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
  for (const auto& t : s.object->triangles)
    for (int e = 0; e < 3; ++e) {
      Vec3 a = s.object->positions[t[e]], b = s.object->positions[t[(e + 1) % 3]];
      double len = length(b - a);
      // Only a crossing inside the edge counts: an object resting on the floor touches it at its vertices.
      if (len > 2 * kRayEpsilon && s.proxy_rt.occluded(a, (b - a) / len, kRayEpsilon, len - kRayEpsilon)) ++crossing;
    }
  if (crossing > 0)
    fail(ErrorKind::Value,
         "the object intersects the proxy ({} of its edges cross it): move it (at) or make it smaller (size)",
         crossing);
}

// What one photograph pixel becomes (composite.h): n×n camera rays, those that meet the object shaded on
// it, the first that meets the proxy giving the proxy's terms at the pixel.
struct PixelResult {
  Vec3 composite, rho, without, with;
  double coverage = 0;
  bool proxy = false, changed = false, over_one = false, unlit = false;
};

struct Shading {
  const Tracers& t;
  const geometry::Camera& cam;
  const render::Material& material;
  const std::vector<Vec3>& tri_radiance;
  const CompositeDesc& desc;
  int object_samples_per_ray;
};

PixelResult shade_pixel(const Shading& sh, int x, int y, Vec3 photo) {
  const Tracers& t = sh.t;
  const CompositeDesc& desc = sh.desc;
  const int n = desc.pixel_samples;
  const uint64_t pixel = static_cast<uint64_t>(y) * sh.cam.width + x;
  Vec3 object_sum, proxy_dir;
  int object_hits = 0;
  bool have_proxy = false;
  double proxy_t = 0;
  uint32_t proxy_tri = 0;
  for (int k = 0; k < n * n; ++k) {
    const int ray = (k + (n * n) / 2) % (n * n);  // the centre-most ray first (proxy lookups prefer it)
    Vec3 d = sh.cam.ray_direction(x + (ray % n + 0.5) / n, y + (ray / n + 0.5) / n);
    geometry::Hit h = t.both_rt.intersect(sh.cam.eye, d);
    if (!h.hit) continue;
    if (h.mesh == 1) {
      Vec3 normal = t.object->normal(h.triangle);
      if (dot(normal, d) > 0) normal = -normal;
      Vec3 z = sh.cam.eye + d * h.t;
      Rng rng(stream_key(desc.seed, kStreamObject, pixel * 64 + static_cast<uint64_t>(ray)));
      const Vec3 rho = object_albedo(*t.object, sh.material, h.triangle, h.b1, h.b2);
      object_sum +=
          object_radiance(t, z + normal * kRayEpsilon, normal, -d, rho, sh.material, sh.object_samples_per_ray, rng);
      if (desc.self_light)  // the object's own light on it: one bounce, its triangles' direct radiance
        object_sum += rho *
                      self_irradiance(t, sh.tri_radiance, z + normal * kRayEpsilon, normal,
                                      std::max(16, sh.object_samples_per_ray / 4), rng) /
                      kPi;
      ++object_hits;
    } else if (!have_proxy) {
      have_proxy = true;
      proxy_dir = d;
      proxy_t = h.t;
      proxy_tri = h.triangle;
    }
  }
  PixelResult r;
  r.composite = photo;
  r.proxy = have_proxy;
  if (have_proxy && desc.shadows) {
    Vec3 normal = t.proxy.normal(proxy_tri);
    if (dot(normal, proxy_dir) > 0) normal = -normal;
    const Vec3 at = sh.cam.eye + proxy_dir * proxy_t + normal * kRayEpsilon;
    Rng rng(stream_key(desc.seed, kStreamProxy, pixel));
    const ProxyTerms terms = proxy_terms(t, &sh.tri_radiance, at, normal, desc.light_samples, desc.bounce_samples, rng);
    const Vec3 dE = terms.bounce - terms.blocked;
    const ProxyAlbedo albedo = proxy_albedo(photo, terms.e0);
    r.rho = albedo.rho;
    for (int c = 0; c < 3; ++c)  // a reflectance > 1 changes no more than 1 would
      if (terms.e0[c] > kUnlitIrradiance)
        r.composite[c] = std::max(0.0, photo[c] + std::min(r.rho[c], 1.0) * dE[c] / kPi);
    r.unlit = !albedo.lit;
    r.over_one = albedo.over_one;
    r.changed = dE.x != 0 || dE.y != 0 || dE.z != 0;
    r.without = r.rho * terms.e0 / kPi;
    r.with = r.rho * (terms.e0 + dE) / kPi;
    for (int c = 0; c < 3; ++c) r.with[c] = std::max(0.0, r.with[c]);
  }
  r.coverage = static_cast<double>(object_hits) / (n * n);
  if (object_hits > 0) {
    const Vec3 object_radiance_mean = object_sum / object_hits;
    r.composite = r.composite * (1 - r.coverage) + object_radiance_mean * r.coverage;
    r.with = r.with * (1 - r.coverage) + object_radiance_mean * r.coverage;
  }
  return r;
}

// The object's radiance per triangle (its light on the proxy).
std::vector<Vec3> triangle_radiance(const Tracers& t, const render::Material& material, const CompositeDesc& desc) {
  const geometry::TriMesh& object = *t.object;
  std::vector<Vec3> radiance(object.triangle_count());
  if (desc.bounce_samples == 0 && !desc.self_light) return radiance;
  parallel_for(
      0, static_cast<int64_t>(object.triangle_count()),
      [&](int64_t ti) {
        const auto& tri = object.triangles[static_cast<size_t>(ti)];
        const Vec3 normal = object.normal(static_cast<size_t>(ti));
        const Vec3 centre = (object.positions[tri[0]] + object.positions[tri[1]] + object.positions[tri[2]]) / 3.0;
        Rng rng(stream_key(desc.seed, kStreamTriangle, static_cast<uint64_t>(ti)));
        radiance[static_cast<size_t>(ti)] =
            object_albedo(object, material, static_cast<uint32_t>(ti), 1.0 / 3, 1.0 / 3) *
            irradiance(t, t.both_rt, centre + normal * kRayEpsilon, normal, desc.triangle_samples, rng, true) / kPi;
      },
      256);
  return radiance;
}

void check_inputs(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                  const geometry::TriMesh& object, const render::Material& material, const CompositeDesc& desc) {
  const int n = desc.pixel_samples;
  if (photo.channels() < 3)
    fail(ErrorKind::Value, "the photograph has {} channels; an RGB image is needed", photo.channels());
  if (photo.width() != cam.width || photo.height() != cam.height)
    fail(ErrorKind::Value, "the photograph is {}x{} but the camera's frame is {}x{}", photo.width(), photo.height(),
         cam.width, cam.height);
  if (n < 1 || n > 8) fail(ErrorKind::Value, "pixel_samples {} must lie in 1..8", n);
  if (desc.light_samples < 1 || desc.object_samples < 1 || desc.triangle_samples < 1 || desc.bounce_samples < 0)
    fail(ErrorKind::Value, "sample counts must be ≥ 1 (bounce samples ≥ 0)");
  if (proxy.triangle_count() == 0) fail(ErrorKind::Value, "the proxy has no triangles");
  if (object.triangle_count() == 0) fail(ErrorKind::Value, "the object has no triangles");
  render::check_material(material);
}

}  // namespace

CompositeResult composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                          const LocalRadiance& light, const geometry::TriMesh& object, const render::Material& material,
                          const CompositeDesc& desc) {
  auto t0 = std::chrono::steady_clock::now();
  check_inputs(photo, cam, proxy, object, material, desc);
  const int W = photo.width(), H = photo.height(), n = desc.pixel_samples;
  Tracers t(proxy, &object);
  if (desc.check_geometry) check_geometry(t, cam);
  LightField field(light, proxy, t.proxy_rt);
  t.light = &field;
  if (desc.shadows) shadow_patches(t, field, desc.light_samples, desc.bounce_samples, desc.seed);
  const std::vector<Vec3> tri_radiance = triangle_radiance(t, material, desc);
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
  const Shading sh{t, cam, material, tri_radiance, desc, std::max(1, desc.object_samples / (n * n))};
  parallel_for(0, H, [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < W; ++x) {
      const Vec3 photo_rgb = photo.rgb(x, y);
      const PixelResult p = shade_pixel(sh, x, y, photo_rgb);
      proxy_px += p.proxy;
      object_px += p.coverage > 0;
      changed += p.changed;
      over += p.over_one;
      unlit += p.unlit;
      r.composite.set_rgb(x, y, p.composite);
      r.mask.at(x, y, 0) = static_cast<float>(p.coverage);
      r.difference.set_rgb(x, y, p.composite - photo_rgb);
      r.albedo.set_rgb(x, y, p.rho);
      r.render_without.set_rgb(x, y, p.without);
      r.render_with.set_rgb(x, y, p.with);
    }
    report(desc.progress, "composite", static_cast<double>(++rows) / H);
  });
  r.stats = {proxy_px, object_px, changed,
             over,     unlit,     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()};
  r.warnings = albedo_warnings(r.stats.proxy_pixels, r.stats.albedo_over_one, r.stats.unlit);
  if (r.stats.object_pixels == 0)
    r.warnings.push_back("no pixel of the photograph sees the object: check at, the eye and the target");
  return r;
}

}  // namespace ibl::augment
