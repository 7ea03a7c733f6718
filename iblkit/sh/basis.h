// Real spherical harmonics: basis evaluation, Gauss–Legendre nodes, exact quadrature on the sphere.
//
// Convention (docs/conventions.md, "Spherical harmonics"): real, orthonormal
// (∫ Y_lm² dω = 1), no Condon–Shortley phase, index k = l(l+1)+m, z the polar axis of the
// formulas, evaluated on world directions as they are: Y_1,−1 = c₁ y, Y_10 = c₁ z, Y_11 = c₁ x with
// c₁ = √(3/4π) — the basis of [1], [2], three.js and (up to the sign of odd m) Filament.
//
// References
//  [1] Ramamoorthi & Hanrahan, "An efficient representation for irradiance environment maps",
//      SIGGRAPH 2001 — the 9 basis polynomials and their constants.
//  [2] Sloan, "Stupid spherical harmonics (SH) tricks", GDC 2008 — the recurrences below.
//  [3] Press et al., Numerical Recipes 3rd ed., §4.6 (Gauss–Legendre nodes by Newton's method).
#pragma once
#include <vector>

#include "iblkit/core/vec.h"

namespace ibl::sh {

constexpr int coeff_count(int bands) { return bands * bands; }
constexpr int index(int l, int m) { return l * (l + 1) + m; }

// Largest number of bands any function here accepts (l ≤ 31); the normalisation constants stay
// well inside double range there.
inline constexpr int kMaxBands = 32;

// out[index(l, m)] = Y_lm(d) for l < bands. d must be unit length. Throws ibl::Error for bands
// outside [1, kMaxBands].
void eval_basis(int bands, Vec3 d, double* out);
void eval_basis(int bands, Vec3 d, float* out);
std::vector<double> eval_basis(int bands, Vec3 d);

// Normalisation K_lm = √((2l+1)/4π · (l−m)!/(l+m)!) times √2 for m > 0: with it
//   Y_l0 = K_l0 P̃_l0(z),  Y_l,±m = K_lm P̃_lm(z) · {Re, Im}(x + i y)^m,
// where P̃_lm(z) = P_l^m(z) / sin^m θ without the (−1)^m phase [2]:
//   P̃_mm = (2m−1)!!,  P̃_{m+1,m} = (2m+1) z P̃_mm,  P̃_lm = ((2l−1) z P̃_{l−1,m} − (l+m−1) P̃_{l−2,m}) / (l−m).
double norm_constant(int l, int m);  // m ≥ 0
// P̃_lm(z) for 0 ≤ m ≤ l < bands into out[l * bands + m] (bands² doubles).
void legendre_table(int bands, double z, double* out);

// Gauss–Legendre rule of n points on [−1, 1] [3]: exact for polynomials of degree ≤ 2n − 1.
void gauss_legendre(int n, std::vector<double>* nodes, std::vector<double>* weights);

// A product rule on the sphere (Gauss–Legendre in z × uniform in φ) that integrates every
// polynomial of degree ≤ `degree` in (x, y, z) exactly: (degree/2 + 1) × (degree + 1) points.
struct SphereQuadrature {
  std::vector<Vec3> directions;
  std::vector<double> weights;  // sum to 4π
};
SphereQuadrature exact_quadrature(int degree);

}  // namespace ibl::sh
