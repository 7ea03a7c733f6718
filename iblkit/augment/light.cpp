#include "iblkit/augment/light.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "iblkit/augment/rays.h"
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
// Normal-conditioned tables (table_for): receivers within 10° of a table's normal use it; the proxy's flat parts
// are its triangles' normals clustered within that angle, the largest by area first; this many tables at most
// (both sides of each normal), and no more than kTableEntries entries in all (bounded memory for large maps).
constexpr double kTableCos = 0.98480775301220802;  // cos 10°
constexpr size_t kMaxTables = 24;
constexpr size_t kTableEntries = size_t{1} << 23;
constexpr double kConditionedShare = 0.7;  // a table's share for what its normal sees; the rest plain (never 0)

}  // namespace

LocalRadiance light_from_grid(const ilf::SHGrid& grid, Vec3 at, int size) {
  if (size < 4 || size > 4096) fail(ErrorKind::Value, "light map size {} must lie in 4..4096", size);
  LocalRadiance l;
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
  l.source = fmt::format("SH grid (Hanning-windowed, rings clamped: power x{:.2f}, scaled back)",
                         luminance(clamped) / std::max(luminance(power), 1e-300));
  return l;
}

LocalRadiance light_from_probes(const fusion::ProbeSet& set, Vec3 at, int size) {
  fusion::FuseDesc d;
  d.size = size;
  fusion::LocalMap m = fusion::fuse(set, at, d);
  LocalRadiance l;
  l.map = std::move(m.radiance);
  l.centre = at;
  l.source = "fused probes";
  return l;
}

LocalRadiance as_median_cut(const LocalRadiance& light, int count) {
  if (light.map.mapping.kind() != sphere::MappingKind::LatLong)
    fail(ErrorKind::Value, "median-cut baseline: the {} map is not lat-long", light.source);
  lights::CutDesc cd;
  cd.count = count;
  lights::LightSet set = lights::median_cut(light.map, cd);
  LocalRadiance out = light;
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

LightField::LightField(const LocalRadiance& light, const geometry::TriMesh& proxy,
                       const geometry::RayTracer& proxy_tracer) {
  const Image& img = light.map.image;
  const sphere::Mapping& mp = light.map.mapping;
  const int W = img.width(), H = img.height();
  const bool have_depth = !light.depth.empty();
  if (have_depth && (light.depth.width() != W || light.depth.height() != H))
    fail(ErrorKind::Value, "light depth map {}x{} and radiance map {}x{} differ in size", light.depth.width(),
         light.depth.height(), W, H);
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
  if (patches_.size() > std::numeric_limits<uint32_t>::max() / 2)
    fail(ErrorKind::Value, "the {} light has too many texels", light.source);
  std::vector<double>& cdf = cdf_.cdf;
  cdf.resize(patches_.size());
  double acc = 0;
  for (size_t i = 0; i < patches_.size(); ++i) {
    const Patch& p = patches_[i];
    acc += kPowerShare * power_of(p.radiance) * p.omega / power + (1 - kPowerShare) * p.omega / solid;
    cdf[i] = acc;
  }
  for (auto& c : cdf) c /= acc;
  cdf.back() = 1.0;
  cdf_.build_guide();
  build_tables(proxy);
}

void LightField::build_tables(const geometry::TriMesh& proxy) {
  // The proxy's flat parts: its triangles' normals, clustered greedily from the largest triangle down.
  const size_t T = proxy.triangle_count();
  std::vector<uint32_t> order(T);
  for (uint32_t t = 0; t < T; ++t) order[t] = t;
  std::vector<double> area(T);
  for (size_t t = 0; t < T; ++t) area[t] = proxy.area(t);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return area[a] > area[b]; });
  std::vector<Vec3> normal;
  std::vector<double> mass;
  constexpr size_t kMaxClusters = 256;
  for (uint32_t t : order) {
    Vec3 n = proxy.normal(t);
    if (!(area[t] > 0) || !(dot(n, n) > 0.5)) continue;
    size_t k = 0;
    while (k < normal.size() && dot(normal[k], n) < kTableCos) ++k;
    if (k == normal.size()) {
      if (normal.size() == kMaxClusters) continue;
      normal.push_back(n);
      mass.push_back(0);
    }
    mass[k] += area[t];
  }
  std::vector<size_t> by_mass(normal.size());
  for (size_t k = 0; k < by_mass.size(); ++k) by_mass[k] = k;
  std::stable_sort(by_mass.begin(), by_mass.end(), [&](size_t a, size_t b) { return mass[a] > mass[b]; });
  const size_t budget = std::min(kMaxTables, kTableEntries / std::max<size_t>(1, patches_.size())) / 2;
  for (size_t j = 0; j < by_mass.size() && j < budget; ++j) {
    table_normal_.push_back(normal[by_mass[j]]);
    table_normal_.push_back(-normal[by_mass[j]]);
  }
  // Each table: kConditionedShare of the plain probabilities times what a receiver of that normal sees of the
  // patch (light.h, table_for), the rest the plain probabilities.
  tables_.resize(table_normal_.size());
  parallel_for(0, static_cast<int64_t>(tables_.size()), [&](int64_t kk) {
    const Vec3 nb = table_normal_[static_cast<size_t>(kk)];
    std::vector<double>& cdf = tables_[static_cast<size_t>(kk)].cdf;
    cdf.resize(patches_.size());
    double acc = 0;
    for (size_t i = 0; i < patches_.size(); ++i) {
      const Patch& p = patches_[i];
      double seen = p.distant ? std::max(0.0, dot(nb, p.point)) : (dot(nb, p.normal) >= kTableCos ? 0.0 : 1.0);
      acc += pmf(i) * seen;
      cdf[i] = acc;
    }
    const double cond = acc > 0 ? kConditionedShare / acc : 0, plain = acc > 0 ? 1 - kConditionedShare : 1;
    for (size_t i = 0; i < patches_.size(); ++i)
      cdf[i] = std::min(1.0, cond * cdf[i] + plain * cdf_.cdf[i]);  // rounding stays ≤ 1
    cdf.back() = 1.0;
    tables_[static_cast<size_t>(kk)].build_guide();
  });
}

int LightField::table_for(Vec3 n) const {
  int best = -1;
  double best_cos = kTableCos;
  for (size_t k = 0; k < table_normal_.size(); ++k) {
    double c = dot(table_normal_[k], n);
    if (c >= best_cos) {
      best_cos = c;
      best = static_cast<int>(k);
    }
  }
  return best;
}

void LightField::Cdf::build_guide() {
  const size_t G = std::max<size_t>(1, cdf.size() / 2);
  guide.assign(G + 1, 0);
  size_t i = 0;
  for (size_t j = 0; j <= G; ++j) {
    const double u = static_cast<double>(j) / static_cast<double>(G);
    while (i < cdf.size() && cdf[i] <= u) ++i;  // upper_bound(u)
    guide[j] = static_cast<uint32_t>(i);
  }
}

size_t LightField::Cdf::find(double u) const {
  // upper_bound(u) over the whole CDF, searched between the guide's bounds of u's cell.
  const size_t G = guide.size() - 1;
  size_t j = static_cast<size_t>(u * static_cast<double>(G));
  j = std::min(j, G - 1);
  auto lo = cdf.begin() + guide[j],
       hi = cdf.begin() + std::min<size_t>(cdf.size(), static_cast<size_t>(guide[j + 1]) + 1);
  if (!(u >= static_cast<double>(j) / static_cast<double>(G)))
    lo = cdf.begin();  // rounding at a cell's edge: search it all
  if (!(u < static_cast<double>(j + 1) / static_cast<double>(G))) hi = cdf.end();
  return static_cast<size_t>(std::upper_bound(lo, hi, u) - cdf.begin());
}

size_t LightField::sample(double u, double* pmf, int table) const {
  const Cdf& t = table < 0 ? cdf_ : tables_[static_cast<size_t>(table)];
  const std::vector<double>& c = t.cdf;
  size_t i = t.find(u);
  if (i >= c.size()) i = c.size() - 1;
  *pmf = c[i] - (i > 0 ? c[i - 1] : 0.0);
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
  return patch_along(x, w, proxy_tracer.intersect(x, w, kRayEpsilon));
}

long LightField::patch_along(Vec3 x, Vec3 w, const geometry::Hit& h) const {
  constexpr double kDepthMatch = 0.05;  // the texel's patch within 5 % of the hit's distance from the centre
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
  int tx = std::clamp(static_cast<int>(px), 0, mapping_.width() - 1),
      ty = std::clamp(static_cast<int>(py), 0, mapping_.height() - 1);
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
