#include "iblkit/augment/sphere_occlusion.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::augment {

OccluderSphere equivalent_sphere(const geometry::TriMesh& object) {
  if (object.triangle_count() == 0) fail(ErrorKind::Value, "the object has no triangles");
  OccluderSphere s;
  Vec3 lo, hi;
  object.bounds(&lo, &hi);
  s.centre = (lo + hi) * 0.5;
  for (const Vec3& p : object.positions) s.bound_radius = std::max(s.bound_radius, length(p - s.centre));
  double volume = 0;
  for (const auto& t : object.triangles)
    volume += dot(object.positions[t[0]] - s.centre,
                  cross(object.positions[t[1]] - s.centre, object.positions[t[2]] - s.centre)) /
              6;
  // A closed mesh has every edge twice, once each way; an open one (a plane, a shell) falls back to the area rule.
  std::vector<std::pair<uint64_t, int>> edges;
  edges.reserve(object.triangle_count() * 3);
  for (const auto& t : object.triangles)
    for (int e = 0; e < 3; ++e) {
      uint64_t a = t[e], b = t[(e + 1) % 3];
      edges.push_back({std::min(a, b) << 32 | std::max(a, b), a < b ? 1 : -1});
    }
  std::sort(edges.begin(), edges.end());
  bool closed = true;
  for (size_t i = 0; i < edges.size() && closed;) {
    size_t j = i;
    int sum = 0;
    while (j < edges.size() && edges[j].first == edges[i].first) sum += edges[j++].second;
    closed = (j - i) == 2 && sum == 0;
    i = j;
  }
  s.radius = closed && volume > 0 ? std::cbrt(3 * volume / (4 * kPi)) : std::sqrt(object.total_area() / (4 * kPi));
  s.radius = std::min(s.radius, s.bound_radius);
  return s;
}

double cap_cosine_integral(double cos_beta, double sin2_alpha) {
  const double s2 = std::clamp(sin2_alpha, 0.0, 1 - 1e-9), c = std::clamp(cos_beta, -1.0, 1.0);
  if (c * c > s2) return c > 0 ? kPi * s2 * c : 0.0;  // wholly above (or below) the horizon
  const double st = std::sqrt(std::max(0.0, 1 - c * c)), x = std::sqrt(1 / s2 - 1),
               y = std::clamp(-x * c / st, -1.0, 1.0);
  const double sy = st * std::sqrt(std::max(0.0, 1 - y * y));
  return std::max(0.0, (c * std::acos(y) - x * sy) * s2 + std::atan(sy / x));
}

Image facing_irradiance(const geometry::TriMesh& object, const std::vector<Vec3>* factor, const Image& soft_irradiance,
                        int height) {
  if (height < 2 || height > 1024) fail(ErrorKind::Value, "facing irradiance height {} must lie in 2..1024", height);
  if (factor && factor->size() != object.triangle_count())
    fail(ErrorKind::Value, "{} soft factors for an object of {} triangles", factor->size(), object.triangle_count());
  if (soft_irradiance.width() != 2 * soft_irradiance.height() || soft_irradiance.channels() < 3)
    fail(ErrorKind::Value, "the soft irradiance is {}x{}x{}, not a lat-long RGB map", soft_irradiance.width(),
         soft_irradiance.height(), soft_irradiance.channels());
  const sphere::EnvMap irr(soft_irradiance, sphere::Mapping(sphere::MappingKind::LatLong, soft_irradiance.width(),
                                                            soft_irradiance.height()));
  // The triangles gathered by normal into cells of a 2H × H lat-long grid of normals: Σ A, Σ A·n, Σ A·f·E_c(n).
  const sphere::Mapping cells(sphere::MappingKind::LatLong, 2 * height, height);
  const size_t C = static_cast<size_t>(2 * height) * height;
  std::vector<double> area(C, 0);
  std::vector<Vec3> normal_sum(C), light_sum(C);
  for (size_t t = 0; t < object.triangle_count(); ++t) {
    const Vec3 n = object.normal(t);
    const double a = object.area(t);
    double px, py;
    if (!(a > 0) || !(dot(n, n) > 0.5) || !cells.to_pixel(n, &px, &py)) continue;
    const int x = std::clamp(static_cast<int>(px), 0, 2 * height - 1),
              y = std::clamp(static_cast<int>(py), 0, height - 1);
    const size_t c = static_cast<size_t>(y) * 2 * height + x;
    const Vec3 f = factor ? (*factor)[t] : Vec3{1, 1, 1};
    area[c] += a;
    normal_sum[c] += n * a;
    light_sum[c] += irr.sample_rgb(n) * f * a;
  }
  std::vector<size_t> used;
  for (size_t c = 0; c < C; ++c)
    if (area[c] > 0) {
      used.push_back(c);
      const double len = length(normal_sum[c]);
      normal_sum[c] = len > 0 ? normal_sum[c] / len : Vec3{0, 1, 0};
    }
  Image out(2 * height, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < 2 * height; ++x) {
      Vec3 d;
      if (!cells.to_direction(x + 0.5, y + 0.5, &d)) continue;
      double w = 0;
      Vec3 e;
      for (size_t c : used) {
        const double k = std::max(0.0, dot(normal_sum[c], d));
        w += k * area[c];
        e += light_sum[c] * k;
      }
      if (w > 0) out.set_rgb(x, y, e / w);
    }
  return out;
}

}  // namespace ibl::augment
