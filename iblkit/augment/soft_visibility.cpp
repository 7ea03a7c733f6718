#include "iblkit/augment/soft_visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "iblkit/augment/proxy_light.h"
#include "iblkit/augment/split_light.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::augment {

namespace {
constexpr double kMaxSoftFactor = 16;  // the clamp of f (soft_visibility.h)
constexpr int kMaxPoolRings = 3;
}  // namespace

std::vector<Vec3> soft_visibility(const LocalRadiance& light, const geometry::TriMesh& proxy,
                                  const geometry::TriMesh& object, const SoftVisibilityDesc& desc) {
  if (desc.samples < 1 || desc.samples > 65536)
    fail(ErrorKind::Value, "soft visibility samples {} must lie in 1..65536", desc.samples);
  if (desc.shadow_samples < 1 || desc.shadow_cone < 0)
    fail(ErrorKind::Value, "shadow samples must be ≥ 1 (cone samples ≥ 0)");
  if (!(desc.threshold >= 0) || !std::isfinite(desc.threshold))
    fail(ErrorKind::Value, "soft threshold {} must be ≥ 0", desc.threshold);
  if (proxy.triangle_count() == 0) fail(ErrorKind::Value, "the proxy has no triangles");
  if (object.triangle_count() == 0) fail(ErrorKind::Value, "the object has no triangles");
  Tracers s(proxy, &object);
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
        Rng rng(stream_key(desc.seed, kStreamVisibility, static_cast<uint64_t>(ti)));
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
