#include "iblkit/io/tonemap.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "iblkit/core/check.h"
#include "iblkit/core/parallel.h"

namespace ibl::io {

double auto_exposure_scale(const Image& img, double key) {
  std::vector<float> lum;
  lum.reserve(img.pixel_count());
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      float l = static_cast<float>(luminance(img.rgb(x, y)));
      if (l > 0) lum.push_back(l);
    }
  if (lum.empty()) return 1.0;
  auto mid = lum.begin() + static_cast<ptrdiff_t>(lum.size() / 2);
  std::nth_element(lum.begin(), mid, lum.end());
  return *mid > 0 ? key / *mid : 1.0;
}

namespace {
// Narkowicz 2015, "ACES Filmic Tone Mapping Curve": a fit of the ACES RRT+ODT.
inline double aces(double x) {
  constexpr double a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
  return std::clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0);
}
}  // namespace

Image tonemap(const Image& img, const ToneMapDesc& desc) {
  require_number("tone map: exposure (stops)", desc.exposure_stops, -64, 64);
  if (!(desc.key > 0) || !std::isfinite(desc.key))
    fail(ErrorKind::Value, "tone map: key {} must be a finite number > 0", desc.key);
  double scale = (desc.auto_exposure ? auto_exposure_scale(img, desc.key) : 1.0) * std::exp2(desc.exposure_stops);
  Image out(img.width(), img.height(), 3);
  parallel_for(0, img.height(), [&](int64_t y) {
    for (int x = 0; x < img.width(); ++x) {
      Vec3 c = img.rgb(x, static_cast<int>(y)) * scale;
      switch (desc.curve) {
        case ToneCurve::Clamp:
          break;
        case ToneCurve::Reinhard: {
          // Reinhard et al. 2002 on luminance, so hues are kept.
          double l = luminance(c);
          if (l > 0) c = c * (1.0 / (1.0 + l));
          break;
        }
        case ToneCurve::Aces:
          c = {aces(c.x), aces(c.y), aces(c.z)};
          break;
      }
      out.set_rgb(x, static_cast<int>(y),
                  {std::clamp(c.x, 0.0, 1.0), std::clamp(c.y, 0.0, 1.0), std::clamp(c.z, 0.0, 1.0)});
    }
  });
  return out;
}

Image false_colour(const Image& values, double vmax) {
  // Piecewise-linear ramp through five stops, in sRGB-looking steps (converted to linear below).
  static const Vec3 kStops[] = {{0, 0, 0}, {0.1, 0.2, 0.9}, {0.1, 0.8, 0.3}, {1.0, 0.9, 0.1}, {0.9, 0.1, 0.1}};
  Image out(values.width(), values.height(), 3);
  for (int y = 0; y < values.height(); ++y)
    for (int x = 0; x < values.width(); ++x) {
      double v = values.at(x, y, 0);
      Vec3 c{0.5, 0.5, 0.5};
      if (std::isfinite(v) && v >= 0) {
        double t = std::clamp(vmax > 0 ? v / vmax : 0.0, 0.0, 1.0) * 4;
        int i = std::min(3, static_cast<int>(t));
        double f = t - i;
        c = kStops[i] * (1 - f) + kStops[i + 1] * f;
      }
      // sRGB-looking stops to linear light (PNG writing encodes again).
      for (int k = 0; k < 3; ++k) c[k] = std::pow(c[k], 2.2);
      out.set_rgb(x, y, c);
    }
  return out;
}

}  // namespace ibl::io
