// The radiometric match between the captured light and the photograph (docs/augment.md, "Radiometric
// match"): the probe and the backplate come from different exposures, often different cameras, so their
// values differ by a scale and per-channel gains. Both see the proxy — the probe in its lower hemisphere,
// the photograph where its pixels meet it — and a Lambertian surface's radiance is the same from every
// side, so the gains are the ratio of what the two see at the same points:
//
//   g_c = median over proxy points y seen by both of  photo_c(y) / L_c(centre → y)
//
// y is where a pixel's ray meets the proxy; the probe sees it when it is on the side of the surface the
// camera sees and nothing of the proxy lies between its centre and y (and, with a depth map, when the map's depth along
// that direction is y's distance within 5 %, so that a lamp in front of the proxy is not taken for the floor). Pixels
// too dark in either (below 1 % of their image's median) or saturated in the photograph are left out. The median and
// the spread (the median absolute deviation of log2 of the ratios) are reported; multiplying the light
// by g puts it in the photograph's units, so that the object is rendered as bright as the photograph's
// surfaces and the shadows are right (a 1-stop mismatch: docs/augment.md).
#pragma once
#include <cstdint>
#include <vector>

#include "iblkit/augment/light.h"
#include "iblkit/core/image.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::augment {

struct MatchResult {
  Vec3 gain{1, 1, 1};  // photograph / light, per channel
  int64_t points = 0;  // proxy points both saw
  double spread = 0;   // median absolute deviation of log2(ratio), stops (luminance)
  bool valid = false;  // enough points (≥ kMinMatchPoints) for a gain
};
inline constexpr int64_t kMinMatchPoints = 64;  // over the whole photograph
inline constexpr int64_t kMinCardPoints = 16;   // inside a grey card's rectangle

// saturated: a photograph value at or above this (in any channel) is left out (the photograph's top code
// linearised; 0: none is). At most max_points pixels, evenly spread, are used. region (x, y, w, h in pixels):
// only the pixels inside it — a grey card (or any matte patch) both see — every one of them.
struct PixelRect {
  int x = 0, y = 0, w = 0, h = 0;
};
MatchResult estimate_match(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                           const LocalRadiance& light, double saturated = 0, int64_t max_points = 40000,
                           const PixelRect* region = nullptr);

// The light times the gains (its map; the depth stays).
LocalRadiance scaled(const LocalRadiance& light, Vec3 gain);

// What estimate_match compares, before the light is looked up: the photograph's value at a proxy point y both can see,
// and the unit direction and distance from the light's centre to y. (estimate_match and register_yaw share it.)
struct SeenPoint {
  Vec3 photo, dir;
  double dist = 0;
};
std::vector<SeenPoint> seen_points(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                                   Vec3 centre, double saturated, int64_t max_points, const PixelRect* region);
// The light towards `dir` for the point p: false where it is below `floor` (light_floor_of: 1 % of the light's
// median) or not positive, or where the light's depth map says something nearer lies that way.
bool light_at(const LocalRadiance& light, const SeenPoint& p, Vec3 dir, double floor, Vec3* out);
double light_floor_of(const LocalRadiance& light);

}  // namespace ibl::augment
