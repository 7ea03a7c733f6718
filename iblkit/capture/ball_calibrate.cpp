#include "iblkit/capture/ball_calibrate.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "iblkit/core/error.h"
#include "iblkit/ilf/ball.h"

namespace ibl::capture {
namespace {

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  return v[k];
}

// The integer pixel range [x0, x1) × [y0, y1) of the pixels whose centres lie in the box; throws when the
// box is not finite, empty or leaves the image.
void pixel_range(const PixelBox& b, const Image& img, const std::string& what, const char* which, int* x0, int* y0,
                 int* x1, int* y1) {
  if (!(std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.w) && std::isfinite(b.h) && b.w > 0 && b.h > 0))
    fail(ErrorKind::Value, "{}: the {} box {},{},{},{} must be finite with a positive size (x,y,w,h in pixels)", what,
         which, b.x, b.y, b.w, b.h);
  if (b.x < 0 || b.y < 0 || b.x + b.w > img.width() || b.y + b.h > img.height())
    fail(ErrorKind::Value, "{}: the {} box {},{},{},{} leaves its {}x{} image", what, which, b.x, b.y, b.w, b.h,
         img.width(), img.height());
  *x0 = int(std::ceil(b.x - 0.5));
  *y0 = int(std::ceil(b.y - 0.5));
  *x1 = int(std::floor(b.x + b.w - 0.5)) + 1;
  *y1 = int(std::floor(b.y + b.h - 0.5)) + 1;
}

struct Sample {
  Vec3 value;
  double lum = 0, incidence_deg = 0;
};

// The samples whose luminance is at least plateau × the 95th percentile.
std::vector<Sample> light_pixels(const std::vector<Sample>& all, double plateau) {
  std::vector<double> lum;
  for (const auto& s : all) lum.push_back(s.lum);
  double cut = plateau * quantile(lum, 0.95);
  std::vector<Sample> out;
  if (!(cut > 0)) return out;
  for (const auto& s : all)
    if (s.lum >= cut) out.push_back(s);
  return out;
}

Vec3 channel_median(const std::vector<Sample>& s) {
  Vec3 m;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> v;
    for (const auto& e : s) v.push_back(e.value[c]);
    m[c] = quantile(v, 0.5);
  }
  return m;
}

}  // namespace

ReflectanceFit calibrate_reflectance(const BallView& view, const BallReflectance& metal, PixelBox in_ball,
                                     const Image& direct, PixelBox in_direct, double plateau, const std::string& what) {
  if (!(plateau > 0 && plateau < 1)) fail(ErrorKind::Value, "{}: plateau {} must lie in (0, 1)", what, plateau);
  if (view.photo.channels() < 3 || direct.channels() < 3)
    fail(ErrorKind::Value, "{}: the ball photograph and the light's image must be RGB", what);
  const BallCircle& c = view.ball;
  if (!(c.r > 0 && std::isfinite(c.cx) && std::isfinite(c.cy) && std::isfinite(c.r)))
    fail(ErrorKind::Value, "{}: the ball {},{},{} is not a circle (--ball cx,cy,r)", what, c.cx, c.cy, c.r);
  if (view.distance != 0 && !(view.distance > 1))
    fail(ErrorKind::Value, "{}: camera distance {} ball radii must exceed 1 (0: orthographic)", what, view.distance);
  BallReflectance rise = metal;
  rise.r0 = Vec3{1, 1, 1};  // at(cos θ) is then F(θ)/F(0), or 1 without the rise
  const double tan_a = view.distance > 0 ? 1 / std::sqrt(view.distance * view.distance - 1) : 0;
  const ilf::BallOptics o{1.0, view.distance};

  int x0, y0, x1, y1;
  pixel_range(in_ball, view.photo, what, "ball", &x0, &y0, &x1, &y1);
  std::vector<Sample> ball;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      double a = (x + 0.5 - c.cx) / c.r, b = (c.cy - (y + 0.5)) / c.r;
      if (a * a + b * b > 0.97 * 0.97) continue;
      double cos_t;
      if (view.distance > 0) {
        Vec3 v = normalize(Vec3{a * tan_a, b * tan_a, -1}), start, dir;
        if (!ilf::ball_reflect(o, v, &start, &dir)) continue;
        cos_t = -dot(v, start);
      } else {
        cos_t = std::sqrt(std::max(0.0, 1 - a * a - b * b));  // orthographic: the view is −Z, n = (a, b, ·)
      }
      Vec3 R = rise.at(cos_t), L = view.photo.rgb(x, y);
      if (!(std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z))) continue;
      Sample s{{L.x / R.x, L.y / R.y, L.z / R.z}, 0, std::acos(std::clamp(cos_t, -1.0, 1.0)) * 180 / kPi};
      s.lum = luminance(s.value);
      ball.push_back(s);
    }
  if (ball.empty())
    fail(ErrorKind::Value, "{}: the ball box {},{},{},{} holds no pixel inside the ball ({},{} r {})", what, in_ball.x,
         in_ball.y, in_ball.w, in_ball.h, c.cx, c.cy, c.r);
  pixel_range(in_direct, direct, what, "light", &x0, &y0, &x1, &y1);
  std::vector<Sample> lamp;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      Vec3 L = direct.rgb(x, y);
      if (std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z)) lamp.push_back({L, luminance(L), 0});
    }
  std::vector<Sample> bl = light_pixels(ball, plateau), dl = light_pixels(lamp, plateau);
  if (bl.size() < 4 || dl.size() < 4)
    fail(ErrorKind::Value,
         "{}: the light covers {} pixels in the ball's box and {} in the light's (at least 4 each): a light larger in "
         "the ball (a window, a softbox), or boxes around it",
         what, bl.size(), dl.size());
  ReflectanceFit f;
  f.light = channel_median(dl);
  if (!(f.light.x > 0 && f.light.y > 0 && f.light.z > 0))
    fail(ErrorKind::Value, "{}: the light's radiance {},{},{} is not positive in every channel", what, f.light.x,
         f.light.y, f.light.z);
  Vec3 m = channel_median(bl);
  f.r0 = {m.x / f.light.x, m.y / f.light.y, m.z / f.light.z};
  if (std::max({f.r0.x, f.r0.y, f.r0.z}) > 1.05)
    fail(ErrorKind::Value,
         "{}: the reflection is brighter than the light ({:.3g},{:.3g},{:.3g} of it): the boxes hold different lights, "
         "or the two images are not in the same units (merge both with the same curve and scale)",
         what, f.r0.x, f.r0.y, f.r0.z);
  f.ball_pixels = int(bl.size());
  f.direct_pixels = int(dl.size());
  f.incidence_min_deg = 90;
  f.incidence_max_deg = 0;
  std::vector<double> ratio;
  for (const auto& s : bl) {
    f.incidence_min_deg = std::min(f.incidence_min_deg, s.incidence_deg);
    f.incidence_max_deg = std::max(f.incidence_max_deg, s.incidence_deg);
    ratio.push_back(s.lum / luminance(f.light));
  }
  double med = quantile(ratio, 0.5);
  f.spread = med > 0 ? (quantile(ratio, 0.75) - quantile(ratio, 0.25)) / med : 0;
  return f;
}

}  // namespace ibl::capture
