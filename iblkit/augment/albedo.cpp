#include "iblkit/augment/albedo.h"

#include <atomic>

#include "iblkit/augment/proxy_light.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::augment {

AlbedoEstimate estimate_albedo(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                               const LocalRadiance& light, int samples, uint64_t seed) {
  if (photo.channels() < 3)
    fail(ErrorKind::Value, "the photograph has {} channels; an RGB image is needed", photo.channels());
  if (photo.width() != cam.width || photo.height() != cam.height)
    fail(ErrorKind::Value, "the photograph is {}x{} but the camera's frame is {}x{}", photo.width(), photo.height(),
         cam.width, cam.height);
  if (samples < 1 || samples > 65536) fail(ErrorKind::Value, "albedo samples {} must lie in 1..65536", samples);
  if (proxy.triangle_count() == 0) fail(ErrorKind::Value, "the proxy has no triangles");
  Tracers t(proxy, nullptr);
  LightField field(light, proxy, t.proxy_rt);
  t.light = &field;
  AlbedoEstimate r;
  r.albedo = Image(photo.width(), photo.height(), 3);
  std::atomic<int64_t> proxy_px{0}, over{0}, unlit{0};
  parallel_for(0, photo.height(), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < photo.width(); ++x) {
      const Vec3 d = cam.pixel_direction(x, y);
      const geometry::Hit h = t.proxy_rt.intersect(cam.eye, d);
      if (!h.hit) continue;
      ++proxy_px;
      Vec3 normal = proxy.normal(h.triangle);
      if (dot(normal, d) > 0) normal = -normal;
      const Vec3 at = cam.eye + d * h.t + normal * kRayEpsilon;
      Rng rng(stream_key(seed, kStreamAlbedo, static_cast<uint64_t>(y) * photo.width() + x));
      const ProxyTerms terms = proxy_terms(t, nullptr, at, normal, samples, 0, rng);
      const ProxyAlbedo a = proxy_albedo(photo.rgb(x, y), terms.e0);
      if (a.over_one) ++over;
      if (!a.lit) ++unlit;
      r.albedo.set_rgb(x, y, a.rho);
    }
  });
  r.proxy_pixels = proxy_px;
  r.over_one = over;
  r.unlit = unlit;
  return r;
}

}  // namespace ibl::augment
