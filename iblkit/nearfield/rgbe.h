// Shared-exponent 8-bit encodings of RGB: Ward's RGBE (Graphics Gems II, "Real pixels") and the
// signed sRGBE of Granier et al. 2003, Appendix A, which the paper uses to pass floating-point frame
// buffers (sums of spotlight terms that may be negative) between passes as 8-bit RGBA textures.
//
// sRGBE (Appendix A, with 8-bit storage of its [0,1] values: byte = round(255·value)):
//   e = ⌊log2 max(|R|,|G|,|B|)⌋ + 2;   [R,G,B]₈ = round(255·(rgb·2^−e + ½));   E₈ = e + 126
//   decode: rgb = ([R,G,B]₈/255 − ½) · 2^(E₈ − 126)
// Round-trip bound: rounding moves a byte by ≤ ½, so |error| ≤ 2^e/510 ≤ 4·max|c|/510 per channel
//   (since 2^e ≤ 4·max|c|): 0.78 % of the largest channel. Exponents outside 2^−125…2^129 clamp.
// RGBE: e = ⌊log2 max⌋ + 1, bytes ⌊c·256/2^e⌋, decode (byte + ½)·2^e/256: error ≤ 2^e/512 ≤ max/256
// (0.39 % of the largest channel); negative values are not representable (encoded as 0).
// Zero encodes to all-zero bytes in both (sRGBE zero decodes to (−½+…)·2^−126 ≈ 0: we special-case
// E₈ = 0 as exact zero). Both store 4 bytes per pixel instead of 12 for float RGB (a 67 % saving).
#pragma once
#include <array>
#include <cstdint>

#include "iblkit/core/vec.h"

namespace ibl::nearfield {

std::array<uint8_t, 4> encode_srgbe(Vec3 rgb);
Vec3 decode_srgbe(std::array<uint8_t, 4> v);
std::array<uint8_t, 4> encode_rgbe(Vec3 rgb);
Vec3 decode_rgbe(std::array<uint8_t, 4> v);

}  // namespace ibl::nearfield
