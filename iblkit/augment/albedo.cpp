#include "iblkit/augment/albedo.h"

#include <atomic>
#include <limits>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/geometry/raytracer.h"

namespace ibl::augment {

namespace {
constexpr double kRayEpsilon = 1e-4, kShadowShorten = 1e-3, kUnlit = 1e-9;  // as composite.cpp
uint64_t mix(uint64_t z) {                                                  // SplitMix64 (Steele, Lea & Flood 2014)
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
}  // namespace

AlbedoEstimate estimate_albedo(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                               const LocalLight& light, int samples, uint64_t seed) {
  if (photo.channels() < 3)
    fail(ErrorKind::Value, "the photograph has {} channels; an RGB image is needed", photo.channels());
  if (photo.width() != cam.width || photo.height() != cam.height)
    fail(ErrorKind::Value, "the photograph is {}x{} but the camera's frame is {}x{}", photo.width(), photo.height(),
         cam.width, cam.height);
  if (samples < 1 || samples > 65536) fail(ErrorKind::Value, "albedo samples {} must lie in 1..65536", samples);
  if (proxy.triangle_count() == 0) fail(ErrorKind::Value, "the proxy has no triangles");
  geometry::RayTracer rt;
  rt.add(proxy);
  rt.commit();
  LightField field(light, proxy, rt);
  AlbedoEstimate r;
  r.albedo = Image(photo.width(), photo.height(), 3);
  std::atomic<int64_t> proxy_px{0}, over{0}, unlit{0};
  parallel_for(0, photo.height(), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < photo.width(); ++x) {
      Vec3 d = cam.pixel_direction(x, y);
      geometry::Hit h = rt.intersect(cam.eye, d);
      if (!h.hit) continue;
      ++proxy_px;
      Vec3 n = proxy.normal(h.triangle);
      if (dot(n, d) > 0) n = -n;
      Vec3 p = cam.eye + d * h.t + n * kRayEpsilon, e;
      uint64_t s = mix(mix(mix(seed) ^ 0x616c62 /* "alb" */) ^ (static_cast<uint64_t>(y) * photo.width() + x));
      const int table = field.table_for(n);  // as composite.cpp: the table for the pixel's side of the proxy
      for (int k = 0; k < samples; ++k) {
        s += 0x9e3779b97f4a7c15ull;
        double u = (k + static_cast<double>(mix(s) >> 11) * 0x1.0p-53) / samples, pmf, dist;
        size_t i = field.sample(u, &pmf, table);
        Vec3 w, c = field.contribution(i, p, n, &w, &dist);
        double tfar =
            std::isinf(dist) ? std::numeric_limits<double>::infinity() : dist * (1 - kShadowShorten) - kRayEpsilon;
        if (max_component(c) <= 0 || rt.occluded(p, w, kRayEpsilon, tfar)) continue;
        e += c / pmf;
      }
      e = e / samples;
      Vec3 ph = photo.rgb(x, y), rho;
      bool bad = false, lit = true;
      for (int c = 0; c < 3; ++c) {
        if (e[c] > kUnlit) {
          rho[c] = kPi * ph[c] / e[c];
          bad = bad || rho[c] > 1;
        } else {
          lit = false;
        }
      }
      if (bad) ++over;
      if (!lit) ++unlit;
      r.albedo.set_rgb(x, y, rho);
    }
  });
  r.proxy_pixels = proxy_px;
  r.over_one = over;
  r.unlit = unlit;
  return r;
}

}  // namespace ibl::augment
