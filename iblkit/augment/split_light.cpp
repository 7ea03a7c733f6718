#include "iblkit/augment/split_light.h"

#include <algorithm>
#include <cmath>

#include "iblkit/augment/rays.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/geometry/raytracer.h"
#include "iblkit/lights/cut.h"
#include "iblkit/lights/place.h"

namespace ibl::augment {

namespace {
// E(n) = ∫ L max(0, n·ω) dω on a lat-long of 2·size × size normals, summed over the soft texels (`soft`) of the grid
// gathered into at most 128 × 64 cells: each cell keeps the exact Σ L dω of its texels (a lamp's power stays whole)
// at their solid-angle-weighted mean direction. No band limit: 3 SH bands misstate the side facing away from a
// bright wall or window by several per cent.
Image cosine_convolution(int W, int H, const lights::LatLongGrid& grid, const std::vector<char>& soft, int size) {
  const int Wc = std::min(W, 128), Hc = std::min(H, 64);
  std::vector<Vec3> power(static_cast<size_t>(Wc) * Hc), dir(power.size());
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      const size_t c = static_cast<size_t>(y * Hc / H) * Wc + x * Wc / W;
      const double dw = grid.row_solid_angle[y];
      dir[c] += grid.direction(x + 0.5, y + 0.5) * dw;
      if (soft[i]) power[c] += grid.rgb[i] * dw;
    }
  for (Vec3& d : dir) d = length(d) > 0 ? normalize(d) : Vec3{0, 1, 0};
  Image out(2 * size, size, 3);
  const sphere::Mapping m(sphere::MappingKind::LatLong, 2 * size, size);
  parallel_for(0, size, [&](int64_t y) {
    for (int x = 0; x < 2 * size; ++x) {
      Vec3 n, e;
      m.to_direction(x + 0.5, static_cast<double>(y) + 0.5, &n);
      for (size_t c = 0; c < power.size(); ++c) e += power[c] * std::max(0.0, dot(n, dir[c]));
      out.set_rgb(x, static_cast<int>(y), Vec3{std::max(0.0, e.x), std::max(0.0, e.y), std::max(0.0, e.z)});
    }
  });
  return out;
}

}  // namespace

SplitLight split_light(const LocalRadiance& light, const geometry::TriMesh& proxy, const SplitDesc& desc) {
  if (desc.lights < 0 || desc.lights > 256) fail(ErrorKind::Value, "hard lights {} must lie in 0..256", desc.lights);
  if (!(desc.threshold >= 0) || !std::isfinite(desc.threshold))
    fail(ErrorKind::Value, "hard-light threshold {} must be ≥ 0", desc.threshold);
  if (desc.irradiance_size < 4 || desc.irradiance_size > 1024)
    fail(ErrorKind::Value, "irradiance map size {} must lie in 4..1024", desc.irradiance_size);
  lights::LatLongGrid grid = lights::to_latlong_grid(light.map);
  const int W = grid.width, H = grid.height;
  double total = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      total += split_measure(grid.rgb[static_cast<size_t>(y) * W + x]) * grid.row_solid_angle[y];
  if (!(total > 0)) fail(ErrorKind::Value, "the {} light has no positive radiance", light.source);
  const double limit = desc.threshold * total / (4 * kPi);
  SplitLight s;
  s.centre = light.centre;
  s.soft = Image(W, H, 3);
  lights::LatLongGrid hard = grid;
  std::vector<char> soft_texel(grid.rgb.size(), 1);
  int hard_texels = 0;
  double hard_power = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      size_t i = static_cast<size_t>(y) * W + x;
      bool is_hard = desc.lights > 0 && desc.threshold > 0 && split_measure(grid.rgb[i]) > limit;
      if (is_hard) {
        soft_texel[i] = 0;
        ++hard_texels;
        hard_power += split_measure(grid.rgb[i]) * grid.row_solid_angle[y];
      } else {
        hard.rgb[i] = {};
        s.soft.set_rgb(x, y, grid.rgb[i]);
      }
    }
  s.hard_share = hard_power / total;
  if (hard_texels > 0) {
    lights::CutDesc cd;
    cd.count = std::min(desc.lights, hard_texels);
    s.hard = lights::median_cut(hard, cd);
    for (auto& l : s.hard.lights) l.direction = normalize(l.direction);
    geometry::RayTracer rt;
    rt.add(proxy);
    rt.commit();
    // A texel's depth: where the probe's depth map says a lamp hangs in front of the proxy, else where the
    // texel's ray from the centre meets the proxy (∞: it leaves the proxy).
    const bool have_depth = !light.depth.empty() && light.depth.width() == W && light.depth.height() == H;
    lights::place_by_depth(s.hard, hard, light.centre, [&](int x, int y) {
      const Vec3 d = grid.direction(x + 0.5, y + 0.5);
      const geometry::Hit hit = rt.intersect(light.centre, d, 1e-6);
      double dist = hit.hit ? hit.t : std::numeric_limits<double>::infinity();
      if (have_depth) {
        const double t = light.depth.at(x, y, 0);
        if (t > 0 && std::isfinite(t) && t < kDepthInFront * dist) dist = t;
      }
      return dist;
    });
  }
  s.hard.origin = light.centre;
  s.soft_irradiance = cosine_convolution(grid.width, grid.height, grid, soft_texel, desc.irradiance_size);
  return s;
}

}  // namespace ibl::augment
