// RGBD: HDR radiance packed into four 8-bit channels, as Babylon.js writes and reads it (its
// `toRGBD` / `fromRGBD`, the packing that EXT_lights_image_based prescribes for 4-channel PNGs).
// docs/conventions.md ("RGBD") records where each rule comes from in Babylon's source.
//
// Encoding of a linear RGB value c (negative or NaN components taken as 0):
//   m = max(c_r, c_g, c_b, 1e-7)
//   k = clamp(⌊255 / m⌋, 1, 255)                   (Babylon: D = saturate(⌊max(255/m, 1)⌋ / 255))
//   g = clamp((c · k/255)^(1/2.2), 0, 1)            (its gamma: pow 1/2.2, not the sRGB curve)
//   bytes = (round(255 g_r), round(255 g_g), round(255 g_b), k)
// Decoding: c' = (byte/255)^2.2 / (k/255).
//
// Range: values up to 255 in every channel; above it a channel decodes as 255 (k = 1, g clamped at
// 1). Values with m ≤ 1 have k = 255: plain gamma-2.2 8-bit data. Quantisation error, per channel,
// from |round(255 g)/255 − g| ≤ 1/510 and the slope of x^2.2 (rgbd_error_bound):
//   |c' − c| ≤ (255/k) · 2.2 · min(1, g + 1/510)^1.2 / 510.
#pragma once
#include <array>
#include <cstdint>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"

namespace ibl::io {

// Babylon's rgbdMaxRange: the largest value RGBD holds.
inline constexpr double kRgbdMaxRange = 255.0;

using Rgbd = std::array<std::uint8_t, 4>;  // r, g, b (gamma 2.2 of c·k/255), d = k

Rgbd rgbd_encode(Vec3 c);
// Throws ibl::Error (Value) when d is 0 (no RGBD encoder writes it; Babylon would divide by 0).
Vec3 rgbd_decode(const Rgbd& p);
// The bound above for channel value c (≥ 0) of a pixel whose d byte is k; for c beyond the range
// (c·k/255 > 1) it bounds the distance to the clamped value.
double rgbd_error_bound(double c, int k);

// Whole images. rgbd_encode_image: RGB (or more channels; the first three are used) → 4 channels
// holding byte/255 exactly (what io::write_image with WriteDesc::data stores as the same bytes).
// rgbd_decode_image: 4 channels of byte/255 (values are rounded to the nearest byte) → RGB.
Image rgbd_encode_image(const Image& radiance);
Image rgbd_decode_image(const Image& rgbd);

}  // namespace ibl::io
