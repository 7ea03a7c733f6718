#include "iblkit/capture/merge.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "iblkit/capture/sensor.h"
#include "iblkit/core/error.h"
#include "iblkit/core/rng.h"

namespace ibl::capture {
namespace {

// A radiance image spanning 14 stops left to right (2^-10 .. 2^4), with texture and a tint.
Image test_radiance(int w, int h) {
  Image L(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double base = std::exp2(-10 + 14.0 * (x + 0.5) / w);
      const double tex = 0.55 + 0.45 * std::sin(0.37 * x + 1.3 * std::sin(0.11 * y)) * std::cos(0.23 * y);
      const double tint[3] = {1.0, 0.8, 0.6};
      for (int c = 0; c < 3; ++c) L.at(x, y, c) = static_cast<float>(base * tex * tint[c]);
    }
  return L;
}

// A ramp of 8 stops times value noise (random values on a 7-pixel lattice, bilinear): a scene with
// no period, as Ward's alignment needs.
Image noise_radiance(int w, int h) {
  const int cell = 7, gw = w / cell + 2, gh = h / cell + 2;
  std::vector<double> lattice(static_cast<size_t>(gw) * gh);
  Rng rng(12345);
  for (double& v : lattice) v = rng.uniform();
  Image L(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double fx = double(x) / cell, fy = double(y) / cell;
      const int i = static_cast<int>(fx), j = static_cast<int>(fy);
      const double a = fx - i, b = fy - j;
      auto at = [&](int u, int v) { return lattice[size_t(v) * gw + u]; };
      const double n = (1 - a) * (1 - b) * at(i, j) + a * (1 - b) * at(i + 1, j) + (1 - a) * b * at(i, j + 1) +
                       a * b * at(i + 1, j + 1);
      const double v = std::exp2(-4 + 8.0 * x / w) * (0.1 + 0.9 * n);
      L.set_rgb(x, y, {v, v * 0.9, v * 0.8});
    }
  return L;
}

// Five exposures 2 EV apart: Δ = 2^-8 … 2^0 (times of 1/256 s … 1 s at f/1, ISO 100).
constexpr int kFrames = 5;
double exposure_of(int j) { return std::exp2(2.0 * j - 8); }

SensorDesc noisy_sensor(const Response& r, int j) {
  SensorDesc s;
  s.exposure_s = exposure_of(j);
  s.response = r;
  // A DSLR-like sensor: 30000 photo-electrons at saturation, read noise 1/3000 of full scale
  // (an engineering dynamic range of 11.6 stops).
  s.full_well = 30000;
  s.read_noise = 3e-4;
  s.seed = 100 + j;
  return s;
}

std::vector<Frame> shoot(const Image& L, const Response& r) {
  std::vector<Frame> f;
  for (int j = 0; j < kFrames; ++j)
    f.push_back({expose(L, noisy_sensor(r, j)), exposure_of(j), "frame" + std::to_string(j)});
  return f;
}

// max over z in [0.05, 0.95] of |s·recovered(z) / true(z) − 1|, s the one scale that the bracket
// cannot observe (geometric mean of the ratio), per channel.
double curve_error(const Response& rec, const Response& truth, double* scale) {
  double worst = 0;
  for (int c = 0; c < 3; ++c) {
    double sl = 0;
    int n = 0;
    for (double z = 0.05; z <= 0.95 + 1e-9; z += 0.005, ++n) sl += std::log(truth.invert(z, c) / rec.invert(z, c));
    const double s = std::exp(sl / n);
    if (c == 1 && scale) *scale = s;
    for (double z = 0.05; z <= 0.95 + 1e-9; z += 0.005) {
      worst = std::max(worst, std::abs(s * rec.invert(z, c) / truth.invert(z, c) - 1));
    }
  }
  return worst;
}

// Median relative error of s·merged against the radiance over pixels well exposed (true X in
// [0.05, 0.95] in every channel) in at least one frame.
double merge_error(const Image& merged, const Image& L, double s) {
  std::vector<double> e;
  for (int y = 0; y < L.height(); ++y)
    for (int x = 0; x < L.width(); ++x) {
      bool ok = false;
      for (int j = 0; j < kFrames && !ok; ++j) {
        bool all = true;
        for (int c = 0; c < 3; ++c) {
          const double X = L.at(x, y, c) * exposure_of(j);
          all = all && X >= 0.05 && X <= 0.95;
        }
        ok = all;
      }
      if (!ok) continue;
      for (int c = 0; c < 3; ++c) e.push_back(std::abs(s * merged.at(x, y, c) / L.at(x, y, c) - 1));
    }
  EXPECT_GT(e.size(), L.size() / 4);
  std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
  return e[e.size() / 2];
}

constexpr double kCurveTol = 0.02;  // issue 29: within 2 % of the true curve on [0.05, 0.95]
constexpr double kMergeTol = 0.02;  // issue 29: median relative error <= 2 %

TEST(HdrMerge, DebevecRecoversTheCameraCurveAndTheRadiance) {
  const Image L = test_radiance(320, 240);
  const Response truth = camera_response();
  const auto frames = shoot(L, truth);
  MergeDesc d;
  d.align = false;
  MergeReport rep;
  const Image m = merge_hdr(frames, d, &rep);
  double s = 1;
  const double ce = curve_error(rep.response, truth, &s);
  // 2.65 % at the default smoothness (κ = 5, chosen on 14 held-out probe brackets, JPEG and PNG:
  // bench/hdr_smoothness_cv.py), which bends this curve's shoulder a little more than κ = 1 did (1.7 %) while it
  // takes the JPEG benchmark from 6.25 % to 4.52 % and the PNG one from 1.16 % to 0.84 %.
  constexpr double kCameraCurveTol = 0.03;
  EXPECT_LT(ce, kCameraCurveTol);
  const double me = merge_error(m, L, s);
  EXPECT_LT(me, kMergeTol);
  std::printf("debevec camera curve: curve error %.4f, merge error %.4f, scale %.4f, noise %.4f, DR %.2f stops\n", ce,
              me, s, rep.noise, rep.dynamic_range_stops);
  EXPECT_EQ(rep.response.kind, "debevec");
  EXPECT_EQ(rep.response.size(), 256);
  for (size_t i = 0; i < m.size(); ++i) ASSERT_TRUE(std::isfinite(m.data()[i]));
}

TEST(HdrMerge, DebevecRecoversSrgb) {
  const Image L = test_radiance(320, 240);
  const Response truth = srgb_response();
  MergeDesc d;
  d.align = false;
  MergeReport rep;
  const Image m = merge_hdr(shoot(L, truth), d, &rep);
  double s = 1;
  EXPECT_LT(curve_error(rep.response, truth, &s), kCurveTol);
  EXPECT_LT(merge_error(m, L, s), kMergeTol);
}

TEST(HdrMerge, RobertsonRecoversTheCameraCurve) {
  const Image L = test_radiance(320, 240);
  const Response truth = camera_response();
  MergeDesc d;
  d.align = false;
  d.method = "robertson";
  MergeReport rep;
  const Image m = merge_hdr(shoot(L, truth), d, &rep);
  double s = 1;
  const double ce = curve_error(rep.response, truth, &s);
  const double me = merge_error(m, L, s);
  std::printf("robertson camera curve: curve error %.4f, merge error %.4f\n", ce, me);
  // Robertson's iteration has no smoothness term: on a bracket of one constant ratio it drifts from its
  // start (Debevec's curve, 2.65 % here) along the ratio's ambiguity (docs/capture.md).
  constexpr double kRobertsonCurveTol = 0.05;  // 4.2 % from Debevec's curve at κ = 5 (3.0 % from κ = 1's)
  EXPECT_LT(ce, kRobertsonCurveTol);
  EXPECT_LT(me, kMergeTol);
  EXPECT_EQ(rep.response.kind, "robertson");
}

TEST(HdrMerge, KnownResponseGivesAbsoluteRadiance) {
  // With the true curve nothing is left to scale: 1 s at f/1, ISO 100 is 1.
  const Image L = test_radiance(320, 240);
  const Response truth = camera_response();
  MergeDesc d;
  d.align = false;
  d.response = truth;
  const Image m = merge_hdr(shoot(L, truth), d);
  EXPECT_LT(merge_error(m, L, 1.0), 0.01);  // quantisation and noise only
}

TEST(HdrMerge, SaturatedAndBlackEverywhereAreCountedAndBounded) {
  Image L = test_radiance(200, 100);
  for (int y = 10; y < 30; ++y)
    for (int x = 100; x < 140; ++x) L.set_rgb(x, y, {1e5, 1e5, 1e5});  // 800 pixels brighter than any frame holds
  for (int y = 60; y < 70; ++y)
    for (int x = 0; x < 30; ++x) L.set_rgb(x, y, {0, 0, 0});  // 300 black pixels
  const Response truth = srgb_response();
  MergeDesc d;
  d.align = false;
  d.response = truth;
  MergeReport rep;
  std::vector<Frame> frames;
  for (int j = 0; j < kFrames; ++j) {
    SensorDesc s;
    s.exposure_s = exposure_of(j);
    s.response = truth;
    frames.push_back({expose(L, s), exposure_of(j), "f"});
  }
  const Image m = merge_hdr(frames, d, &rep);
  // The left end of the ramp (2^-10 .. ) is black in the brightest frame too: count those exactly.
  int64_t black = 0, sat = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 200; ++x) {
      bool b = false, s = false;
      for (int c = 0; c < 3; ++c) {
        bool all_b = true, all_s = true;
        for (const Frame& f : frames) {
          all_b = all_b && f.codes.at(x, y, c) <= kBlackCode;
          all_s = all_s && f.codes.at(x, y, c) >= kSaturatedCode;
        }
        b = b || all_b, s = s || all_s;
      }
      black += b, sat += s;
    }
  EXPECT_EQ(rep.saturated_everywhere, sat);
  EXPECT_EQ(rep.black_everywhere, black);
  EXPECT_GE(sat, 800);
  EXPECT_GE(black, 300);
  // The saturated block gets the darkest exposure's bound: code 1 at Δ = 2^-8.
  EXPECT_FLOAT_EQ(m.at(120, 20, 1), 256.0f);
  EXPECT_FLOAT_EQ(m.at(10, 65, 0), 0.0f);
  for (size_t i = 0; i < m.size(); ++i) ASSERT_TRUE(std::isfinite(m.data()[i]));
}

TEST(HdrMerge, WardAlignmentFindsTheShifts) {
  const Image big = noise_radiance(360, 280);
  const int off[kFrames][2] = {{20, 20}, {23, 18}, {20, 20}, {14, 27}, {31, 9}};
  const Response truth = srgb_response();
  std::vector<Frame> frames;
  for (int j = 0; j < kFrames; ++j) {
    const Image L = big.crop(off[j][0], off[j][1], 320, 240);
    frames.push_back({expose(L, noisy_sensor(truth, j)), exposure_of(j), "f"});
  }
  MergeDesc d;
  d.response = truth;
  MergeReport rep;
  merge_hdr(frames, d, &rep);
  ASSERT_EQ(rep.shifts.size(), size_t(kFrames));
  const int r = rep.reference;
  for (int j = 0; j < kFrames; ++j) {
    constexpr int kShiftTol = 1;  // Ward's bitmaps find the shift to a pixel; the chain may add one at the ends
    EXPECT_NEAR(rep.shifts[j][0], off[r][0] - off[j][0], kShiftTol) << "frame " << j;
    EXPECT_NEAR(rep.shifts[j][1], off[r][1] - off[j][1], kShiftTol) << "frame " << j;
  }
}

TEST(HdrMerge, GreyCardSetsScaleAndWhiteBalance) {
  Image L = test_radiance(200, 100);
  for (int y = 40; y < 60; ++y)
    for (int x = 90; x < 110; ++x) L.set_rgb(x, y, {0.05, 0.05, 0.05});  // a neutral card
  const Response truth = srgb_response();
  std::vector<Frame> frames;
  for (int j = 0; j < kFrames; ++j) {
    SensorDesc s = noisy_sensor(truth, j);
    s.wb_gains = {1.6, 1.0, 0.7};
    frames.push_back({expose(L, s), exposure_of(j), "f"});
  }
  MergeDesc d;
  d.align = false;
  d.response = truth;
  d.grey_card = std::array<int, 4>{92, 42, 16, 16};
  d.reflectance = 0.18;
  MergeReport rep;
  const Image m = merge_hdr(frames, d, &rep);
  Vec3 mean{0, 0, 0};
  for (int y = 42; y < 58; ++y)
    for (int x = 92; x < 108; ++x) mean = mean + m.rgb(x, y) / 256.0;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], 0.18, 1e-5);
  // The white balance undoes the sensor's gains: factor 0.18 / 0.05 / gain_c.
  constexpr double kGainTol = 0.01;
  EXPECT_NEAR(rep.gains.x * 1.6 / 3.6, 1.0, kGainTol);
  EXPECT_NEAR(rep.gains.z * 0.7 / 3.6, 1.0, kGainTol);
  d.grey_card = std::array<int, 4>{190, 90, 20, 20};
  EXPECT_THROW(merge_hdr(frames, d), Error);
}

TEST(HdrMerge, BadBracketsAreRefusedNamingTheFile) {
  const Image L = test_radiance(64, 32);
  auto frames = shoot(L, srgb_response());
  MergeDesc d;
  auto message = [&](const std::vector<Frame>& f) {
    try {
      merge_hdr(f, d);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({frames[0]}).find("one photograph"), std::string::npos);
  auto sizes = frames;
  sizes[3].codes = sizes[3].codes.crop(0, 0, 60, 32);
  EXPECT_NE(message(sizes).find("frame3: 60x32"), std::string::npos) << message(sizes);
  auto same = frames;
  for (auto& f : same) f.exposure = 0.5;
  EXPECT_NE(message(same).find("--exposures"), std::string::npos);
  auto white = frames;
  for (auto& f : white) f.codes = Image(64, 32, 3, 1.0f);
  EXPECT_NE(message(white).find("frame0: even the darkest photograph is saturated"), std::string::npos)
      << message(white);
}

}  // namespace
}  // namespace ibl::capture
