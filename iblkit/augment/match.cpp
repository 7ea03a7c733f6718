#include "iblkit/augment/match.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "iblkit/augment/rays.h"
#include "iblkit/core/error.h"
#include "iblkit/geometry/raytracer.h"

namespace ibl::augment {

namespace {

double median(std::vector<double>& v) {
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

double median_of_image(const Image& img) {
  std::vector<double> y;
  const size_t step = std::max<size_t>(1, img.pixel_count() / 20000);
  for (size_t i = 0; i < img.pixel_count(); i += step) {
    const float* p = img.data() + i * static_cast<size_t>(img.channels());
    y.push_back(luminance(Vec3{p[0], p[std::min(1, img.channels() - 1)], p[std::min(2, img.channels() - 1)]}));
  }
  return y.empty() ? 0 : median(y);
}

}  // namespace

std::vector<SeenPoint> seen_points(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                                   Vec3 centre, double saturated, int64_t max_points, const PixelRect* region) {
  if (photo.channels() < 3 || photo.width() != cam.width || photo.height() != cam.height)
    fail(ErrorKind::Value, "match: the photograph ({}x{}) and the camera's frame ({}x{}) must agree", photo.width(),
         photo.height(), cam.width, cam.height);
  if (proxy.triangle_count() == 0) fail(ErrorKind::Value, "match: the proxy has no triangles");
  const int64_t pixels = static_cast<int64_t>(photo.width()) * photo.height();
  if (region && (region->w < 1 || region->h < 1 || region->x < 0 || region->y < 0 ||
                 region->x + region->w > photo.width() || region->y + region->h > photo.height()))
    fail(ErrorKind::Value, "grey card {},{},{},{} must lie inside the {}x{} photograph", region->x, region->y,
         region->w, region->h, photo.width(), photo.height());
  geometry::RayTracer rt;
  rt.add(proxy);
  rt.commit();
  const double photo_floor = 0.01 * median_of_image(photo);
  const int64_t stride = region ? 1 : std::max<int64_t>(1, pixels / std::max<int64_t>(1, max_points));
  std::vector<SeenPoint> out;
  for (int64_t i = 0; i < pixels; i += stride) {
    const int x = static_cast<int>(i % photo.width()), y = static_cast<int>(i / photo.width());
    if (region && (x < region->x || x >= region->x + region->w || y < region->y || y >= region->y + region->h))
      continue;
    const Vec3 d = cam.pixel_direction(x, y);
    const geometry::Hit h = rt.intersect(cam.eye, d);
    if (!h.hit) continue;
    const Vec3 at = cam.eye + d * h.t;
    Vec3 w = at - centre;
    const double dist = length(w);
    if (!(dist > 1e-6)) continue;
    w = w / dist;
    const Vec3 n = proxy.normal(h.triangle);
    if (dot(n, d) * dot(n, w) <= 0) continue;  // the probe sees the other side of the surface (or grazes it)
    if (rt.occluded(centre, w, kRayEpsilon, dist * (1 - kShadowShorten))) continue;  // hidden from the probe
    const Vec3 ph = photo.rgb(x, y);
    if (saturated > 0 && (ph.x >= saturated || ph.y >= saturated || ph.z >= saturated)) continue;
    if (luminance(ph) < photo_floor || !(ph.x > 0 && ph.y > 0 && ph.z > 0)) continue;
    out.push_back({ph, w, dist});
  }
  return out;
}

bool light_at(const LocalRadiance& light, const SeenPoint& p, Vec3 dir, double light_floor, Vec3* lp) {
  if (!light.depth.empty()) {
    double px, py;
    if (!light.map.mapping.to_pixel(dir, &px, &py)) return false;
    const int ix = std::clamp(static_cast<int>(px), 0, light.depth.width() - 1),
              iy = std::clamp(static_cast<int>(py), 0, light.depth.height() - 1);
    const double t = light.depth.at(ix, iy, 0);
    if (t > 0 && std::abs(t - p.dist) > 0.05 * p.dist) return false;  // something else along that direction
  }
  *lp = light.map.sample_rgb(dir);
  return luminance(*lp) >= light_floor && lp->x > 0 && lp->y > 0 && lp->z > 0;
}

double light_floor_of(const LocalRadiance& light) { return 0.01 * median_of_image(light.map.image); }

MatchResult estimate_match(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                           const LocalRadiance& light, double saturated, int64_t max_points, const PixelRect* region) {
  const std::vector<SeenPoint> pts = seen_points(photo, cam, proxy, light.centre, saturated, max_points, region);
  const double light_floor = light_floor_of(light);
  std::array<std::vector<double>, 3> ratio;
  std::vector<double> log_ratio;
  for (const SeenPoint& p : pts) {
    Vec3 lp;
    if (!light_at(light, p, p.dir, light_floor, &lp)) continue;
    for (int c = 0; c < 3; ++c) ratio[c].push_back(p.photo[c] / lp[c]);
    log_ratio.push_back(std::log2(luminance(p.photo) / luminance(lp)));
  }
  MatchResult r;
  r.points = static_cast<int64_t>(log_ratio.size());
  if (r.points < (region ? kMinCardPoints : kMinMatchPoints)) return r;
  for (int c = 0; c < 3; ++c) r.gain[c] = median(ratio[c]);
  const double m = median(log_ratio);
  for (double& v : log_ratio) v = std::abs(v - m);
  r.spread = median(log_ratio);
  r.valid = true;
  return r;
}

LocalRadiance scaled(const LocalRadiance& light, Vec3 gain) {
  LocalRadiance out = light;
  Image& img = out.map.image;
  for (size_t i = 0; i < img.pixel_count(); ++i)
    for (int c = 0; c < std::min(3, img.channels()); ++c)
      img.data()[i * static_cast<size_t>(img.channels()) + c] *= static_cast<float>(gain[c]);
  return out;
}

}  // namespace ibl::augment
