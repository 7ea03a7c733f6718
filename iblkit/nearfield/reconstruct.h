// The shift-invariant approximation of Granier et al. 2003, §3.1 (Eqs. 7–11): per filter position mn
// an incoming-radiance texture E'_mn(s,t) on M, such that the light field is approximately
//   L̃(u,v,s,t) ≈ Σ_mn Φ_mn(u,v) · E'_mn(s,t)                                       (Eq. 11)
//
// Derivation (our normalisation; dataset.h for the geometry). The measurement behind the dual filter
// of transmittance h²Φ'_mn is E_mn(s,t) = ∫_S h²Φ'_mn(u,v) L(u,v,s,t) g(u,v,s,t) du dv, with the
// geometric term g = cos²θ/R² of parallel planes. Eq. 8 freezes g at the filter centre c_mn:
// g_mn(s,t) = d²/R_mn⁴, R_mn² = d² + (s − c_u)² + (t − c_v)². Biorthogonality (∫Φ'_mn Φ_kl = δ) then
// gives E_mn(s,t) ≈ h² · g_mn(s,t) · Σ_kl Φ_kl(s,t) L_mnkl (Eq. 9) and
//
//   ╔═════════════════════════════════════════════════════════════════════════════╗
//   ║  E'_mn(s,t) = Σ_kl Φ_kl(s,t) L_mnkl,  where g_mn,kl · L_mnkl are the         ║
//   ║  coefficients of E_mn / h² in the basis on M                                 ║
//   ╚═════════════════════════════════════════════════════════════════════════════╝
//
// With the bilinear (interpolating) basis on M, the coefficients are the pixel values and the
// deconvolution is a division per pixel: E'_mn(p) = E_mn(p) / (h² g_mn(p)). With the biquadratic
// basis on M the pixel values are Σ_l β2(k − l)·a_l: we solve for a_l (a separable B-spline
// prefilter, the small-support deconvolution the paper asks for), divide by g_mn at the node and
// convolve back with β2 at the nodes ([⅛, ¾, ⅛]) to give E' at the pixel centres.
#pragma once
#include <functional>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/nearfield/dataset.h"
#include "iblkit/nearfield/spotlight.h"

namespace ibl::nearfield {

// E'_mn for every filter position, index n·nx + m, each RGB (may hold negative texels).
std::vector<Image> incoming_radiance(const Dataset& ds);

// Places precomputed E' textures (from incoming_radiance) as spotlights; spotlights(ds, …) is this
// with incoming_radiance(ds).
std::vector<TexturedSpotlight> place_spotlights(const Dataset& ds, const std::vector<Image>& eprime,
                                                const Placement& placement, bool shadow = true);

// The far-field approximation: one point light at S's origin with a goniometric texture, as one
// spotlight with A = 1 m², support width 0 and E'(s,t) = I(ω)/cos θ for ω towards (s, t, d), so that
// irradiance() gives I(ω)·cos θ'/δ². `intensity(ω)` is in the luminaire frame; the texture has
// `resolution`² texels over [−extent, extent]² on the plane at distance d.
TexturedSpotlight far_field_spotlight(const std::function<Vec3(Vec3)>& intensity, double d, double extent,
                                      int resolution, const Placement& placement, bool shadow = true);

}  // namespace ibl::nearfield
