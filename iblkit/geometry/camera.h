// The pinhole camera every renderer and evaluation uses (docs/conventions.md, "Camera"): an eye looking at a
// target, a vertical field of view and a frame of width × height pixels. Pixel (i, j) — row i, column j —
// has its centre at the continuous position (j + ½, i + ½), row 0 at the top, in the CPU and GL
// renderers, the near-field renderer, the lab's photographs and the fusion views alike.
// Header-only (no Embree): the lean GL benchmark uses it too.
#pragma once
#include <array>
#include <cmath>

#include "iblkit/core/check.h"
#include "iblkit/core/vec.h"

namespace ibl::geometry {

using Mat4f = std::array<float, 16>;  // column-major: m[col * 4 + row] (as GL takes it)

// a · b of column-major 4×4 matrices.
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

struct Camera {
  Vec3 eye{0, 0.3, 1.2};              // centre of projection, world metres
  Vec3 target{0, 0, 0};               // the point seen at the frame's centre
  Vec3 up{0, 1, 0};                   // world direction that appears upwards (not parallel to target − eye)
  double fov_y_deg = 40.0;            // vertical field of view, degrees
  int width = 1024, height = 768;     // frame size, pixels
  double znear = 0.01, zfar = 100.0;  // clip distances of projection(), metres

  // Unit world direction through the continuous pixel position (px, py): x to the right, y down, (0, 0)
  // the frame's top-left corner; pixel (i, j)'s centre is (j + ½, i + ½).
  Vec3 ray_direction(double px, double py) const {
    Vec3 f = normalize(target - eye), r = normalize(cross(f, up)), u = cross(r, f);
    double t = std::tan(fov_y_deg * kPi / 360.0), aspect = static_cast<double>(width) / height;
    double sx = (2 * px / width - 1) * t * aspect, sy = (1 - 2 * py / height) * t;
    return normalize(f + r * sx + u * sy);
  }
  // The direction through the centre of the pixel in column x, row y.
  Vec3 pixel_direction(int x, int y) const { return ray_direction(x + 0.5, y + 0.5); }

  // World → eye space (right-handed, looking along −Z, +Y up), as GL's lookAt.
  Mat4f view() const {
    Vec3 f = normalize(target - eye), r = normalize(cross(f, up)), u = cross(r, f);
    return {static_cast<float>(r.x),          static_cast<float>(u.x),          static_cast<float>(-f.x),        0,
            static_cast<float>(r.y),          static_cast<float>(u.y),          static_cast<float>(-f.y),        0,
            static_cast<float>(r.z),          static_cast<float>(u.z),          static_cast<float>(-f.z),        0,
            static_cast<float>(-dot(r, eye)), static_cast<float>(-dot(u, eye)), static_cast<float>(dot(f, eye)), 1};
  }
  // Eye → clip space: GL's perspective (depth −1 at znear, +1 at zfar).
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

// Fails (ErrorKind::Value) unless the camera's eye and target are points within the supported range
// (core/check.h), distinct, its up direction is not parallel to the view and its field of view lies in
// (0°, 180°). Every renderer calls this before it casts a ray.
inline void require_camera(const Camera& c) {
  require_point("camera eye", c.eye);
  require_point("camera target", c.target);
  Vec3 f = c.target - c.eye;
  if (!(length(f) > 1e-9))
    fail(ErrorKind::Value, "camera: eye and target are the same point ({}, {}, {})", c.eye.x, c.eye.y, c.eye.z);
  Vec3 up = require_direction("camera up", c.up);
  if (length(cross(normalize(f), up)) < 1e-9)
    fail(ErrorKind::Value, "camera: up ({}, {}, {}) is parallel to the view direction", c.up.x, c.up.y, c.up.z);
  if (!(c.fov_y_deg > 0 && c.fov_y_deg < 180))
    fail(ErrorKind::Value, "camera: field of view {}° outside (0°, 180°)", c.fov_y_deg);
}

}  // namespace ibl::geometry
