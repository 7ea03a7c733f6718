#include "iblkit/io/rgbd.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"

namespace ibl::io {

namespace {
constexpr double kGamma = 2.2;     // Babylon's LinearEncodePowerApprox
constexpr double kEpsilon = 1e-7;  // its maxEps floor of max(r, g, b)

double clean(double v) { return std::isfinite(v) && v > 0 ? v : 0.0; }
std::uint8_t byte_of(float v) { return static_cast<std::uint8_t>(std::clamp(std::lround(v * 255.0), 0L, 255L)); }
}  // namespace

Rgbd rgbd_encode(Vec3 c) {
  const double r = clean(c.x), g = clean(c.y), b = clean(c.z);
  const double m = std::max({r, g, b, kEpsilon});
  const double k = std::clamp(std::floor(std::max(kRgbdMaxRange / m, 1.0)), 1.0, 255.0);
  auto channel = [&](double v) {
    double e = std::clamp(std::pow(v * k / 255.0, 1.0 / kGamma), 0.0, 1.0);
    return static_cast<std::uint8_t>(std::lround(e * 255.0));
  };
  return {channel(r), channel(g), channel(b), static_cast<std::uint8_t>(k)};
}

Vec3 rgbd_decode(const Rgbd& p) {
  if (p[3] == 0) fail(ErrorKind::Value, "RGBD pixel ({}, {}, {}, 0): d = 0 is not RGBD", p[0], p[1], p[2]);
  const double scale = 255.0 / p[3];
  auto channel = [&](std::uint8_t v) { return std::pow(v / 255.0, kGamma) * scale; };
  return {channel(p[0]), channel(p[1]), channel(p[2])};
}

double rgbd_error_bound(double c, int k) {
  const double g = std::min(1.0, std::pow(std::max(c, 0.0) * k / 255.0, 1.0 / kGamma));
  return (255.0 / k) * kGamma * std::pow(std::min(1.0, g + 1.0 / 510.0), kGamma - 1.0) / 510.0;
}

Image rgbd_encode_image(const Image& radiance) {
  if (radiance.channels() < 3) fail(ErrorKind::Value, "RGBD encoding needs RGB (got {} channels)", radiance.channels());
  Image out(radiance.width(), radiance.height(), 4);
  for (int y = 0; y < radiance.height(); ++y)
    for (int x = 0; x < radiance.width(); ++x) {
      Rgbd p = rgbd_encode(radiance.rgb(x, y));
      for (int c = 0; c < 4; ++c) out.at(x, y, c) = p[c] / 255.0f;
    }
  return out;
}

Image rgbd_decode_image(const Image& rgbd) {
  if (rgbd.channels() != 4) fail(ErrorKind::Value, "RGBD decoding needs 4 channels (got {})", rgbd.channels());
  Image out(rgbd.width(), rgbd.height(), 3);
  for (int y = 0; y < rgbd.height(); ++y)
    for (int x = 0; x < rgbd.width(); ++x) {
      const float* p = rgbd.pixel(x, y);
      Rgbd q{byte_of(p[0]), byte_of(p[1]), byte_of(p[2]), byte_of(p[3])};
      if (q[3] == 0) fail(ErrorKind::Value, "RGBD image: pixel ({}, {}) has d = 0 (not RGBD data)", x, y);
      out.set_rgb(x, y, rgbd_decode(q));
    }
  return out;
}

}  // namespace ibl::io
