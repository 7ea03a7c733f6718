// The split-sum BRDF table [1] ("DFG"): for n·v = μ and perceptual roughness ρ (α = ρ²), the
// directional albedo of the GGX specular lobe with Fresnel factored out,
//
//   ∫ f(v, l) (n·l) dl = F0 · scale(μ, ρ) + F90 · bias(μ, ρ),     F = F0 (1 − Fc) + F90 Fc, Fc = (1 − v·h)⁵
//
//   scale = ∫ D G₂/(4 μ (n·l)) (1 − Fc) (n·l) dl,    bias = ∫ D G₂/(4 μ (n·l)) Fc (n·l) dl,
//
// with the height-correlated Smith masking-shadowing G₂ of Heitz [2] (the V term of Filament [3]):
//   V = G₂/(4 μ (n·l)) = ½ / ((n·l)√(μ²(1−α²)+α²) + μ√((n·l)²(1−α²)+α²)).
// Quadrature: h is drawn from D(h)(n·h) by the GGX inverse CDF u2 ↦ θ_h, so that
//   scale + bias = ∫∫ 4 V (n·l)(v·h)/(n·h) du2 dφ/π  over n·l > 0 (φ ∈ [0, π]: v lies in the x–z
// plane, the integrand is even in φ); n_θ midpoints in s with u2 = 1 − (1 − s)⁴ (grazing v reflects
// off near-horizon h, which the inverse CDF packs next to u2 = 1), and per row n_φ midpoints over
// the φ interval where n·l > 0 (found in closed form), where the integrand is smooth.
// Limits (dfg_test): ρ → 0 gives scale = 1 − (1 − μ)⁵, bias = (1 − μ)⁵ (a mirror: G₂ → 1).
//
// Table layout (docs/engines.md): texel (i, j) of a size×size table holds μ = (i + ½)/size and
// ρ = (j + ½)/size, row j = 0 first (the top row of a PNG/EXR, the first row a GL upload reads
// at t = 0), so a shader reads it at (μ, ρ) without a flip; R = scale, G = bias (B = 0 in PNG/EXR).
//
// References
//  [1] B. Karis, "Real Shading in Unreal Engine 4", SIGGRAPH 2013.
//  [2] E. Heitz, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 2014.
//  [3] R. Guy, M. Agopian, "Physically Based Rendering in Filament" (Filament.md) §4.4.2, §5.3.4.
#pragma once
#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"

namespace ibl::engine {

// (scale, bias) at one point; `n` is the grid's n_θ (n_φ = n/2).
Vec2 dfg(double mu, double roughness, int n = 128);

struct DfgDesc {
  int size = 128;  // table size (4..1024)
  int n = 128;     // quadrature n_θ per texel (n_φ = n/2; 8..2048)
};
// RGB table: R = scale, G = bias, B = 0.
Image dfg_table(const DfgDesc& desc = {});

}  // namespace ibl::engine
