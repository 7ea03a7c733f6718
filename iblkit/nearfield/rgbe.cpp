#include "iblkit/nearfield/rgbe.h"

#include <algorithm>
#include <cmath>

namespace ibl::nearfield {

namespace {
uint8_t byte_of(double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }
}  // namespace

std::array<uint8_t, 4> encode_srgbe(Vec3 c) {
  const double m = std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z)});
  if (!(m > 0) || !std::isfinite(m)) return {0, 0, 0, 0};
  int e = static_cast<int>(std::floor(std::log2(m))) + 2;
  e = std::clamp(e, -125, 129);  // E₈ = e + 126 in 1..255
  const double s = std::ldexp(1.0, -e);
  return {byte_of(255 * (c.x * s + 0.5)), byte_of(255 * (c.y * s + 0.5)), byte_of(255 * (c.z * s + 0.5)),
          static_cast<uint8_t>(e + 126)};
}

Vec3 decode_srgbe(std::array<uint8_t, 4> v) {
  if (v[3] == 0) return {0, 0, 0};
  const double s = std::ldexp(1.0, v[3] - 126);
  return Vec3{v[0] / 255.0 - 0.5, v[1] / 255.0 - 0.5, v[2] / 255.0 - 0.5} * s;
}

std::array<uint8_t, 4> encode_rgbe(Vec3 c) {
  const double m = std::max({c.x, c.y, c.z});
  if (!(m > 1e-38) || !std::isfinite(m)) return {0, 0, 0, 0};
  int e;
  const double f = std::frexp(m, &e);  // m = f·2^e, f in [½, 1)
  (void)f;
  const double s = std::ldexp(256.0, -e);
  auto q = [&](double x) {
    return static_cast<uint8_t>(std::clamp(static_cast<long>(std::max(0.0, x) * s), 0L, 255L));
  };
  return {q(c.x), q(c.y), q(c.z), static_cast<uint8_t>(std::clamp(e + 128, 0, 255))};
}

Vec3 decode_rgbe(std::array<uint8_t, 4> v) {
  if (v[3] == 0) return {0, 0, 0};
  const double s = std::ldexp(1.0, v[3] - 128 - 8);
  return Vec3{v[0] + 0.5, v[1] + 0.5, v[2] + 0.5} * s;
}

}  // namespace ibl::nearfield
