#include "iblkit/nearfield/spotlight.h"

#include <cmath>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"

namespace ibl::nearfield {

namespace {

// GL_LINEAR with GL_CLAMP_TO_BORDER (border 0) on one level at normalised (u, v).
Vec3 bilinear_border(const Image& img, double u, double v) {
  const int w = img.width(), h = img.height();
  const double px = u * w - 0.5, py = v * h - 0.5;
  const double fx0 = std::floor(px), fy0 = std::floor(py);
  const double ax = px - fx0, ay = py - fy0;
  const long x0 = static_cast<long>(fx0), y0 = static_cast<long>(fy0);
  Vec3 acc{0, 0, 0};
  for (int dy = 0; dy < 2; ++dy) {
    const long y = y0 + dy;
    if (y < 0 || y >= h) continue;
    const double wy = dy ? ay : 1 - ay;
    for (int dx = 0; dx < 2; ++dx) {
      const long x = x0 + dx;
      if (x < 0 || x >= w) continue;
      const double wx = dx ? ax : 1 - ax;
      const float* p = img.pixel(static_cast<int>(x), static_cast<int>(y));
      acc += Vec3{p[0], p[1], p[2]} * (wx * wy);
    }
  }
  return acc;
}

}  // namespace

Vec3 texture_lookup(const TexturedSpotlight& L, Vec3 x) {
  const Vec3 q = x - L.position;
  const double z = dot(q, L.frame.n);
  if (z <= 0 || !L.mips || L.mips->empty()) return {0, 0, 0};
  const auto& mips = *L.mips;
  const double d = L.plane_distance;
  const double s = dot(q, L.frame.t) * d / z, t = dot(q, L.frame.b) * d / z;
  const double ext_x = L.tex_max.x - L.tex_min.x, ext_y = L.tex_max.y - L.tex_min.y;
  const double u = (s - L.tex_min.x) / ext_x, v = (L.tex_max.y - t) / ext_y;
  const double footprint = L.support_width * std::abs(1 - d / z);
  const double texel = std::max(ext_x / mips[0].width(), ext_y / mips[0].height());
  const int levels = static_cast<int>(mips.size());
  double lambda = footprint > 0 ? std::log2(footprint / texel) : 0.0;
  lambda = std::clamp(lambda, 0.0, static_cast<double>(levels - 1));
  const int a = static_cast<int>(std::floor(lambda));
  const int b = std::min(a + 1, levels - 1);
  const double f = lambda - a;
  Vec3 ea = bilinear_border(mips[a], u, v);
  if (f == 0) return ea;
  return ea * (1 - f) + bilinear_border(mips[b], u, v) * f;
}

Vec3 irradiance(const TexturedSpotlight& L, Vec3 x, Vec3 n) {
  const Vec3 q = x - L.position;
  const double z = dot(q, L.frame.n);
  if (z <= 0) return {0, 0, 0};
  const double d2 = dot(q, q), dl = std::sqrt(d2);
  const double cos_l = z / dl, cos_r = -dot(n, q) / dl;
  if (cos_r <= 0) return {0, 0, 0};
  return texture_lookup(L, x) * (L.support_area * cos_l * cos_r / d2);
}

std::vector<Image> build_mips(const Image& img) {
  if (img.empty() || img.channels() < 3)
    fail(ErrorKind::Value, "build_mips: need a non-empty RGB image, got {}x{}x{}", img.width(), img.height(),
         img.channels());
  std::vector<Image> mips;
  mips.push_back(img.with_channels(3));
  while (mips.back().width() > 1 || mips.back().height() > 1) {
    const Image& src = mips.back();
    const int w = std::max(1, src.width() / 2), h = std::max(1, src.height() / 2);
    Image dst(w, h, 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        // The 2×2 block (2x..2x+1, 2y..2y+1), clamped where a side is already 1 texel.
        const int x0 = std::min(2 * x, src.width() - 1), x1 = std::min(2 * x + 1, src.width() - 1);
        const int y0 = std::min(2 * y, src.height() - 1), y1 = std::min(2 * y + 1, src.height() - 1);
        for (int c = 0; c < 3; ++c)
          dst.at(x, y, c) = 0.25f * (src.at(x0, y0, c) + src.at(x1, y0, c) + src.at(x0, y1, c) + src.at(x1, y1, c));
      }
    mips.push_back(std::move(dst));
  }
  return mips;
}

Frame Placement::frame() const {
  require_point("luminaire position", position);
  const Vec3 f = require_direction("luminaire forward", forward);
  require_direction("luminaire up", up_hint);
  const Vec3 r = cross(up_hint, f);
  if (length(f) == 0 || length(r) < 1e-9)
    fail(ErrorKind::Value, "luminaire placement: forward ({}, {}, {}) is zero or parallel to up ({}, {}, {})",
         forward.x, forward.y, forward.z, up_hint.x, up_hint.y, up_hint.z);
  const Vec3 right = normalize(r);
  return Frame{right, cross(f, right), f};
}

Vec3 Placement::to_world(Vec3 local) const { return position + frame().from_local(local); }

}  // namespace ibl::nearfield
