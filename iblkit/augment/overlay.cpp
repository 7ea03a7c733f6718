#include "iblkit/augment/overlay.h"

#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "iblkit/core/error.h"
#include "iblkit/geometry/raytracer.h"
#include "iblkit/io/draw.h"

namespace ibl::augment {

namespace {

constexpr double kFeatureCos = 0.93969262078590838;  // cos 20°

// Vertices welded by position (1 µm), so that meshes without shared vertices still know their neighbours.
std::tuple<long long, long long, long long> key_of(Vec3 p) {
  return {std::llround(p.x * 1e6), std::llround(p.y * 1e6), std::llround(p.z * 1e6)};
}

}  // namespace

Image proxy_overlay(const Image& picture, const geometry::Camera& cam, const geometry::TriMesh& proxy, Vec3 rgb) {
  if (picture.width() != cam.width || picture.height() != cam.height || picture.channels() < 3)
    fail(ErrorKind::Value, "proxy overlay: the picture ({}x{}) and the camera's frame ({}x{}) must agree",
         picture.width(), picture.height(), cam.width, cam.height);
  Image out = picture.with_channels(3);
  if (proxy.triangle_count() == 0) return out;
  std::map<std::tuple<long long, long long, long long>, int> ids;
  std::vector<Vec3> welded;
  auto id = [&](Vec3 p) {
    auto [it, added] = ids.try_emplace(key_of(p), static_cast<int>(welded.size()));
    if (added) welded.push_back(p);
    return it->second;
  };
  std::map<std::pair<int, int>, std::vector<size_t>> edges;  // welded vertex pair → triangles
  for (size_t t = 0; t < proxy.triangle_count(); ++t)
    for (int e = 0; e < 3; ++e) {
      int a = id(proxy.positions[proxy.triangles[t][e]]), b = id(proxy.positions[proxy.triangles[t][(e + 1) % 3]]);
      if (a == b) continue;
      edges[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  geometry::RayTracer rt;
  rt.add(proxy);
  rt.commit();
  auto visible = [&](Vec3 q) {
    Vec3 d = q - cam.eye;
    const double dist = length(d);
    if (!(dist > 0)) return false;
    d = d / dist;
    const geometry::Hit h = rt.intersect(cam.eye, d);
    return !h.hit || h.t >= dist * (1 - 1e-3) - 1e-4;
  };
  for (const auto& [e, tris] : edges) {
    bool feature = tris.size() != 2;
    if (!feature) feature = std::abs(dot(proxy.normal(tris[0]), proxy.normal(tris[1]))) < kFeatureCos;
    if (!feature) continue;
    const Vec3 a = welded[static_cast<size_t>(e.first)], b = welded[static_cast<size_t>(e.second)];
    const auto pa = cam.project(a), pb = cam.project(b);
    // About one sample per pixel of the projected edge (a part behind the eye, or off the frame: 1024 samples).
    const bool in_frame = pa && pb && std::abs(pa->x) < 4 * cam.width && std::abs(pb->x) < 4 * cam.width &&
                          std::abs(pa->y) < 4 * cam.height && std::abs(pb->y) < 4 * cam.height;
    const double px_len = in_frame ? std::hypot(pb->x - pa->x, pb->y - pa->y) : 1024.0;
    const int n = std::clamp(static_cast<int>(std::ceil(px_len)), 1, 4096);
    std::optional<Vec2> prev;
    for (int i = 0; i <= n; ++i) {
      const Vec3 q = a + (b - a) * (static_cast<double>(i) / n);
      auto p = cam.project(q);
      // Only inside the frame: beyond it a strong lens's polynomial folds back and throws points far away.
      if (p && !(p->x > -2 && p->x < cam.width + 2 && p->y > -2 && p->y < cam.height + 2)) p.reset();
      const bool seen = p && visible(q);
      if (seen && prev && std::hypot(p->x - prev->x, p->y - prev->y) < 8)  // samples ~1 px apart; a jump: a fold
        ibl::io::draw_line(out, prev->x, prev->y, p->x, p->y, rgb, 1.5);
      prev = seen ? p : std::nullopt;
    }
  }
  return out;
}

}  // namespace ibl::augment
