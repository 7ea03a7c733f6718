#include "iblkit/capture/sensor.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/core/rng.h"

namespace ibl::capture {

void validate(const SensorDesc& s) {
  auto positive = [](const char* what, double v, double hi) {
    if (!(std::isfinite(v) && v > 0 && v <= hi))
      fail(ErrorKind::Value, "sensor: {} = {} must lie in (0, {:g}]", what, v, hi);
  };
  positive("exposure time (s)", s.exposure_s, 1e6);
  positive("f-number", s.f_number, 1e4);
  positive("ISO", s.iso, 1e7);
  for (int c = 0; c < 3; ++c) positive("white-balance gain", s.wb_gains[c], 1e3);
  if (!(std::isfinite(s.full_well) && s.full_well >= 0 && s.full_well <= 1e9))
    fail(ErrorKind::Value, "sensor: full well {} must lie in [0, 1e9] electrons (0: no shot noise)", s.full_well);
  if (!(std::isfinite(s.read_noise) && s.read_noise >= 0 && s.read_noise <= 1))
    fail(ErrorKind::Value, "sensor: read noise {} must lie in [0, 1] (units of saturation)", s.read_noise);
  if (!(s.vignetting >= 0 && s.vignetting < 1))
    fail(ErrorKind::Value, "sensor: vignetting {} must lie in [0, 1)", s.vignetting);
  if (s.bits != 8 && s.bits != 16) fail(ErrorKind::Value, "sensor: bit depth {} must be 8 or 16", s.bits);
  s.response.validate("sensor response");
}

Image expose(const Image& radiance, const SensorDesc& s) {
  validate(s);
  if (radiance.empty()) fail(ErrorKind::Value, "sensor: the radiance image is empty");
  const int w = radiance.width(), h = radiance.height(), nc = radiance.channels();
  Image out(w, h, 3);
  const double k = s.exposure_factor();
  const double electrons = s.full_well * 100.0 / s.iso;
  const double levels = std::exp2(s.bits) - 1;
  const double cx = 0.5 * w, cy = 0.5 * h, r2max = cx * cx + cy * cy;
  const uint64_t seed_key = mix64(s.seed);
  parallel_for(
      0, h,
      [&](int64_t y) {
        for (int x = 0; x < w; ++x) {
          const float* in = radiance.pixel(x, static_cast<int>(y));
          const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
          const double v = 1.0 - s.vignetting * (dx * dx + dy * dy) / r2max;
          const uint64_t pix = static_cast<uint64_t>(y) * w + x;
          Rng rng(mix64(seed_key ^ pix));
          for (int c = 0; c < 3; ++c) {
            const double L = in[nc >= 3 ? c : 0];
            if (!(std::isfinite(L) && L >= 0))
              fail(ErrorKind::Value, "sensor: radiance at pixel ({}, {}) channel {} is {}: must be finite and >= 0", x,
                   y, c, L);
            double X = L * k * s.wb_gains[c] * v;
            // Both normals are drawn for every pixel, so each pixel's noise is the same whatever the settings.
            const double n_shot = rng.normal(), n_read = rng.normal();
            if (electrons > 0) X += std::sqrt(std::min(X, 1.0) / electrons) * n_shot;
            X += s.read_noise * n_read;
            const double z = s.response.apply(std::clamp(X, 0.0, 1.0), c);
            out.pixel(x, static_cast<int>(y))[c] = static_cast<float>(std::round(z * levels) / levels);
          }
        }
      },
      4);
  return out;
}

}  // namespace ibl::capture
