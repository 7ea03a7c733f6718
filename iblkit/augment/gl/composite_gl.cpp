#include "iblkit/augment/gl/compositor.h"
#include "iblkit/augment/soft_visibility.h"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "iblkit/augment/albedo.h"
#include "iblkit/augment/proxy_light.h"
#include "iblkit/augment/run_composite.h"
#include "iblkit/core/error.h"
#include "iblkit/render/gl/context.h"

// composite(): the compositor with its CPU inputs (the albedo estimate, the light split, the object's soft
// light share), in a file of its
// own so that the lean GL benchmark (bench/gl_frames_main.cpp, no Embree) builds compositor.cpp alone.
namespace ibl::augment::gl {

CompositeResult composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                          const LocalRadiance& light, const geometry::TriMesh& object, const render::Material& material,
                          const CompositeDesc& desc, GlFrameTiming* timing) {
  auto t0 = std::chrono::steady_clock::now();
  if (desc.gl.visibility_samples < -1 || desc.gl.visibility_samples > 65536)
    fail(ErrorKind::Value, "visibility samples {} must lie in 0..65536 (or -1: automatic)", desc.gl.visibility_samples);
  render::gl::Context context;
  AlbedoEstimate est = estimate_albedo(photo, cam, proxy, light, desc.light_samples, desc.seed);
  SplitDesc sd = desc.gl.split;
  sd.lights = std::min(sd.lights, Compositor::kMaxLights);
  SplitLight split = split_light(light, proxy, sd);
  CompositeResult r;
  {
    Compositor comp(photo, cam, proxy, split, est.albedo, desc);
    std::vector<Vec3> vis;
    // The noise a pixel shows depends on the rays per unit of the object's area: a fixed budget over the triangles.
    const int samples =
        desc.gl.visibility_samples >= 0
            ? desc.gl.visibility_samples
            : static_cast<int>(std::clamp<int64_t>(
                  GlOptions::kVisibilityRays / std::max<int64_t>(object.triangle_count(), 1), 16, 1024));
    if (samples > 0) {
      SoftVisibilityDesc vd;
      vd.samples = samples;
      vd.threshold = sd.lights > 0 ? sd.threshold : 0;
      vd.seed = desc.seed;
      vis = soft_visibility(light, proxy, object, vd);
    }
    comp.set_object(object, material, vis.empty() ? nullptr : &vis);
    comp.draw({}, false, timing);
    Image proxy_comp;
    comp.read_back(&r.composite, &r.mask, &r.difference, &proxy_comp);
    const int W = photo.width(), H = photo.height();
    r.albedo = est.albedo;
    r.render_without = Image(W, H, 3);
    r.render_with = Image(W, H, 3);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        Vec3 rho = est.albedo.rgb(x, y), ph = photo.rgb(x, y), without;
        for (int c = 0; c < 3; ++c)
          without[c] = rho[c] > 0 ? ph[c] * std::min(rho[c], 1.0) / rho[c] : 0.0;  // min(ρ,1)/π E₀
        Vec3 with = without + (proxy_comp.rgb(x, y) - ph);
        for (int c = 0; c < 3; ++c) with[c] = std::max(0.0, with[c]);
        double f = r.mask.at(x, y, 0);
        r.render_without.set_rgb(x, y, without);
        r.render_with.set_rgb(x, y, with * (1 - f) + (r.composite.rgb(x, y) - proxy_comp.rgb(x, y) * (1 - f)));
        if (f > 0) ++r.stats.object_pixels;
        Vec3 d = proxy_comp.rgb(x, y) - ph;
        if (d.x != 0 || d.y != 0 || d.z != 0) ++r.stats.changed_pixels;
      }
  }
  r.stats.proxy_pixels = est.proxy_pixels;
  r.stats.albedo_over_one = est.over_one;
  r.stats.unlit = est.unlit;
  r.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.warnings = albedo_warnings(est.proxy_pixels, est.over_one, est.unlit);
  if (r.stats.object_pixels == 0)
    r.warnings.push_back("no pixel of the photograph sees the object: check at, the eye and the target");
  return r;
}

}  // namespace ibl::augment::gl

namespace ibl::augment {

bool gl_backend_available(std::string* why) { return render::gl::available(why); }

CompositeResult gl_backend_composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                                     const LocalRadiance& light, const geometry::TriMesh& object,
                                     const render::Material& material, const CompositeDesc& desc) {
  return gl::composite(photo, cam, proxy, light, object, material, desc);
}

}  // namespace ibl::augment
