#include "iblkit/lab/view.h"

#include <atomic>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/core/rng.h"
#include "iblkit/lab/radiance.h"

namespace ibl::lab {

View photograph(const Scene& scene, const PixelRayFn& ray, const ViewDesc& desc, const ProgressFn& progress) {
  if (!scene.built()) fail(ErrorKind::Internal, "lab::photograph needs a built scene");
  const int W = desc.width, H = desc.height, n = desc.samples;
  if (W < 1 || H < 1 || W > 16384 || H > 16384) fail(ErrorKind::Value, "view size {}x{} is invalid", W, H);
  if (n < 1 || n > 64) fail(ErrorKind::Value, "samples per pixel axis {} must be in 1..64", n);
  View v{Image(W, H, 3), Image(W, H, 1, -1.0f)};
  std::atomic<int> rows_done{0};
  parallel_for(0, H, [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < W; ++x) {
      const uint64_t pixel = static_cast<uint64_t>(y) * W + x;
      Vec3 sum;
      for (int s = 0; s < n * n; ++s) {
        Vec3 o, d;
        ray(x + (s % n + 0.5) / n, y + (s / n + 0.5) / n, &o, &d);
        Rng rng(stream_key(desc.render.seed, 0x76696577 /* "view" */, pixel, s));
        sum += radiance(scene, o, d, rng, desc.render);
      }
      v.radiance.set_rgb(x, y, sum / (n * n));
      Vec3 o, d;
      ray(x + 0.5, y + 0.5, &o, &d);
      geometry::Hit h = scene.tracer().intersect(o, d);
      if (h.hit) v.surface.at(x, y, 0) = static_cast<float>(h.mesh);
    }
    report(progress, "photograph", static_cast<double>(++rows_done) / H);
  });
  return v;
}

int add_object(Scene& scene, const std::string& name, geometry::TriMesh mesh, Vec3 albedo) {
  if (scene.built()) fail(ErrorKind::Internal, "lab::add_object: add objects before Scene::build");
  Surface s;
  s.name = name;
  s.mesh = std::move(mesh);
  s.albedo.constant = albedo;
  s.proxy = false;
  scene.surfaces.push_back(std::move(s));
  return static_cast<int>(scene.surfaces.size()) - 1;
}

}  // namespace ibl::lab
