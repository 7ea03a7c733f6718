#include "iblkit/lights/evaluate.h"

#include <random>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"
#include "iblkit/lights/test_probes.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::lights {
namespace {

using testing::constant_probe;

// Double-precision reference of E(n) straight from the definition.
std::vector<Vec3> reference(const sphere::EnvMap& env, const std::vector<Vec3>& normals) {
  std::vector<Vec3> out(normals.size());
  for (int y = 0; y < env.image.height(); ++y)
    for (int x = 0; x < env.image.width(); ++x) {
      Vec3 d;
      if (!env.mapping.valid(x, y) || !env.mapping.to_direction(x + 0.5, y + 0.5, &d)) continue;
      Vec3 L = env.image.rgb(x, y) * env.mapping.solid_angle(x, y);
      for (size_t k = 0; k < normals.size(); ++k) out[k] += L * std::max(0.0, dot(normals[k], normalize(d)));
    }
  return out;
}

TEST(LightsGroundTruth, UnitRadianceGivesPi) {
  // Σ max(0, n·ω) dω over pixel centres of a 256×128 grid: the clamped cosine is sampled at pixel
  // centres, an O(pixel²) quadrature error of ~1e−4 relative.
  constexpr double kQuadratureTol = 5e-4;
  auto env = constant_probe(256, 128);
  auto e = irradiance_ground_truth(env, sphere::icosphere_face_centres(3));
  for (const auto& v : e)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[c], kPi, kQuadratureTol * kPi);
}

TEST(LightsGroundTruth, MatchesDoublePrecisionDefinition) {
  // Float lanes against double sums over ~2k pixels: 1e−5 relative covers float rounding.
  constexpr double kFloatTol = 1e-5;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 1);
  Image img(64, 32, 3);
  for (size_t i = 0; i < img.size(); ++i) img.data()[i] = u(rng) < 0.3f ? 0.0f : u(rng) * 10;
  sphere::EnvMap env(img, sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  auto normals = sphere::fibonacci_sphere(200);
  auto ref = reference(env, normals);
  for (bool cull : {true, false}) {
    GroundTruthDesc d;
    d.cull = cull;
    d.tile = 8;
    auto e = irradiance_ground_truth(env, normals, d);
    for (size_t k = 0; k < normals.size(); ++k)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[k][c], ref[k][c], kFloatTol * ref[k][c] + 1e-9) << "cull " << cull;
  }
}

TEST(LightsGroundTruth, CullingEqualsBruteForceOnRealProbe) {
  auto probes = testing::blender_probes();
  if (probes.empty()) GTEST_SKIP() << "blender-data not installed";
  // Both paths add the same float terms, grouped differently: 1e−5 relative.
  constexpr double kRegroupTol = 1e-5;
  auto env = testing::small_probe(probes.front(), 256, 128);
  auto normals = sphere::icosphere_face_centres(3);
  GroundTruthDesc brute;
  brute.cull = false;
  auto a = irradiance_ground_truth(env, normals);
  auto b = irradiance_ground_truth(env, normals, brute);
  for (size_t k = 0; k < normals.size(); ++k)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[k][c], b[k][c], kRegroupTol * b[k][c] + 1e-12);
}

TEST(LightsGroundTruth, AnyMappingAgreesWithLatLong) {
  // A smooth probe in a mirror ball and in a lat-long: both are quadratures of the same integral;
  // the resampled ball carries ~0.5% interpolation and rim error.
  constexpr double kMappingTol = 0.01;
  auto ll = testing::lobe_probe(256, 128, {{0.3, 0.8, 0.2}, {-0.5, 0.1, 0.7}}, {{4, 3, 2}, {1, 2, 5}}, 0.5);
  sphere::Mapping ball(sphere::MappingKind::MirrorBall, 256, 256);
  sphere::EnvMap mb(sphere::resample(ll, ball), ball);
  auto normals = sphere::icosphere_face_centres(2);
  auto a = irradiance_ground_truth(ll, normals), b = irradiance_ground_truth(mb, normals);
  for (size_t k = 0; k < normals.size(); ++k)
    EXPECT_NEAR(luminance(b[k]), luminance(a[k]), kMappingTol * luminance(a[k]));
}

TEST(LightsErrors, RelativeErrorsAndGuard) {
  constexpr double kExact = 1e-12;  // plain arithmetic on a handful of values
  std::vector<Vec3> gt = {{1, 2, 4}, {2, 2, 2}, {0, 0, 0}};
  std::vector<Vec3> est = {{1.1, 2.2, 4.4}, {2.2, 2.2, 2.2}, {0, 0, 0}};
  auto s = compare_irradiance(est, gt);
  EXPECT_NEAR(s.mean_rel, 0.2 / 3, kExact);  // (0.1 + 0.1 + 0) / 3 per channel
  EXPECT_NEAR(s.max_rel, 0.1, kExact);
  // The dark normal: an error of 0.01 against a floor of 1% of the mean (1/100·(3/3 … )).
  est[2] = {0.01, 0.0, 0.0};
  auto g = compare_irradiance(est, gt);
  double floor_r = 0.01 * (1 + 2 + 0) / 3.0;
  EXPECT_NEAR(g.max_rel, (0.01 / floor_r + 0.1 + 0.1) / 3, kExact);
  EXPECT_THROW(compare_irradiance({{1, 1, 1}}, gt), Error);
}

TEST(LightsErrors, LightsIrradianceIsClampedCosine) {
  constexpr double kExact = 1e-12;
  std::vector<Light> l = {{{0, 1, 0}, {2, 3, 4}, 0.1}};
  auto e = irradiance_from_lights(l, {{0, 1, 0}, {0, -1, 0}, normalize(Vec3{1, 1, 0})});
  EXPECT_NEAR(e[0].y, 3, kExact);
  EXPECT_NEAR(e[1].y, 0, kExact);
  EXPECT_NEAR(e[2].z, 4 / std::sqrt(2.0), kExact);
}

}  // namespace
}  // namespace ibl::lights
