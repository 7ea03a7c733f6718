// Light-space matrices for the GL renderer's shadow maps: an orthographic frustum for a directional
// light, a perspective one for a point light outside the objects, six cube faces for one inside.
// Built from the one pinhole camera (geometry/camera.h), column-major as GL takes them.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

#include "iblkit/geometry/camera.h"

namespace ibl::render {

using geometry::Mat4f;
using geometry::mul;

// Orthographic light-space matrix for a directional light shining along −dir_to_light, fitting a
// bounding sphere (centre, radius).
inline Mat4f light_view_projection(Vec3 dir_to_light, Vec3 centre, double radius) {
  geometry::Camera c;
  c.eye = centre + normalize(dir_to_light) * (2 * radius);
  c.target = centre;
  c.up = std::abs(normalize(dir_to_light).y) > 0.99 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  Mat4f v = c.view();
  Mat4f p{};
  float r = static_cast<float>(radius);
  p[0] = 1 / r;
  p[5] = 1 / r;
  p[10] = -1 / (2 * r);  // z from 2r·(±1) around the centre at distance 2r: near 0, far 4r
  p[14] = -1;
  p[15] = 1;
  return mul(p, v);
}

// Perspective light-space matrix for a light at `position` looking at a bounding sphere (centre,
// radius) that it sits outside of: the frustum just contains the sphere. Returns false (and leaves
// *m alone) when the light is inside or too close to the sphere for one frustum to hold it.
inline bool point_light_view_projection(Vec3 position, Vec3 centre, double radius, Mat4f* m) {
  Vec3 to = centre - position;
  double dist = length(to);
  if (!(dist > radius * 1.05)) return false;
  geometry::Camera c;
  c.eye = position;
  c.target = centre;
  c.up = std::abs(to.y / dist) > 0.99 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  c.fov_y_deg = 2 * std::asin(std::min(1.0, radius / dist)) * 180 / kPi * 1.02;
  c.width = c.height = 1;
  c.znear = std::max(1e-4, dist - radius) * 0.95;
  c.zfar = (dist + radius) * 1.05;
  *m = mul(c.projection(), c.view());
  return true;
}

// The six faces of a cube shadow map around a point light (+X, −X, +Y, −Y, +Z, −Z, each a 95°
// frustum: a margin at the face edges so that the 2×2 PCF taps stay inside), reaching `far` metres.
// The shader picks the face of the largest component of p − position (its sign: + first).
inline std::array<Mat4f, 6> cube_light_view_projections(Vec3 position, double far) {
  static const Vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const Vec3 ups[6] = {{0, 1, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, -1}, {0, 1, 0}, {0, 1, 0}};
  std::array<Mat4f, 6> out;
  for (int f = 0; f < 6; ++f) {
    geometry::Camera c;
    c.eye = position;
    c.target = position + axes[f];
    c.up = ups[f];
    c.fov_y_deg = 95;
    c.width = c.height = 1;
    c.zfar = far;
    c.znear = std::max(1e-4, far * 1e-4);
    out[f] = mul(c.projection(), c.view());
  }
  return out;
}

}  // namespace ibl::render
