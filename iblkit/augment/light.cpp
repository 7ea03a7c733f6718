#include "iblkit/augment/light.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/fusion/fuse.h"
#include "iblkit/lights/cut.h"
#include "iblkit/sh/convolve.h"

namespace ibl::augment {

namespace {

constexpr double kMinCosCentre = 0.05;  // grazing texels: their patch area stops growing at 1/0.05 (≈ 87°)
constexpr double kPowerShare = 0.8;     // sampling: this share by power, the rest by solid angle (no fireflies
                                        // from dim but near patches)
// A patch's power is its mean RGB radiance × solid angle (not luminance: a red lamp is as much a light as a white one).
double power_of(Vec3 L) { return (std::max(0.0, L.x) + std::max(0.0, L.y) + std::max(0.0, L.z)) / 3; }
constexpr double kDepthInFront = 0.98;  // a depth this much shorter than the proxy's hit is a free emitter (a lamp)

}  // namespace

LocalLight light_from_grid(const ilf::SHGrid& grid, Vec3 at, int size) {
  if (size < 4 || size > 4096) fail(ErrorKind::Value, "light map size {} must lie in 4..4096", size);
  LocalLight l;
  l.map = sphere::EnvMap(Image(2 * size, size, 3), sphere::Mapping(sphere::MappingKind::LatLong, 2 * size, size));
  l.centre = at;
  // A radiance map from band-limited coefficients rings: a bright lamp's few bands swing negative around it.
  // Light is never negative; evaluated as they are and clamped, the rings lit the object from every side
  // (docs/augment.md: low-scene2's object error 48 %). So the
  // coefficients are Hanning-windowed first (smaller rings, sh::apply_window), the rest is clamped, and the map
  // is scaled per channel back to the grid's own power (its DC term: ∫L dω = √(4π)·c₀₀, which the window keeps).
  sh::WindowDesc wd;
  wd.kind = sh::Window::Hanning;
  const sh::Coeffs c = sh::apply_window(grid.coeffs_at(at), wd);
  std::vector<Vec3> row_sum(static_cast<size_t>(size));
  parallel_for(0, size, [&](int64_t y) {
    for (int x = 0; x < 2 * size; ++x) {
      Vec3 d;
      l.map.mapping.to_direction(x + 0.5, y + 0.5, &d);
      Vec3 L = c.evaluate(d);
      L = {std::max(0.0, L.x), std::max(0.0, L.y), std::max(0.0, L.z)};
      l.map.image.set_rgb(x, static_cast<int>(y), L);
      row_sum[static_cast<size_t>(y)] += L * l.map.mapping.solid_angle(x, static_cast<int>(y));
    }
  });
  Vec3 clamped;
  for (const Vec3& r : row_sum) clamped += r;
  const Vec3 power = c.c[0] * std::sqrt(4 * kPi);
  Vec3 scale{1, 1, 1};
  for (int k = 0; k < 3; ++k) scale[k] = clamped[k] > 0 && power[k] > 0 ? power[k] / clamped[k] : 1.0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < 2 * size; ++x) l.map.image.set_rgb(x, y, l.map.image.rgb(x, y) * scale);
  l.source = fmt::format("SH grid (Hanning-windowed, rings clamped: power x{:.2f}, scaled back)", luminance(clamped) / std::max(luminance(power), 1e-300));
  return l;
}

LocalLight light_from_probes(const fusion::ProbeSet& set, Vec3 at, int size) {
  fusion::FuseDesc d;
  d.size = size;
  fusion::LocalMap m = fusion::fuse(set, at, d);
  LocalLight l;
  l.map = std::move(m.radiance);
  l.centre = at;
  l.source = "fused probes";
  return l;
}

LocalLight as_median_cut(const LocalLight& light, int count) {
  if (light.map.mapping.kind() != sphere::MappingKind::LatLong) fail(ErrorKind::Value, "median-cut baseline: the {} map is not lat-long", light.source);
  lights::CutDesc cd;
  cd.count = count;
  lights::LightSet set = lights::median_cut(light.map, cd);
  LocalLight out = light;
  out.source = fmt::format("{} as {} median-cut lights", light.source, set.lights.size());
  const int W = light.map.image.width(), H = light.map.image.height();
  out.map.image = Image(W, H, 3);
  if (!light.depth.empty()) out.depth = Image(W, H, 1);
  for (const auto& l : set.lights) {
    double px, py;
    if (!light.map.mapping.to_pixel(l.direction, &px, &py)) continue;
    int x = std::clamp(static_cast<int>(px), 0, W - 1), y = std::clamp(static_cast<int>(py), 0, H - 1);
    double sa = light.map.mapping.solid_angle(x, y);
    out.map.image.set_rgb(x, y, out.map.image.rgb(x, y) + l.irradiance / sa);
    if (!light.depth.empty()) out.depth.at(x, y, 0) = light.depth.at(x, y, 0);
  }
  return out;
}

LightField::LightField(const LocalLight& light, const geometry::TriMesh& proxy, const geometry::RayTracer& proxy_tracer) {
  const Image& img = light.map.image;
  const sphere::Mapping& mp = light.map.mapping;
  const int W = img.width(), H = img.height();
  const bool have_depth = !light.depth.empty();
  if (have_depth && (light.depth.width() != W || light.depth.height() != H))
    fail(ErrorKind::Value, "light depth map {}x{} and radiance map {}x{} differ in size", light.depth.width(), light.depth.height(), W, H);
  std::vector<std::vector<Patch>> rows(H);
  parallel_for(0, H, [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < W; ++x) {
      Vec3 L = img.rgb(x, y), d;
      double sa = mp.solid_angle(x, y);
      if (!(max_component(L) > 0) || !(sa > 0) || !mp.to_direction(x + 0.5, y + 0.5, &d)) continue;
      Patch p;
      p.radiance = L;
      p.omega = sa;
      geometry::Hit h = proxy_tracer.intersect(light.centre, d);
      double depth = have_depth ? light.depth.at(x, y, 0) : 0;
      if (have_depth && depth > 0 && (!h.hit || depth < h.t * kDepthInFront)) {
        p.point = light.centre + d * depth;  // something in front of the proxy (a lamp): it faces the centre
        p.normal = -d;
        p.area = sa * depth * depth;
        p.lamp = true;
      } else if (h.hit) {
        p.point = light.centre + d * h.t;
        Vec3 n = proxy.normal(h.triangle);
        if (dot(n, d) > 0) n = -n;  // towards the centre
        double c = std::max(kMinCosCentre, -dot(n, d));
        p.normal = n;
        p.area = sa * h.t * h.t / c;
      } else {
        p.point = d;
        p.area = sa;
        p.distant = true;
      }
      p.texel = static_cast<long>(y) * W + x;
      rows[y].push_back(p);
    }
  });
  mapping_ = mp;
  centre_ = light.centre;
  texel_patch_.assign(static_cast<size_t>(W) * H, -1);
  for (auto& r : rows)
    for (auto& p : r) {
      texel_patch_[static_cast<size_t>(p.texel)] = static_cast<long>(patches_.size());
      patches_.push_back(p);
    }
  if (patches_.empty()) fail(ErrorKind::Value, "the {} light is black: nothing to light the scene with", light.source);
  double power = 0, solid = 0;
  for (const auto& p : patches_) {
    power += power_of(p.radiance) * p.omega;
    solid += p.omega;
  }
  total_ = power;
  if (!(power > 0)) fail(ErrorKind::Value, "the {} light has no positive radiance", light.source);
  cdf_.resize(patches_.size());
  double acc = 0;
  for (size_t i = 0; i < patches_.size(); ++i) {
    const Patch& p = patches_[i];
    acc += kPowerShare * power_of(p.radiance) * p.omega / power + (1 - kPowerShare) * p.omega / solid;
    cdf_[i] = acc;
  }
  for (auto& c : cdf_) c /= acc;
  cdf_.back() = 1.0;
}

size_t LightField::sample(double u, double* pmf) const {
  size_t i = static_cast<size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin());
  if (i >= cdf_.size()) i = cdf_.size() - 1;
  *pmf = cdf_[i] - (i > 0 ? cdf_[i - 1] : 0.0);
  return i;
}

double LightField::solid_angle_at(size_t i, Vec3 x) const {
  const Patch& p = patches_[i];
  if (p.distant) return p.area;
  Vec3 v = p.point - x;
  double r2 = dot(v, v);
  if (!(r2 > 0)) return 0;
  double cq = -dot(p.normal, v) / std::sqrt(r2);
  return cq > 0 ? p.area * cq / std::max(r2, p.area) : 0;  // as contribution()
}

long LightField::patch_along(Vec3 x, Vec3 w, const geometry::RayTracer& proxy_tracer) const {
  constexpr double kRayStart = 1e-4;    // metres, as the composite's secondary rays
  constexpr double kDepthMatch = 0.05;  // the texel's patch within 5 % of the hit's distance from the centre
  geometry::Hit h = proxy_tracer.intersect(x, w, kRayStart);
  Vec3 d = w;
  double dist = 0;
  if (h.hit) {
    d = x + w * h.t - centre_;
    dist = length(d);
    if (!(dist > 0)) return -1;
    d = d / dist;
  }
  double px, py;
  if (!mapping_.to_pixel(d, &px, &py)) return -1;
  int tx = std::clamp(static_cast<int>(px), 0, mapping_.width() - 1), ty = std::clamp(static_cast<int>(py), 0, mapping_.height() - 1);
  long i = texel_patch_[static_cast<size_t>(ty) * mapping_.width() + tx];
  if (i < 0) return -1;
  const Patch& p = patches_[static_cast<size_t>(i)];
  if (p.lamp || p.distant != !h.hit) return -1;
  if (h.hit && std::abs(length(p.point - centre_) - dist) > kDepthMatch * dist) return -1;  // hidden from the centre
  return i;
}

Vec3 LightField::contribution(size_t i, Vec3 x, Vec3 n, Vec3* w, double* dist, bool shadowed) const {
  const Patch& p = patches_[i];
  const Vec3 L = shadowed ? p.radiance * p.shadow : p.radiance;
  if (p.distant) {
    *w = p.point;
    *dist = std::numeric_limits<double>::infinity();
    double c = dot(n, p.point);
    return c > 0 ? L * (p.area * c) : Vec3{};
  }
  Vec3 v = p.point - x;
  double r2 = dot(v, v), r = std::sqrt(r2);
  if (!(r > 0)) return {};
  *w = v / r;
  *dist = r;
  double cx = dot(n, *w), cq = -dot(p.normal, *w);
  if (cx <= 0 || cq <= 0) return {};
  return L * (p.area * cq * cx / std::max(r2, p.area));  // r² ≥ A: a patch never covers more than ~π sr
}

}  // namespace ibl::augment
