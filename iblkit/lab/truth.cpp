#include "iblkit/lab/truth.h"

#include <algorithm>
#include <atomic>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/core/rng.h"
#include "iblkit/lab/capture.h"
#include "iblkit/lab/radiance.h"
#include "iblkit/sh/project.h"

namespace ibl::lab {

namespace {
// Per-row partial sums in a fixed order keep the result independent of scheduling.
template <typename RowF>
std::vector<Vec3> row_sums(const sphere::EnvMap& map, size_t k, RowF row) {
  int H = map.image.height();
  std::vector<std::vector<Vec3>> rows(H, std::vector<Vec3>(k));
  parallel_for(0, H, [&](int64_t y) { row(static_cast<int>(y), rows[y]); });
  std::vector<Vec3> total(k);
  for (auto& r : rows)
    for (size_t i = 0; i < k; ++i) total[i] += r[i];
  return total;
}
}  // namespace

Vec3 irradiance(const sphere::EnvMap& map, Vec3 n) {
  n = normalize(n);
  return row_sums(map, 1, [&](int y, std::vector<Vec3>& acc) {
    for (int x = 0; x < map.image.width(); ++x) {
      Vec3 d;
      double sa = map.mapping.solid_angle(x, y);
      if (sa <= 0 || !map.mapping.to_direction(x + 0.5, y + 0.5, &d)) continue;
      double c = dot(n, d);
      if (c > 0) acc[0] += map.image.rgb(x, y) * (c * sa);
    }
  })[0];
}

Truth ground_truth(const Scene& scene, Vec3 position, const TruthDesc& desc, const ProgressFn& progress) {
  require_point("ground-truth position", position);
  if (desc.area_samples < 1) fail(ErrorKind::Value, "area samples {} must be ≥ 1", desc.area_samples);
  CaptureDesc cd;
  cd.mapping = sphere::MappingKind::LatLong;
  cd.size = desc.size;
  cd.samples = desc.samples;
  cd.render = scene.render;
  cd.render.area_samples = desc.area_samples;
  cd.render.env_samples = std::max(scene.render.env_samples, desc.area_samples);
  cd.render.seed = desc.seed;
  Capture cap = capture_probe(scene, position, cd, 0, progress);
  Truth t;
  t.radiance = sphere::EnvMap(std::move(cap.radiance), cap.mapping);
  if (desc.bands > 0) t.sh = sh::project(t.radiance, desc.bands);
  if (desc.bands > 0 && desc.blind_cone_deg > 0) {
    // The same map rendered only inside the cone (the same random streams, so the same values
    // there, at a fraction of the cost), subtracted: the map without the cone, sub-sample exact.
    if (!(desc.blind_cone_deg < 180))
      fail(ErrorKind::Value, "blind cone {}° must lie in (0, 180)", desc.blind_cone_deg);
    cd.cone = CaptureDesc::Cone::Inside;
    cd.cone_deg = desc.blind_cone_deg;
    if (length(desc.blind_axis) == 0) fail(ErrorKind::Value, "blind cone axis (0,0,0) has no direction");
    cd.cone_axis = normalize(desc.blind_axis);
    Capture inside = capture_probe(scene, position, cd, 0);
    sphere::EnvMap vis = t.radiance;
    for (size_t i = 0; i < vis.image.size(); ++i)
      vis.image.data()[i] = std::max(0.0f, vis.image.data()[i] - inside.radiance.data()[i]);
    t.sh_visible = sh::project(vis, desc.bands);
  }
  for (Vec3 n : desc.normals) {
    if (length(n) == 0) fail(ErrorKind::Value, "irradiance normal (0,0,0) has no direction");
    t.normals.push_back(normalize(n));
    t.irradiance.push_back(irradiance(t.radiance, n));
  }
  return t;
}

std::vector<Vec3> radiance_along(const Scene& scene, Vec3 position, const std::vector<Vec3>& directions,
                                 const RenderDesc& desc, int streams) {
  if (streams < 1) fail(ErrorKind::Value, "radiance along rays: {} random streams per ray (need ≥ 1)", streams);
  require_point("radiance position", position);
  std::vector<Vec3> out(directions.size());
  parallel_for(
      0, static_cast<int64_t>(directions.size()),
      [&](int64_t i) {
        Vec3 s;
        for (int k = 0; k < streams; ++k) {
          Rng rng(stream_key(desc.seed, 7, static_cast<uint64_t>(i), k));
          s += radiance(scene, position, directions[static_cast<size_t>(i)], rng, desc);
        }
        out[static_cast<size_t>(i)] = s / streams;
      },
      64);
  return out;
}

}  // namespace ibl::lab
