// RGBD (io/rgbd.h): the packing of Babylon.js's toRGBD/fromRGBD, checked against its closed forms —
// exact values at the ends of the range, the clamp above 255, and the round trip within the 8-bit
// quantisation bound (derived in rgbd.h; not a fitted tolerance: the test also checks that the bound
// is nearly reached, so it is not vacuous).
#include "iblkit/io/rgbd.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "iblkit/core/error.h"

namespace ibl::io {
namespace {

TEST(Rgbd, ExactValuesAndTheD) {
  // m ≤ 1: k = 255, plain gamma 2.2 — white is exact.
  Rgbd w = rgbd_encode({1, 1, 1});
  EXPECT_EQ(w, (Rgbd{255, 255, 255, 255}));
  EXPECT_EQ(rgbd_decode(w).x, 1.0);
  // Black: maxEps keeps m at 1e-7, so k = 255 and the colour bytes are 0.
  EXPECT_EQ(rgbd_encode({0, 0, 0}), (Rgbd{0, 0, 0, 255}));
  // k = ⌊255/m⌋: m = 2 → 127, m = 100 → 2, m = 255 → 1 (and the max channel then encodes 1·… ≤ 1).
  EXPECT_EQ(rgbd_encode({2, 0, 0})[3], 127);
  EXPECT_EQ(rgbd_encode({0, 100, 0})[3], 2);
  EXPECT_EQ(rgbd_encode({0, 0, 255})[3], 1);
  EXPECT_EQ(rgbd_encode({0, 0, 255}), (Rgbd{0, 0, 255, 1}));
  EXPECT_DOUBLE_EQ(rgbd_decode({0, 0, 255, 1}).z, 255.0);
  // g = (c k / 255)^(1/2.2): c = 0.5 with m = 1 → round(255 · 0.5^(1/2.2)) = 186.
  EXPECT_EQ(rgbd_encode({1, 0.5, 0})[1], static_cast<int>(std::lround(255 * std::pow(0.5, 1 / 2.2))));
  EXPECT_THROW(rgbd_decode({10, 10, 10, 0}), Error);
}

TEST(Rgbd, ValuesAboveTheRangeClampAt255) {
  // m > 255: k = 1 and each channel is saturate((c/255)^(1/2.2)): 255 for every channel above 255.
  Rgbd p = rgbd_encode({1000, 300, 51});
  EXPECT_EQ(p[3], 1);
  Vec3 d = rgbd_decode(p);
  EXPECT_DOUBLE_EQ(d.x, kRgbdMaxRange);
  EXPECT_DOUBLE_EQ(d.y, kRgbdMaxRange);
  EXPECT_NEAR(d.z, 51.0, rgbd_error_bound(51.0, 1));
  // Negative and NaN components are 0 (light is not negative; read_image rejects both before).
  EXPECT_EQ(rgbd_encode({-3, std::nan(""), 1}), (Rgbd{0, 0, 255, 255}));
}

TEST(Rgbd, RoundTripWithinTheQuantisationBound) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> log_m(std::log(1e-4), std::log(250.0)), frac(0.0, 1.0);
  double worst_ratio = 0, worst_rel_max = 0;
  for (int i = 0; i < 200000; ++i) {
    double m = std::exp(log_m(rng));
    Vec3 c{m, m * frac(rng), m * frac(rng) * frac(rng)};
    if (i % 3 == 1) c = {c.y, c.x, c.z};
    if (i % 3 == 2) c = {c.z, c.y, c.x};
    Rgbd p = rgbd_encode(c);
    Vec3 d = rgbd_decode(p);
    for (int a = 0; a < 3; ++a) {
      double bound = rgbd_error_bound(c[a], p[3]);
      double err = std::abs(d[a] - c[a]);
      ASSERT_LE(err, bound * (1 + 1e-9) + 1e-12) << "c = (" << c.x << ", " << c.y << ", " << c.z << "), channel " << a;
      if (bound > 0) worst_ratio = std::max(worst_ratio, err / bound);
    }
    if (m >= 1)
      worst_rel_max = std::max(worst_rel_max, std::abs(d[0] + d[1] + d[2] - c[0] - c[1] - c[2]) / (c[0] + c[1] + c[2]));
  }
  EXPECT_GT(worst_ratio, 0.5) << "the bound is far from what quantisation reaches";
  // From m = 1 to 255 the pixel keeps its relative precision: there k = ⌊255/m⌋ (unclamped) and
  // ⌊x⌋ > x/2 for x ≥ 1 gives k·m/255 > 1/2, so every channel's bound is below (255/k)·2.2/510 <
  // 2m·2.2/510, and the sum of three below 3·2·2.2/510 ≈ 2.6 % of m ≤ Σc. (Below m = 1, k is 255:
  // plain 8-bit gamma-2.2 data, whose relative precision falls with m.)
  EXPECT_LT(worst_rel_max, 3 * 2 * 2.2 / 510);
}

TEST(Rgbd, Images) {
  Image hdr(3, 2, 3);
  hdr.set_rgb(0, 0, {0.25, 0.5, 1});
  hdr.set_rgb(1, 0, {20, 5, 1});
  hdr.set_rgb(2, 0, {300, 0, 0});
  hdr.set_rgb(0, 1, {0, 0, 0});
  hdr.set_rgb(1, 1, {1e-3, 2e-3, 3e-3});
  hdr.set_rgb(2, 1, {254, 254, 254});
  Image enc = rgbd_encode_image(hdr);
  ASSERT_EQ(enc.channels(), 4);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      Rgbd p = rgbd_encode(hdr.rgb(x, y));
      for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(enc.at(x, y, c) * 255.0f, p[c]);
    }
  Image dec = rgbd_decode_image(enc);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      Vec3 want = rgbd_decode(rgbd_encode(hdr.rgb(x, y)));
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(dec.at(x, y, c), want[c], 1e-5 * std::max(1.0, want[c]));
    }
  EXPECT_THROW(rgbd_decode_image(hdr), Error);  // 3 channels
  enc.at(0, 0, 3) = 0;
  EXPECT_THROW(rgbd_decode_image(enc), Error);  // d = 0
}

}  // namespace
}  // namespace ibl::io
