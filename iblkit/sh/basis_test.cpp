#include "iblkit/sh/basis.h"

#include <cmath>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"

namespace ibl::sh {
namespace {

// ∫ Y_k Y_k' dω = δ_kk' for every pair up to 9 bands, with a product rule exact for degree 16.
TEST(ShBasis, OrthonormalByQuadratureUpTo9Bands) {
  constexpr double kOrthoTol = 1e-12;  // exact quadrature: only rounding remains
  const int bands = 9, K = coeff_count(bands);
  SphereQuadrature q = exact_quadrature(2 * (bands - 1));
  std::vector<double> gram(K * K, 0.0), y(K);
  double wsum = 0;
  for (size_t i = 0; i < q.directions.size(); ++i) {
    eval_basis(bands, q.directions[i], y.data());
    wsum += q.weights[i];
    for (int a = 0; a < K; ++a)
      for (int b = 0; b < K; ++b) gram[a * K + b] += q.weights[i] * y[a] * y[b];
  }
  EXPECT_NEAR(wsum, kFourPi, kOrthoTol);
  for (int a = 0; a < K; ++a)
    for (int b = 0; b < K; ++b) ASSERT_NEAR(gram[a * K + b], a == b ? 1.0 : 0.0, kOrthoTol) << a << "," << b;
}

// The quadrature itself: Gauss–Legendre integrates z^k exactly up to degree 2n−1, and the product
// rule integrates x^a y^b z^c like the closed form on the sphere (here x²y²z² = 4π/105).
TEST(ShBasis, QuadratureIsExact) {
  constexpr double kQuadTol = 1e-13;  // rounding of sums of ~100 terms
  std::vector<double> z, w;
  gauss_legendre(5, &z, &w);
  for (int k = 0; k <= 9; ++k) {
    double s = 0;
    for (int i = 0; i < 5; ++i) s += w[i] * std::pow(z[i], k);
    EXPECT_NEAR(s, k % 2 ? 0.0 : 2.0 / (k + 1), kQuadTol) << k;
  }
  SphereQuadrature q = exact_quadrature(6);
  double s = 0;
  for (size_t i = 0; i < q.directions.size(); ++i) {
    Vec3 d = q.directions[i];
    s += q.weights[i] * d.x * d.x * d.y * d.y * d.z * d.z;
  }
  EXPECT_NEAR(s, kFourPi / 105.0, kQuadTol);
}

// The 9 polynomials of Ramamoorthi & Hanrahan 2001 (no Condon–Shortley phase: all signs +).
TEST(ShBasis, MatchesRamamoorthiHanrahanPolynomials) {
  constexpr double kClosedFormTol = 1e-14;
  const double c0 = 0.5 / std::sqrt(kPi), c1 = std::sqrt(3.0 / kFourPi), c2 = std::sqrt(15.0 / kFourPi),
               c20 = std::sqrt(5.0 / (16 * kPi)), c22 = std::sqrt(15.0 / (16 * kPi));
  for (Vec3 d : {Vec3{0.3, -0.5, 0.81}, Vec3{-0.9, 0.1, -0.4}, Vec3{0, 1, 0}, Vec3{0, 0, -1}}) {
    d = normalize(d);
    double y[9];
    eval_basis(3, d, y);
    const double x = d.x, yy = d.y, z = d.z;
    double expect[9] = {c0,
                        c1 * yy,
                        c1 * z,
                        c1 * x,
                        c2 * x * yy,
                        c2 * yy * z,
                        c20 * (3 * z * z - 1),
                        c2 * x * z,
                        c22 * (x * x - yy * yy)};
    for (int k = 0; k < 9; ++k) EXPECT_NEAR(y[k], expect[k], kClosedFormTol) << k;
  }
  // Two constants in their closed forms, the rest follow from the recurrence.
  EXPECT_NEAR(norm_constant(0, 0), 0.28209479177387814, kClosedFormTol);
  EXPECT_NEAR(norm_constant(1, 1), 0.48860251190291992, kClosedFormTol);
}

// Band 3 against its closed forms (a band the R&H table does not cover), e.g.
// Y_3,−3 = √(35/32π) y(3x² − y²), Y_30 = √(7/16π) z(5z² − 3), Y_33 = √(35/32π) x(x² − 3y²).
TEST(ShBasis, Band3ClosedForms) {
  constexpr double kClosedFormTol = 1e-13;
  Vec3 d = normalize(Vec3{0.2, 0.7, -0.5});
  double y[16];
  eval_basis(4, d, y);
  const double x = d.x, yy = d.y, z = d.z;
  EXPECT_NEAR(y[index(3, -3)], std::sqrt(35.0 / (32 * kPi)) * yy * (3 * x * x - yy * yy), kClosedFormTol);
  EXPECT_NEAR(y[index(3, 0)], std::sqrt(7.0 / (16 * kPi)) * z * (5 * z * z - 3), kClosedFormTol);
  EXPECT_NEAR(y[index(3, 2)], std::sqrt(105.0 / (16 * kPi)) * z * (x * x - yy * yy), kClosedFormTol);
  EXPECT_NEAR(y[index(3, 3)], std::sqrt(35.0 / (32 * kPi)) * x * (x * x - 3 * yy * yy), kClosedFormTol);
}

TEST(ShBasis, FloatMatchesDoubleAndRejectsBadBands) {
  constexpr double kFloatTol = 1e-5;  // float rounding of values ≤ ~3 at 12 bands
  std::vector<double> yd(144);
  std::vector<float> yf(144);
  Vec3 d = normalize(Vec3{-0.3, 0.4, 0.2});
  eval_basis(12, d, yd.data());
  eval_basis(12, d, yf.data());
  for (int k = 0; k < 144; ++k) EXPECT_NEAR(yf[k], yd[k], kFloatTol);
  EXPECT_THROW(eval_basis(0, d), Error);
  EXPECT_THROW(eval_basis(kMaxBands + 1, d), Error);
}

}  // namespace
}  // namespace ibl::sh
