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

namespace {

// Calls emit(x, y, c, X) with every pixel's and channel's noisy relative exposure X (not clamped), the
// white-balance gains applied when `wb`.
template <typename Emit>
void sense(const Image& radiance, const SensorDesc& s, bool wb, Emit emit) {
  validate(s);
  if (radiance.empty()) fail(ErrorKind::Value, "sensor: the radiance image is empty");
  const int w = radiance.width(), h = radiance.height(), nc = radiance.channels();
  const double k = s.exposure_factor();
  const double electrons = s.full_well * 100.0 / s.iso;
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
            double X = L * k * (wb ? s.wb_gains[c] : 1.0) * v;
            // Both normals are drawn for every pixel, so each pixel's noise is the same whatever the settings.
            const double n_shot = rng.normal(), n_read = rng.normal();
            if (electrons > 0) X += std::sqrt(std::min(X, 1.0) / electrons) * n_shot;
            X += s.read_noise * n_read;
            emit(x, static_cast<int>(y), c, X);
          }
        }
      },
      4);
}

}  // namespace

Image expose(const Image& radiance, const SensorDesc& s) {
  Image out(radiance.width(), radiance.height(), 3);
  const double levels = std::exp2(s.bits) - 1;
  sense(radiance, s, true, [&](int x, int y, int c, double X) {
    const double z = s.response.apply(std::clamp(X, 0.0, 1.0), c);
    out.pixel(x, y)[c] = static_cast<float>(std::round(z * levels) / levels);
  });
  return out;
}

Image olpf_blur(const Image& radiance) {
  const int w = radiance.width(), h = radiance.height(), nc = radiance.channels();
  Image across(w, h, nc), out(w, h, nc);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < nc; ++c)
        across.at(x, y, c) = 0.25f * radiance.at(std::max(x - 1, 0), y, c) + 0.5f * radiance.at(x, y, c) +
                             0.25f * radiance.at(std::min(x + 1, w - 1), y, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < nc; ++c)
        out.at(x, y, c) = 0.25f * across.at(x, std::max(y - 1, 0), c) + 0.5f * across.at(x, y, c) +
                          0.25f * across.at(x, std::min(y + 1, h - 1), c);
  return out;
}

std::vector<uint16_t> expose_raw(const Image& radiance_in, const SensorDesc& s, const RawSensor& r) {
  const Image blurred = r.mosaic && r.olpf && !radiance_in.empty() ? olpf_blur(radiance_in) : Image();
  const Image& radiance = blurred.empty() ? radiance_in : blurred;
  if (!(r.black >= 0 && r.black < r.white && r.white <= 65535))
    fail(ErrorKind::Value, "sensor: black level {} and white level {}: need 0 <= black < white <= 65535", r.black,
         r.white);
  const int w = radiance.width(), h = radiance.height();
  if (w % 2 || h % 2) fail(ErrorKind::Value, "sensor: a raw mosaic needs an even size, not {}x{}", w, h);
  std::vector<uint16_t> out(static_cast<size_t>(w) * h * (r.mosaic ? 1 : 3));
  const double span = r.white - r.black;
  sense(radiance, s, false, [&](int x, int y, int c, double X) {
    const auto v = static_cast<uint16_t>(std::lround(r.black + std::clamp(X, 0.0, 1.0) * span));
    const size_t pixel = static_cast<size_t>(y) * w + x;
    if (!r.mosaic)
      out[3 * pixel + c] = v;
    else if ((y & 1) + (x & 1) == c)  // R G / G B: 0 red, 1 green, 2 blue
      out[pixel] = v;
  });
  return out;
}

io::DngDesc expose_dng(const Image& radiance, const SensorDesc& s, const RawSensor& r, const io::PhotoMeta& meta) {
  io::DngDesc d;
  d.cfa = expose_raw(radiance, s, r);
  d.width = radiance.width(), d.height = radiance.height();
  d.black = r.black, d.white = r.white;
  d.mosaic = r.mosaic;
  for (int c = 0; c < 3; ++c) d.as_shot_neutral[c] = s.wb_gains[1] / s.wb_gains[c];
  d.meta = meta;
  d.meta.exposure_time = s.exposure_s, d.meta.f_number = s.f_number, d.meta.iso = s.iso;
  return d;
}

}  // namespace ibl::capture
