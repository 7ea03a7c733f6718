// Prefiltered Phong maps against closed forms: a constant sky, one small bright source, and a
// band-limited sky whose Phong convolution the SH path computes exactly.
#include "iblkit/render/prefilter.h"

#include <gtest/gtest.h>

#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sh/convolve.h"

namespace ibl::render {
namespace {

sphere::EnvMap latlong(int h) {
  return sphere::EnvMap(Image(2 * h, h, 3), sphere::Mapping(sphere::MappingKind::LatLong, 2 * h, h));
}

std::vector<Vec3> test_directions() {
  std::vector<Vec3> r;
  for (int i = 0; i < 60; ++i) {
    double z = 1 - 2 * (i + 0.5) / 60, s = std::sqrt(1 - z * z), ph = 2.39996 * i;
    r.push_back({s * std::cos(ph), z, s * std::sin(ph)});
  }
  return r;
}

// The lobe is normalised: ∫ (s+1)/2π max(0, r·ω)^s dω = 1, so a constant sky L gives G = L.
TEST(Prefilter, ConstantSkyGivesItsRadiance) {
  constexpr double kQuadratureTol = 5e-3;  // midpoint rule of cos^s over pixels of ~σ/3 (0.2% at s = 40)
  auto env = latlong(32);
  for (size_t i = 0; i < env.image.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c) env.image.data()[i * 3 + c] = 1.0f + c;
  for (double s : {1.0, 20.0, 40.0}) {
    GlossyMap g = prefilter_phong(env, s);
    EXPECT_EQ(g.latlong.height(), glossy_map_height(s));
    for (Vec3 r : test_directions()) {
      Vec3 v = lookup(g, r);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[c], 1.0 + c, kQuadratureTol * (1 + c)) << "s=" << s;
    }
  }
}

// A sky that is a sum of SH bands 0..2: G(r) = Σ ρ̂_l(s) c_lm Y_lm(r) exactly (Funk–Hecke).
TEST(Prefilter, BandLimitedSkyMatchesShConvolution) {
  constexpr double kRelTol = 5e-3;  // quadrature and the map's bilinear interpolation
  const int bands = 3;
  std::vector<Vec3> c = {{2.0, 1.8, 1.5},  {0.3, 0.1, 0.0}, {0.6, 0.5, 0.2},  {-0.2, 0.1, 0.3}, {0.1, 0.0, 0.1},
                         {0.05, 0.1, 0.0}, {0.2, 0.1, 0.1}, {0.0, 0.1, 0.05}, {-0.1, 0.05, 0.1}};
  auto env = latlong(64);
  std::vector<double> y(9);
  for (int py = 0; py < env.image.height(); ++py)
    for (int px = 0; px < env.image.width(); ++px) {
      Vec3 d;
      env.mapping.to_direction(px + 0.5, py + 0.5, &d);
      sh::eval_basis(bands, d, y.data());
      Vec3 L;
      for (int k = 0; k < 9; ++k) L += c[k] * y[k];
      env.image.set_rgb(px, py, L);
    }
  const double s = 10;
  GlossyMap g = prefilter_phong(env, s);
  auto zh = sh::phong_zh(bands, s);
  for (Vec3 r : test_directions()) {
    sh::eval_basis(bands, r, y.data());
    Vec3 want;
    for (int l = 0; l < bands; ++l)
      for (int k = l * l; k < (l + 1) * (l + 1); ++k) want += c[k] * (zh[l] * y[k]);
    Vec3 got = lookup(g, r);
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(got[ch], want[ch], kRelTol * want[0]) << "r=" << r.x << "," << r.y << "," << r.z;
  }
}

// One bright pixel delivering irradiance E from direction ω: G(r) = E (s+1)/2π (r·ω)^s.
TEST(Prefilter, SmallSourceGivesTheLobe) {
  // The map resolves the lobe with ~3.6 texels per σ at s = 8: bilinear interpolation between texel
  // centres (≈2%) and the source moved to the centre of its map-resolution input pixel (≈2%).
  constexpr double kLobeTol = 0.06;
  auto env = latlong(128);
  const int sx = 100, sy = 40;
  double dw = env.mapping.solid_angle(sx, sy);
  env.image.set_rgb(sx, sy, Vec3{1, 1, 1} / dw);  // E = 1 W/m² at normal incidence
  Vec3 w;
  env.mapping.to_direction(sx + 0.5, sy + 0.5, &w);
  const double s = 8;
  GlossyMap g = prefilter_phong(env, s);
  for (double a : {0.0, 0.2, 0.4, 0.7}) {
    // r tilted from ω by angle a about an axis perpendicular to it
    Vec3 t = normalize(cross(w, Vec3{0, 1, 0}));
    Vec3 r = w * std::cos(a) + t * std::sin(a);
    double want = (s + 1) / kTwoPi * std::pow(std::cos(a), s);
    EXPECT_NEAR(lookup(g, r).x, want, kLobeTol * (s + 1) / kTwoPi) << "a=" << a;
  }
}

TEST(Prefilter, RejectsBadExponent) {
  auto env = latlong(8);
  EXPECT_THROW(prefilter_phong(env, -1), Error);
  EXPECT_THROW(prefilter_phong(env, std::nan("")), Error);
}

}  // namespace
}  // namespace ibl::render
