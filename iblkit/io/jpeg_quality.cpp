#include "iblkit/io/jpeg_quality.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <vector>

namespace ibl::io {

namespace {

// ITU-T T.81 Annex K, Table K.1: luminance quantisation, natural order.
constexpr int kLuminance[64] = {16, 11, 10, 16, 24,  40,  51,  61,  12, 12, 14, 19, 26,  58,  60,  55,
                                14, 13, 16, 24, 40,  57,  69,  56,  14, 17, 22, 29, 51,  87,  80,  62,
                                18, 22, 37, 56, 68,  109, 103, 77,  24, 35, 55, 64, 81,  104, 113, 92,
                                49, 64, 78, 87, 103, 121, 120, 101, 72, 92, 95, 98, 112, 100, 103, 99};

// The zig-zag order of T.81 Figure A.6: entry k of a DQT segment is natural index kZigzag[k].
constexpr int kZigzag[64] = {0,  1,  8,  16, 9,  2,  3,  10, 17, 24, 32, 25, 18, 11, 4,  5,  12, 19, 26, 33, 40, 48,
                             41, 34, 27, 20, 13, 6,  7,  14, 21, 28, 35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23,
                             30, 37, 44, 51, 58, 59, 52, 45, 38, 31, 39, 46, 53, 60, 61, 54, 47, 55, 62, 63};

}  // namespace

int jpeg_quality_of_table(const int table[64]) {
  bool any = false;
  for (int i = 0; i < 64; ++i) any = any || table[i] > 0;
  if (!any) return 0;
  int best = 0;
  long best_err = -1;
  for (int q = 1; q <= 100; ++q) {
    const int s = q < 50 ? 5000 / q : 200 - 2 * q;
    long err = 0;
    for (int i = 0; i < 64; ++i) err += std::abs(std::clamp((kLuminance[i] * s + 50) / 100, 1, 255) - table[i]);
    if (best_err < 0 || err < best_err) {
      best_err = err;
      best = q;
    }
  }
  return best;
}

int estimate_jpeg_quality(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return 0;
  auto byte = [&f]() -> int {
    const int c = f.get();
    return c == std::char_traits<char>::eof() ? -1 : c;
  };
  if (byte() != 0xFF || byte() != 0xD8) return 0;  // SOI
  for (int segments = 0; segments < 1000; ++segments) {
    int b = byte();
    while (b == 0xFF) b = byte();  // fill bytes
    if (b < 0) return 0;
    const int marker = b;
    if (marker == 0xD9 || marker == 0xDA) return 0;  // EOI or start of scan: no table before the data
    const int hi = byte(), lo = byte();
    if (hi < 0 || lo < 0) return 0;
    int length = (hi << 8 | lo) - 2;
    if (length < 0) return 0;
    if (marker != 0xDB) {  // not DQT: skip it
      f.seekg(length, std::ios::cur);
      if (!f) return 0;
      continue;
    }
    while (length > 0) {
      const int pq_tq = byte();
      if (pq_tq < 0) return 0;
      const int precision = pq_tq >> 4, id = pq_tq & 15;
      int table[64];
      for (int k = 0; k < 64; ++k) {
        int v = byte();
        if (precision == 1) v = v << 8 | byte();
        if (v < 0) return 0;
        table[kZigzag[k]] = v;
      }
      length -= 1 + 64 * (precision == 1 ? 2 : 1);
      if (id == 0) return jpeg_quality_of_table(table);
    }
  }
  return 0;
}

}  // namespace ibl::io
