#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "iblkit/capture/response.h"
#include "iblkit/capture/sensor.h"
#include "iblkit/core/error.h"

namespace ibl::capture {
namespace {

TEST(Response, BuiltinCurvesAreTheirClosedForms) {
  const Response s = srgb_response(), l = linear_response(), cam = camera_response(0.8, -2.5);
  constexpr double kTableTol = 2e-6;  // linear interpolation of a 4096-entry table of a smooth curve
  for (double z = 0; z <= 1.0; z += 0.013) {
    const double srgb = z <= 0.04045 ? z / 12.92 : std::pow((z + 0.055) / 1.055, 2.4);
    EXPECT_NEAR(s.invert(z, 1), srgb, kTableTol);
    EXPECT_NEAR(l.invert(z, 2), z, 1e-12);
  }
  // The camera curve: z(x) = σ(0.8 (log2 x + 2.5)) / σ(2), at x = 1/4 (two stops under saturation).
  auto sig = [](double t) { return 1 / (1 + std::exp(-t)); };
  EXPECT_NEAR(cam.apply(0.25, 0), sig(0.8 * 0.5) / sig(2.0), 1e-5);
  EXPECT_DOUBLE_EQ(cam.apply(1.0, 0), 1.0);
  EXPECT_DOUBLE_EQ(cam.apply(0.0, 0), 0.0);
  // A toe: below the midpoint the slope dz/dlog2x rises; a shoulder: above it the slope falls.
  auto slope = [&](double stops) {
    return cam.apply(std::exp2(stops + 0.05), 0) - cam.apply(std::exp2(stops - 0.05), 0);
  };
  EXPECT_LT(slope(-6), slope(-2.5));
  EXPECT_LT(slope(-0.2), slope(-2.5));
}

TEST(Response, ApplyAndInvertAreInverses) {
  for (const Response& r : {srgb_response(), camera_response(), linear_response(256)})
    for (double x = 0.001; x < 1; x *= 1.37) EXPECT_NEAR(r.invert(r.apply(x, 0), 0), x, 1e-9 + 1e-9 * x) << r.kind;
}

TEST(Response, FileRoundTripAndBadFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "iblkit_response_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "cam.json").string();
  Response r = camera_response(1.1, -3, 300);
  r.inverse[0][5] *= 1.001;  // channels may differ
  write_response(path, r);
  const Response q = read_response(path);
  EXPECT_EQ(q.kind, "camera");
  ASSERT_EQ(q.size(), 300);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 300; ++i) EXPECT_DOUBLE_EQ(q.inverse[c][i], r.inverse[c][i]);
  // Not increasing: refused with the file's name.
  r.inverse[1][10] = r.inverse[1][9];
  EXPECT_THROW(write_response(path, r), Error);
  const std::string bad = (dir / "bad.json").string();
  {
    FILE* f = std::fopen(bad.c_str(), "w");
    std::fputs(R"({"format":"iblkit.response/1","channels":[[0,0.5,1],[0,0.5,1],[0,1,0.5]]})", f);
    std::fclose(f);
  }
  try {
    read_response(bad);
    FAIL() << "a decreasing curve was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(Sensor, NoiseFreeCodesAreTheQuantisedCurve) {
  Image L(16, 4, 3);
  for (int x = 0; x < 16; ++x)
    for (int y = 0; y < 4; ++y)
      for (int c = 0; c < 3; ++c) L.at(x, y, c) = 0.01f * (x + 1) * (c + 1) * (y + 1);
  SensorDesc s;
  s.exposure_s = 0.5;
  s.f_number = 2;
  s.iso = 400;  // factor 0.5 · 4 / 4 = 0.5
  s.wb_gains = {2, 1, 0.5};
  s.response = camera_response();
  const Image z = expose(L, s);
  for (int x = 0; x < 16; ++x)
    for (int y = 0; y < 4; ++y)
      for (int c = 0; c < 3; ++c) {
        const double X = std::min(1.0, L.at(x, y, c) * 0.5 * s.wb_gains[c]);
        EXPECT_FLOAT_EQ(z.at(x, y, c), static_cast<float>(std::round(s.response.apply(X, c) * 255) / 255));
      }
}

TEST(Sensor, NoiseHasTheModelsVarianceAndFollowsTheSeed) {
  const int n = 256;
  Image L(n, n, 3, 0.25f);
  SensorDesc s;
  s.response = linear_response();
  s.bits = 16;
  s.full_well = 10000;
  s.read_noise = 0.002;
  const Image a = expose(L, s), b = expose(L, s);
  s.seed = 7;
  const Image c = expose(L, s);
  double sum = 0, sum2 = 0;
  int same = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.data()[i], b.data()[i]);
    same += a.data()[i] == c.data()[i];
    sum += a.data()[i];
    sum2 += a.data()[i] * double(a.data()[i]);
  }
  EXPECT_LT(same, static_cast<int>(a.size() / 20));
  const double m = sum / a.size(), var = sum2 / a.size() - m * m;
  const double model = 0.25 / 10000 + 0.002 * 0.002 + 1.0 / (12.0 * 65535 * 65535);
  constexpr double kVarTol = 0.03;  // 196608 samples: the variance's standard error is 0.3 %
  EXPECT_NEAR(m, 0.25, 1e-4);
  EXPECT_NEAR(var / model, 1.0, kVarTol);
}

TEST(Sensor, VignettingAndBadDescriptions) {
  Image L(101, 51, 1, 0.5f);
  SensorDesc s;
  s.response = linear_response();
  s.bits = 16;
  s.vignetting = 0.4;
  const Image z = expose(L, s);
  EXPECT_NEAR(z.at(50, 25, 0), 0.5, 1e-4);
  EXPECT_NEAR(z.at(0, 0, 1), 0.5 * (1 - 0.4 * (50.0 * 50 + 25 * 25) / (50.5 * 50.5 + 25.5 * 25.5)), 1e-4);
  s.bits = 12;
  EXPECT_THROW(expose(L, s), Error);
  s.bits = 8;
  s.f_number = 0;
  EXPECT_THROW(expose(L, s), Error);
}

}  // namespace
}  // namespace ibl::capture
