#include "iblkit/lights/place.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "iblkit/core/error.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::lights {

void place_by_depth(LightSet& set, const LatLongGrid& grid, Vec3 origin, const std::function<double(int, int)>& depth) {
  const size_t n = set.lights.size();
  if (n > 0 && (set.regions.width != grid.width || set.regions.height != grid.height))
    fail(ErrorKind::Internal, "place_by_depth: the light set's regions ({}x{}) are not the grid's ({}x{})",
         set.regions.width, set.regions.height, grid.width, grid.height);
  std::vector<double> e_all(n, 0), e_hit(n, 0);
  std::vector<std::vector<std::pair<double, double>>> depths(n);  // (depth, energy) of the pixels that see near
  for (int y = 0; y < grid.height; ++y)
    for (int x = 0; x < grid.width; ++x) {
      const int label = set.regions.at(x, y);
      if (label < 0) continue;
      const double e = luminance(grid.rgb[static_cast<size_t>(y) * grid.width + x]) * grid.row_solid_angle[y];
      if (!(e > 0)) continue;
      const size_t i = static_cast<size_t>(label);
      e_all[i] += e;
      const double t = depth(x, y);
      if (t > 0 && std::isfinite(t)) {
        e_hit[i] += e;
        depths[i].push_back({t, e});
      }
    }
  const sphere::Mapping latlong(sphere::MappingKind::LatLong, grid.width, grid.height);
  for (size_t i = 0; i < n; ++i) {
    if (!(e_hit[i] > 0) || e_hit[i] < 0.5 * e_all[i]) continue;
    auto& d = depths[i];
    std::sort(d.begin(), d.end());
    double acc = 0, t = d.back().first;
    for (const auto& [dist, e] : d)
      if ((acc += e) >= 0.5 * e_hit[i]) {
        t = dist;
        break;
      }
    // Never beyond what the light's own direction sees.
    const Vec3 dir = set.lights[i].direction;
    double px, py;
    if (latlong.to_pixel(dir, &px, &py)) {
      const int x = std::clamp(static_cast<int>(px), 0, grid.width - 1),
                y = std::clamp(static_cast<int>(py), 0, grid.height - 1);
      const double along = depth(x, y);
      if (along > 0 && std::isfinite(along)) t = std::min(t, along);
    }
    set.lights[i].position = origin + dir * t;
  }
  set.origin = origin;
}

}  // namespace ibl::lights
