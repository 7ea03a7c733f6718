// Rotation of SH coefficient vectors: full rotation by any 3×3 rotation matrix, and zonal
// harmonics turned to any axis.
//
// References
//  [1] Sloan, Luna & Snyder, "Local, deformable precomputed radiance transfer", SIGGRAPH 2005, §3
//      (rotating zonal harmonics: c_lm = √(4π/(2l+1)) z_l Y_lm(axis)).
//  [2] Ivanic & Ruedenberg, "Rotation matrices for real spherical harmonics", J. Phys. Chem. 1996 —
//      the band-by-band block structure used here; the blocks themselves are computed by exact
//      quadrature instead of their recurrence (see rotation_matrix).
#pragma once
#include <vector>

#include "iblkit/core/vec.h"
#include "iblkit/sh/coeffs.h"

namespace ibl::sh {

// Block-diagonal rotation matrix of `bands` bands: blocks[l] is (2l+1)×(2l+1), row-major, row m+l,
// column m'+l. Semantics as sphere::ResampleDesc::rotation: the rotated function is g(d) = f(Rᵀd)
// (the environment turned by R), and g_lm = Σ_m' blocks[l][m][m'] f_lm'.
//
//   blocks[l][m][m'] = ∫ Y_lm(d) Y_lm'(Rᵀd) dω,
//
// computed with a product quadrature that is exact for polynomials of degree 2l (basis.h
// exact_quadrature), so each block is exact to rounding, for any bands and any orthogonal R.
struct RotationMatrix {
  int bands = 0;
  std::vector<std::vector<double>> blocks;
};
RotationMatrix rotation_matrix(int bands, const Mat3& R);

// g = f(Rᵀ d) for every channel.
Coeffs rotate(const Coeffs& c, const Mat3& R);
Coeffs rotate(const Coeffs& c, const RotationMatrix& M);

// A zonal function f(d) = Σ_l zh[l] Y_l0(d) (symmetric about +z) turned so that +z goes to unit
// `axis`: returns its bands² coefficients c_lm = √(4π/(2l+1)) zh[l] Y_lm(axis) [1].
std::vector<double> rotate_zh(const std::vector<double>& zh, Vec3 axis);

// A rotation matrix that takes +z to unit `axis` (for tests and for building frames).
Mat3 rotation_from_z(Vec3 axis);

}  // namespace ibl::sh
