// The camera every renderer and evaluation uses (docs/conventions.md, "Camera"): an eye looking at a
// target, a vertical field of view and a frame of width × height pixels — a pinhole — or, optionally,
// a photograph's own intrinsics (focal lengths and principal point in pixels) and Brown–Conrady lens
// distortion (OpenCV's model and signs). Pixel (i, j) — row i, column j —
// has its centre at the continuous position (j + ½, i + ½), row 0 at the top, in the CPU and GL
// renderers, the near-field renderer, the lab's photographs and the fusion views alike.
// Header-only (no Embree): the lean GL benchmark uses it too.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string_view>

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

// A photograph's intrinsics: focal lengths fx, fy in pixels and the principal point (cx, cy) in the
// continuous pixel coordinates of Camera (the frame spans [0, W] × [0, H], pixel i's centre at i + ½;
// OpenCV's principal point is (cx − ½, cy − ½), its pixel centres being integers).
struct Intrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
};

// Brown–Conrady lens distortion, OpenCV's model and signs (cv::projectPoints with distCoeffs
// (k1, k2, p1, p2, k3)): an undistorted normalised point (x, y) = (X/Z, Y/Z) in OpenCV's camera axes
// (x right, y down, z forward), r² = x² + y², lands at
//   x' = x·(1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2x²)
//   y' = y·(1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2y²) + 2 p2 x y
// and then at the pixel (fx x' + cx, fy y' + cy).
struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  bool any() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }
  // The distorted normalised point of the undistorted (x, y).
  Vec2 apply(Vec2 u) const {
    double x = u.x, y = u.y, r2 = x * x + y * y;
    double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x), y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
  }
  // The undistorted normalised point whose distortion is d: Newton's method on apply(u) = d from u = d,
  // halving a step that does not reduce the residual, until |apply(u) − d| < kUndistortTolerance
  // (normalised units; 1e-13 is 1e-10 px at a focal length of 1000 px) or 50 steps. Where the lens
  // folds (the radial factor's derivative vanishes, far outside any frame it is valid for) the last
  // iterate is returned; `converged`, when given, says whether the tolerance was met.
  static constexpr double kUndistortTolerance = 1e-13;
  Vec2 invert(Vec2 d, bool* converged = nullptr) const {
    Vec2 u = d;
    auto residual = [&](Vec2 v) { return apply(v) - d; };
    Vec2 e = residual(u);
    double err = std::hypot(e.x, e.y);
    for (int it = 0; it < 50 && err >= kUndistortTolerance; ++it) {
      double x = u.x, y = u.y, r2 = x * x + y * y;
      double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3)), dradial = k1 + r2 * (2 * k2 + 3 * k3 * r2);  // d/d(r²)
      double a = radial + 2 * x * x * dradial + 2 * p1 * y + 6 * p2 * x;                                // ∂x'/∂x
      double b = 2 * x * y * dradial + 2 * p1 * x + 2 * p2 * y;           // ∂x'/∂y = ∂y'/∂x
      double c = radial + 2 * y * y * dradial + 6 * p1 * y + 2 * p2 * x;  // ∂y'/∂y
      double det = a * c - b * b;
      if (!(std::abs(det) > 1e-300)) break;
      Vec2 step{(c * e.x - b * e.y) / det, (a * e.y - b * e.x) / det};
      double s = 1;
      for (int h = 0; h < 30; ++h, s *= 0.5) {
        Vec2 v = u - step * s;
        Vec2 ev = residual(v);
        double errv = std::hypot(ev.x, ev.y);
        if (errv < err) {
          u = v, e = ev, err = errv;
          break;
        }
      }
      if (s < 1e-8) break;
    }
    if (converged) *converged = err < kUndistortTolerance;
    return u;
  }
};

struct Camera {
  Vec3 eye{0, 0.3, 1.2};              // centre of projection, world metres
  Vec3 target{0, 0, 0};               // the point seen at the frame's centre
  Vec3 up{0, 1, 0};                   // world direction that appears upwards (not parallel to target − eye)
  double fov_y_deg = 40.0;            // vertical field of view, degrees
  int width = 1024, height = 768;     // frame size, pixels
  double znear = 0.01, zfar = 100.0;  // clip distances of projection(), metres
  // A photograph's own lens: when set, intrinsics replace fov_y_deg (and the centred principal point)
  // everywhere, and distortion applies. Unset (the default), the camera is the undistorted pinhole of
  // fov_y_deg, computed as it always was.
  std::optional<Intrinsics> intrinsics;
  Distortion distortion;  // only with intrinsics (require_camera)

  bool distorted() const { return intrinsics && distortion.any(); }
  // The intrinsics in use: the ones set, or the pinhole's (fx = fy = H / (2 tan(fov/2)), centred).
  Intrinsics effective_intrinsics() const {
    if (intrinsics) return *intrinsics;
    double f = height / (2 * std::tan(fov_y_deg * kPi / 360.0));
    return {f, f, width / 2.0, height / 2.0};
  }

  // Unit world direction through the continuous pixel position (px, py): x to the right, y down, (0, 0)
  // the frame's top-left corner; pixel (i, j)'s centre is (j + ½, i + ½). With distortion the pixel is
  // undistorted first (Distortion::invert).
  Vec3 ray_direction(double px, double py) const {
    Vec3 f = normalize(target - eye), r = normalize(cross(f, up)), u = cross(r, f);
    if (!intrinsics) {
      double t = std::tan(fov_y_deg * kPi / 360.0), aspect = static_cast<double>(width) / height;
      double sx = (2 * px / width - 1) * t * aspect, sy = (1 - 2 * py / height) * t;
      return normalize(f + r * sx + u * sy);
    }
    const Intrinsics& k = *intrinsics;
    Vec2 n{(px - k.cx) / k.fx, (py - k.cy) / k.fy};
    if (distortion.any()) n = distortion.invert(n);
    return normalize(f + r * n.x - u * n.y);
  }
  // The continuous pixel position where the world point p appears (through the distortion), or nothing
  // when p is not in front of the eye (on or behind its image plane). The inverse of ray_direction.
  std::optional<Vec2> project(Vec3 p) const {
    Vec3 f = normalize(target - eye), r = normalize(cross(f, up)), u = cross(r, f);
    Vec3 d = p - eye;
    double z = dot(d, f);
    if (!(z > 0)) return std::nullopt;
    Vec2 n{dot(d, r) / z, -dot(d, u) / z};
    if (distorted()) n = distortion.apply(n);
    Intrinsics k = effective_intrinsics();
    return Vec2{k.fx * n.x + k.cx, k.fy * n.y + k.cy};
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
  // Eye → clip space: GL's perspective (depth −1 at znear, +1 at zfar). With intrinsics, their focal
  // lengths and principal point (NDC y up: the frame's top row at +1); a projection has no distortion.
  Mat4f projection() const {
    Mat4f m{};
    if (intrinsics) {
      const Intrinsics& k = *intrinsics;
      m[0] = static_cast<float>(2 * k.fx / width);
      m[5] = static_cast<float>(2 * k.fy / height);
      m[8] = static_cast<float>(1 - 2 * k.cx / width);
      m[9] = static_cast<float>(2 * k.cy / height - 1);
    } else {
      double t = 1.0 / std::tan(fov_y_deg * kPi / 360.0), aspect = static_cast<double>(width) / height;
      m[0] = static_cast<float>(t / aspect);
      m[5] = static_cast<float>(t);
    }
    m[10] = static_cast<float>(-(zfar + znear) / (zfar - znear));
    m[11] = -1;
    m[14] = static_cast<float>(-2 * zfar * znear / (zfar - znear));
    return m;
  }
};

// Fails (ErrorKind::Value) unless the camera's intrinsics and distortion are as require_camera says;
// `what` names the camera (a file, an option).
inline void require_lens(const Camera& c, std::string_view what) {
  if (c.intrinsics) {
    const Intrinsics& k = *c.intrinsics;
    for (double v : {k.fx, k.fy, k.cx, k.cy})
      if (!std::isfinite(v))
        fail(ErrorKind::Value, "{}: intrinsics ({}, {}, {}, {}) are not finite", what, k.fx, k.fy, k.cx, k.cy);
    if (!(k.fx > 0 && k.fy > 0 && k.fx <= 1e7 && k.fy <= 1e7))
      fail(ErrorKind::Value, "{}: focal lengths fx = {:g}, fy = {:g} px must lie in (0, 1e7]", what, k.fx, k.fy);
    double w = std::max(c.width, 1), h = std::max(c.height, 1);
    if (std::abs(k.cx - w / 2) > 1.5 * w || std::abs(k.cy - h / 2) > 1.5 * h)
      fail(ErrorKind::Value, "{}: principal point ({:g}, {:g}) lies far outside the {}x{} frame", what, k.cx, k.cy,
           c.width, c.height);
  }
  const Distortion& d = c.distortion;
  for (double v : {d.k1, d.k2, d.p1, d.p2, d.k3})
    if (!std::isfinite(v))
      fail(ErrorKind::Value, "{}: distortion ({}, {}, {}, {}, {}) is not finite", what, d.k1, d.k2, d.p1, d.p2, d.k3);
  if (std::abs(d.k1) > 100 || std::abs(d.k2) > 100 || std::abs(d.k3) > 100 || std::abs(d.p1) > 1 || std::abs(d.p2) > 1)
    fail(ErrorKind::Value, "{}: distortion (k1 {:g}, k2 {:g}, p1 {:g}, p2 {:g}, k3 {:g}) beyond |k| ≤ 100, |p| ≤ 1",
         what, d.k1, d.k2, d.p1, d.p2, d.k3);
  if (d.any() && !c.intrinsics) fail(ErrorKind::Value, "{}: distortion needs intrinsics (fx, fy, cx, cy)", what);
}

// Fails (ErrorKind::Value) unless the camera's eye and target are points within the supported range
// (core/check.h), distinct, its up direction is not parallel to the view and its field of view lies in
// (0°, 180°); with intrinsics, that they are finite, fx, fy > 0 and the principal point within the
// frame widened by its size on every side, and that distortion comes only with intrinsics, its
// coefficients finite and bounded (|k1|, |k2|, |k3| ≤ 100, |p1|, |p2| ≤ 1). Every renderer calls this
// before it casts a ray.
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
  require_lens(c, "camera");
}

}  // namespace ibl::geometry
