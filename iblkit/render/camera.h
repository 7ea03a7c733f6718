// A pinhole camera and the 4×4 matrices GL wants (column-major floats).
#pragma once
#include <array>
#include <cmath>

#include "iblkit/core/vec.h"

namespace ibl::render {

using Mat4f = std::array<float, 16>;  // column-major: m[col * 4 + row]

struct Camera {
  Vec3 eye{0, 0.3, 1.2};
  Vec3 target{0, 0, 0};
  Vec3 up{0, 1, 0};
  double fov_y_deg = 40.0;  // vertical field of view
  int width = 1024, height = 768;
  double znear = 0.01, zfar = 100.0;

  // Unit world direction through pixel position (px, py) (continuous, y down).
  Vec3 ray_direction(double px, double py) const {
    Vec3 f = normalize(target - eye), r = normalize(cross(f, up)), u = cross(r, f);
    double t = std::tan(fov_y_deg * kPi / 360.0), aspect = static_cast<double>(width) / height;
    double sx = (2 * px / width - 1) * t * aspect, sy = (1 - 2 * py / height) * t;
    return normalize(f + r * sx + u * sy);
  }
  Mat4f view() const {
    Vec3 f = normalize(target - eye), r = normalize(cross(f, up)), u = cross(r, f);
    return {static_cast<float>(r.x), static_cast<float>(u.x), static_cast<float>(-f.x), 0,
            static_cast<float>(r.y), static_cast<float>(u.y), static_cast<float>(-f.y), 0,
            static_cast<float>(r.z), static_cast<float>(u.z), static_cast<float>(-f.z), 0,
            static_cast<float>(-dot(r, eye)), static_cast<float>(-dot(u, eye)), static_cast<float>(dot(f, eye)), 1};
  }
  Mat4f projection() const {
    double t = 1.0 / std::tan(fov_y_deg * kPi / 360.0), aspect = static_cast<double>(width) / height;
    Mat4f m{};
    m[0] = static_cast<float>(t / aspect);
    m[5] = static_cast<float>(t);
    m[10] = static_cast<float>(-(zfar + znear) / (zfar - znear));
    m[11] = -1;
    m[14] = static_cast<float>(-2 * zfar * znear / (zfar - znear));
    return m;
  }
};

inline Mat4f mul(const Mat4f& a, const Mat4f& b) {
  Mat4f r{};
  for (int c = 0; c < 4; ++c)
    for (int rr = 0; rr < 4; ++rr) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + rr] * b[c * 4 + k];
      r[c * 4 + rr] = s;
    }
  return r;
}

// Orthographic light-space matrix for a directional light shining along −dir_to_light, fitting a
// bounding sphere (centre, radius).
inline Mat4f light_view_projection(Vec3 dir_to_light, Vec3 centre, double radius) {
  Camera c;
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
  Camera c;
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
    Camera c;
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
