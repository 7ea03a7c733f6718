// Tests of the filter bases, the shift-invariance error and the textured spotlight's GL-exact lookup.
#include <gtest/gtest.h>

#include <cmath>

#include "iblkit/nearfield/basis.h"
#include "iblkit/nearfield/spotlight.h"

namespace ibl::nearfield {
namespace {

// ∫ f over [lo, hi] by composite Simpson with n panels.
template <typename F>
double simpson(F f, double lo, double hi, int n = 4000) {
  double h = (hi - lo) / n, acc = f(lo) + f(hi);
  for (int k = 1; k < n; ++k) acc += f(lo + k * h) * (k % 2 ? 4 : 2);
  return acc * h / 3;
}

TEST(NearfieldBasis, DualIsBiorthogonalToTheBSplines) {
  // Simpson on 4000 panels of piecewise polynomials with kinks: error ~1e-7.
  constexpr double kQuadTol = 1e-6;
  for (Basis b : {Basis::Bilinear, Basis::Biquadratic}) {
    for (int j = -5; j <= 5; ++j) {
      double g = simpson([&](double x) { return dual(b, x) * primal(b, x - j); }, -6, 6);
      EXPECT_NEAR(g, j == 0 ? 1.0 : 0.0, kQuadTol) << basis_name(b) << " j=" << j;
    }
    EXPECT_NEAR(simpson([&](double x) { return dual(b, x); }, -6, 6), 1.0, kQuadTol) << basis_name(b);
    EXPECT_NEAR(simpson([&](double x) { return primal(b, x); }, -6, 6), 1.0, kQuadTol) << basis_name(b);
    // The support widths the paper quotes: 4h for the biquadratic dual (5 mm -> 20 mm).
    EXPECT_EQ(dual(b, dual_half_width(b) + 1e-9), 0.0);
    EXPECT_NE(dual(b, dual_half_width(b) - 0.2), 0.0);
    // The filter has negative lobes (hence E⁺ and E⁻ measurements).
    double mn = 0;
    for (double x = -3; x <= 3; x += 0.01) mn = std::min(mn, dual(b, x));
    EXPECT_LT(mn, 0) << basis_name(b);
  }
  EXPECT_EQ(dual_half_width(Basis::Biquadratic), 2.0);
  // Partition of unity of the primal B-splines.
  for (double x = -0.5; x <= 0.5; x += 0.05) {
    double s = 0;
    for (int i = -3; i <= 3; ++i) s += primal(Basis::Biquadratic, x - i);
    EXPECT_NEAR(s, 1.0, 1e-14);  // exact arithmetic up to rounding
  }
}

TEST(NearfieldBasis, ShiftInvarianceErrorMatchesThePaper) {
  // Granier et al. §3.1: "the error is below 8% if the ratio s … equals 0.04". To first order
  // E_r = s·4u/(1+u²) with u = tan θ0, largest (2s = 0.08) at θ0 = 45°.
  double worst = 0;
  for (double t = 0; t < 1.5; t += 0.001) worst = std::max(worst, shift_invariance_error(t, 0.04));
  constexpr double kSecondOrder = 2e-3;  // the second-order term of the expansion at s = 0.04
  EXPECT_NEAR(worst, 0.08, kSecondOrder);
  EXPECT_NEAR(shift_invariance_error(kPi / 4, 0.04), 0.08, kSecondOrder);
  // On the axis the support is symmetric: E_r = 1 − cos⁴ at u = s/2 = 1 − 1/(1 + s²/4)².
  EXPECT_NEAR(shift_invariance_error(0, 0.04), 1 - 1 / std::pow(1 + 0.0004, 2), 1e-12);
  // The 2-D square support is worse than the 1-D interval.
  EXPECT_GT(shift_invariance_error(0.5, 0.04, true), shift_invariance_error(0.5, 0.04, false));
}

TexturedSpotlight test_light(const Image& tex, double width) {
  TexturedSpotlight L;
  L.position = {0.1, 1.0, -0.2};
  Placement p;
  p.forward = {0, 0, 1};
  L.frame = p.frame();
  L.plane_distance = 0.5;
  L.tex_min = {-0.2, -0.2};
  L.tex_max = {0.2, 0.2};
  L.mips = std::make_shared<const std::vector<Image>>(build_mips(tex));
  L.support_area = 2.5e-5;
  L.support_width = width;
  return L;
}

TEST(NearfieldSpotlight, ConstantTextureGivesTheClosedForm) {
  Image tex(16, 16, 3, 7.0f);
  auto L = test_light(tex, 0.015);
  // A point 1 m ahead, 0.1 m right and 0.05 m up, facing back at the light.
  Vec3 x = L.position + Vec3{0.1, 0.05, 1.0};  // right = +x for forward +z, up +y
  Vec3 n = normalize(L.position - x);
  Vec3 q = x - L.position;
  double d2 = dot(q, q), cl = q.z / std::sqrt(d2);
  Vec3 e = irradiance(L, x, n);
  constexpr double kFloatTol = 1e-6;  // float texels
  EXPECT_NEAR(e.x, 2.5e-5 * cl * 1.0 / d2 * 7.0, kFloatTol * e.x);
  EXPECT_EQ(irradiance(L, L.position - Vec3{0, 0, 0.3}, {0, 0, 1}).x, 0.0);  // behind S
  EXPECT_EQ(irradiance(L, x, -n).x, 0.0);                                    // facing away
  EXPECT_EQ(L.frame.t.x, 1.0);  // right = +x, up = +y, right × up = forward = +z
}

TEST(NearfieldSpotlight, RowZeroIsTheLargestT) {
  Image tex(8, 8, 3, 0.0f);
  for (int x = 0; x < 8; ++x) tex.set_rgb(x, 0, {1, 1, 1});  // top row only
  auto L = test_light(tex, 0.0);
  // t on M = 0.2 − half a texel (0.025) is the centre of row 0: up·d/z = 0.175 with z = 0.5.
  Vec3 top = L.position + Vec3{0, 0.175, 0.5}, bottom = L.position + Vec3{0, -0.175, 0.5};
  EXPECT_NEAR(texture_lookup(L, top).x, 1.0, 1e-6);
  EXPECT_EQ(texture_lookup(L, bottom).x, 0.0);
  // Half a texel beyond the edge the border (0) weighs one half.
  Vec3 edge = L.position + Vec3{0, 0.2, 0.5};
  EXPECT_NEAR(texture_lookup(L, edge).x, 0.5, 1e-6);
}

TEST(NearfieldSpotlight, FootprintPicksTheMipLevel) {
  // A 2-texel checker: level 0 alternates 0/1, level 1 is the mean 0.5 everywhere.
  Image tex(64, 64, 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) tex.set_rgb(x, y, Vec3{1, 1, 1} * ((x + y) % 2));
  auto mips = build_mips(tex);
  ASSERT_EQ(mips.size(), 7u);
  EXPECT_FLOAT_EQ(mips[1].at(3, 5, 0), 0.5f);
  EXPECT_FLOAT_EQ(mips[6].at(0, 0, 0), 0.5f);
  const double texel = 0.4 / 64;
  // footprint = w·|1 − d/z|: at z = 2d it is w/2. Choose w so that footprint = 2 texels -> λ = 1.
  auto L = test_light(tex, 4 * texel);
  Vec3 centre_of_texel = L.position + Vec3{(0.5 * texel) * 2, 0.5 * texel * 2, 1.0};  // (s,t) = (½, ½) texel
  EXPECT_NEAR(texture_lookup(L, centre_of_texel).x, 0.5, 1e-6);
  // At z = d the footprint is 0: the level-0 texel itself (row 31, column 32 -> (32+31) odd = 1).
  L.support_width = 4 * texel;
  Vec3 on_m = L.position + Vec3{0.5 * texel, 0.5 * texel, 0.5};
  EXPECT_NEAR(texture_lookup(L, on_m).x, 1.0, 1e-6);
}

}  // namespace
}  // namespace ibl::nearfield
