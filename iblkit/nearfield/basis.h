// The filter bases of the two-plane light-field measurement (Goesele et al. 2003, section 2 of
// Granier et al. 2003): the reconstruction basis Φ (B-splines of spacing h on S) and the compactly
// supported dual Φ' that is the physical filter, with ∫ Φ'_i Φ_j = δ_ij.
//
// In units of the spacing (x = u/h), 1-D:
//   bilinear    β1(x) = max(0, 1 − |x|)                                   support [−1, 1]
//   biquadratic β2(x) = ¾ − x² (|x| ≤ ½),  ½(|x| − 3/2)² (½ ≤ |x| ≤ 3/2)   support [−3/2, 3/2]
// The dual φ'(x) = Σ_{|k|<4H} a_|k| β1(4x − k) is piecewise linear on quarter-spacing nodes, support
// [−H, H]: H = 3/2 (width 3h) for the bilinear basis, H = 2 (width 4h, the paper's 20 mm dual for 5 mm
// spacing) for the biquadratic one. The coefficients are the minimum-norm solution of
//   ∫ φ'(x) β(x − j) dx = δ_j0 for every j            (biorthogonality)
//   Σ_m φ'(x − m) = 1 for every x                     (the filters add up to an open aperture)
// The second condition makes the reconstruction keep the power of any light field, however small
// its features are against h (without it, 2-D power errors of ×0.75…×2.6 on sub-spacing emitters).
// Derived here, not taken from Goesele et al. (their filters are not in our copy): the paper only
// fixes the widths. 2-D functions are tensor products: Φ_ij(u,v) = β(u/h − i')·β(v/h − j'),
// Φ'_ij(u,v) = φ'(u/h − i')·φ'(v/h − j')/h² (i', j' the centre in units of h).
#pragma once
#include <vector>

#include "iblkit/nearfield/dataset.h"

namespace ibl::nearfield {

// β(x) of the basis, x in units of the spacing.
double primal(Basis b, double x);
// Half the support width of β, in units of the spacing (1 or 3/2).
double primal_half_width(Basis b);
// φ'(x), the dual filter (may be negative), x in units of the spacing; ∫ φ' = 1.
double dual(Basis b, double x);
// Half the support width of φ' in units of the spacing (3/2 or 2).
double dual_half_width(Basis b);
// a_0 … a_K of the dual (for the docs and the tests).
const std::vector<double>& dual_coefficients(Basis b);

// Relative error of the shift-invariant approximation (Granier et al. 2003, §3.1, Fig. 3):
//   E_r(θ0) = (max_F cos⁴θ − min_F cos⁴θ) / cos⁴θ0
// over a filter support F of width `rel_width` = filter width / plane distance, centred where the
// ray makes angle θ0 (radians) with the planes' normal. `two_d` takes F as the square
// [tanθ0 ± w/2] × [± w/2] (the real 2-D support); otherwise the 1-D interval (the paper's plot).
double shift_invariance_error(double theta0, double rel_width, bool two_d = false);

}  // namespace ibl::nearfield
