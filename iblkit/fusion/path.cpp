#include "iblkit/fusion/path.h"

#include <chrono>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"

namespace ibl::fusion {

PathResult fuse_path(const ProbeSet& set, const std::vector<PathPoint>& path, const PathDesc& desc,
                     const PathFrameFn& on_frame) {
  if (path.empty()) fail(ErrorKind::Value, "fuse_path: the path has no points");
  if (desc.fuse.mapping != sphere::MappingKind::LatLong)
    fail(ErrorKind::Value, "fuse_path: the maps must be lat-long (the lights are cut from them), not {}",
         sphere::mapping_name(desc.fuse.mapping));
  if (desc.lights < 1) fail(ErrorKind::Value, "fuse_path: lights = {} must be at least 1", desc.lights);
  for (size_t k = 0; k < path.size(); ++k) {
    require_point(fmt::format("fuse_path: point {}", k + 1), path[k].position);
    if (!std::isfinite(path[k].time))
      fail(ErrorKind::Value, "fuse_path: point {} has time {}, not a finite number", k + 1, path[k].time);
  }
  FuseDesc fd = desc.fuse;
  fd.progress = {};
  LightTracker raw_tr({false, desc.track.time_constant}), filt_tr(desc.track);
  std::vector<lights::LightSet> raw_sets, filt_sets;
  std::vector<std::vector<int>> raw_ids, filt_ids;
  std::vector<sphere::EnvMap> maps;
  auto t0 = std::chrono::steady_clock::now();
  for (size_t k = 0; k < path.size(); ++k) {
    LocalMap m = fuse(set, path[k].position, fd);
    auto cut = localize_lights(m, {desc.lights});
    double dt = k == 0 ? 0.0 : path[k].time - path[k - 1].time;
    raw_sets.push_back(raw_tr.update(cut, dt));
    raw_ids.push_back(raw_tr.ids());
    filt_sets.push_back(filt_tr.update(cut, dt));
    filt_ids.push_back(filt_tr.ids());
    maps.push_back(m.radiance);
    if (on_frame) on_frame({k, path[k], m, cut, raw_sets.back(), filt_sets.back(), raw_ids.back(), filt_ids.back()});
    report(desc.progress, "path", static_cast<double>(k + 1) / path.size());
  }
  PathResult r;
  r.frames = path.size();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.map_flicker = map_flicker(maps);
  r.raw_flicker = light_flicker(raw_sets);
  r.filtered_flicker = light_flicker(filt_sets);
  r.raw_vs_maps = lights_vs_maps(raw_sets, maps);
  r.filtered_vs_maps = lights_vs_maps(filt_sets, maps);
  r.raw_excess = excess_flicker(raw_sets, maps);
  r.filtered_excess = excess_flicker(filt_sets, maps);
  r.raw_jitter = shadow_light_jitter(raw_sets, raw_ids, desc.shadow_lights);
  r.filtered_jitter = shadow_light_jitter(filt_sets, filt_ids, desc.shadow_lights);
  return r;
}

}  // namespace ibl::fusion
