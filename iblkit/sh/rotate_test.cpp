#include "iblkit/sh/rotate.h"

#include <cmath>

#include <gtest/gtest.h>

#include "iblkit/sh/basis.h"
#include "iblkit/sh/convolve.h"

namespace ibl::sh {
namespace {

constexpr double kRotTol = 1e-12;  // blocks are exact up to rounding

Mat3 some_rotation() { return Mat3::rotation(normalize(Vec3{0.3, -0.8, 0.5}), 1.1) * Mat3::rotation({0, 1, 0}, -0.4); }

Coeffs some_coeffs(int bands) {
  Coeffs c(bands);
  for (int k = 0; k < coeff_count(bands); ++k) c.c[k] = {std::sin(1.3 * k + 0.2), std::cos(0.7 * k), 0.1 * k - 0.5};
  return c;
}

// Band 1 is (c₁y, c₁z, c₁x): its block is R itself with rows and columns in the order (y, z, x).
TEST(ShRotate, Band1BlockIsTheRotationMatrix) {
  Mat3 R = some_rotation();
  RotationMatrix M = rotation_matrix(2, R);
  const int axis[3] = {1, 2, 0};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(M.blocks[1][a * 3 + b], R.m[axis[a]][axis[b]], kRotTol);
  EXPECT_NEAR(M.blocks[0][0], 1.0, kRotTol);
}

// About z by α every order m turns like a 2D rotation by mα:
//   g_m = f_m cos mα − f_−m sin mα,  g_−m = f_m sin mα + f_−m cos mα.
TEST(ShRotate, AboutZMatchesExplicitMatrices) {
  const int bands = 9;
  const double alpha = 0.7;
  Coeffs f = some_coeffs(bands);
  Coeffs g = rotate(f, Mat3::rotation({0, 0, 1}, alpha));
  for (int l = 0; l < bands; ++l) {
    EXPECT_NEAR(g.c[index(l, 0)].x, f.c[index(l, 0)].x, kRotTol);
    for (int m = 1; m <= l; ++m) {
      double c = std::cos(m * alpha), s = std::sin(m * alpha);
      Vec3 gm = f.c[index(l, m)] * c - f.c[index(l, -m)] * s, gn = f.c[index(l, m)] * s + f.c[index(l, -m)] * c;
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(g.c[index(l, m)][ch], gm[ch], kRotTol) << l << " " << m;
        EXPECT_NEAR(g.c[index(l, -m)][ch], gn[ch], kRotTol) << l << " " << m;
      }
    }
  }
}

// 90° about x maps (x, y, z) → (x, −z, y); band 2 in closed form: xy → −xz, so g(2,−2) = −f(2,1), etc.
TEST(ShRotate, QuarterTurnAboutXBand2) {
  Coeffs f(3);
  f.c[index(2, -2)] = {1, 0, 0};  // c₂ xy
  Coeffs g = rotate(f, Mat3::rotation({1, 0, 0}, kPi / 2));
  // g(d) = f(Rᵀd) with Rᵀ(x,y,z) = (x, z, −y): xy → x z → Y_21.
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(g.c[k].x, k == index(2, 1) ? 1.0 : 0.0, kRotTol) << k;
}

// g(d) = f(Rᵀd) pointwise, 9 bands; blocks orthogonal; composition M(AB) = M(A)M(B).
TEST(ShRotate, PointwiseOrthogonalAndComposes) {
  constexpr double kPointTol = 1e-11;  // sums of 81 terms of size ~1
  const int bands = 9;
  Mat3 A = some_rotation(), B = Mat3::rotation(normalize(Vec3{1, 2, 3}), 2.5);
  Coeffs f = some_coeffs(bands), g = rotate(f, A);
  for (Vec3 d : {Vec3{0, 1, 0}, normalize(Vec3{1, -2, 0.5}), normalize(Vec3{-0.3, 0.1, -0.9})}) {
    Vec3 a = g.evaluate(d), b = f.evaluate(A.transposed() * d);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(a[ch], b[ch], kPointTol);
  }
  Coeffs ab = rotate(f, A * B), a_b = rotate(rotate(f, B), A);
  for (int k = 0; k < coeff_count(bands); ++k)
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(ab.c[k][ch], a_b.c[k][ch], kPointTol);
  RotationMatrix M = rotation_matrix(bands, A);
  for (int l = 0; l < bands; ++l) {
    int n = 2 * l + 1;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        double s = 0;
        for (int j = 0; j < n; ++j) s += M.blocks[l][a * n + j] * M.blocks[l][b * n + j];
        EXPECT_NEAR(s, a == b ? 1.0 : 0.0, kPointTol);
      }
  }
}

// Sloan et al. 2005: a zonal lobe turned to an axis equals the full rotation of the same lobe.
TEST(ShRotate, ZonalRotationEqualsFullRotation) {
  const int bands = 9;
  std::vector<double> zh = clamped_cosine_zh(bands);
  for (int l = 0; l < bands; ++l) zh[l] *= std::sqrt((2 * l + 1) / kFourPi);  // the lobe's own Y_l0 coefficients
  for (Vec3 axis : {normalize(Vec3{0.2, 0.9, -0.4}), Vec3{0, 0, -1}, Vec3{1, 0, 0}}) {
    std::vector<double> fast = rotate_zh(zh, axis);
    Coeffs lobe(bands);
    for (int l = 0; l < bands; ++l) lobe.c[index(l, 0)] = {zh[l], zh[l], zh[l]};
    Mat3 R = rotation_from_z(axis);
    EXPECT_NEAR(length(R * Vec3{0, 0, 1} - axis), 0.0, kRotTol);
    Coeffs full = rotate(lobe, R);
    for (int k = 0; k < coeff_count(bands); ++k) EXPECT_NEAR(fast[k], full.c[k].x, kRotTol) << k;
  }
}

}  // namespace
}  // namespace ibl::sh
