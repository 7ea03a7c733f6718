#include "iblkit/augment/sphere_occlusion.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"

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
    volume += dot(object.positions[t[0]] - s.centre, cross(object.positions[t[1]] - s.centre, object.positions[t[2]] - s.centre)) / 6;
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
  const double st = std::sqrt(std::max(0.0, 1 - c * c)), x = std::sqrt(1 / s2 - 1), y = std::clamp(-x * c / st, -1.0, 1.0);
  const double sy = st * std::sqrt(std::max(0.0, 1 - y * y));
  return std::max(0.0, (c * std::acos(y) - x * sy) * s2 + std::atan(sy / x));
}

}  // namespace ibl::augment
