// Prefiltered environment maps for glossy reflection of a single probe: the probe convolved with
// the normalised Phong lobe of the material, tabulated over reflection directions in a lat-long map.
//
//   G_s(r) = ∫_S² L(ω) · (s+1)/(2π) · max(0, r·ω)^s dω                                        (1)
//
// This is the same G(r) the SH path computes (render/shading.h), without the SH band limit: with
// 5 bands a Phong lobe of exponent 20 keeps only its l ≤ 4 part (ρ̂_4(20) ≈ 0.60), so sharp
// highlights of small bright sources are lost; the prefiltered map keeps them up to its pixel size.
// Both renderers look the map up with the same bilinear filter (u repeats, v clamps, texel centres
// at half-integers), so the CPU reference and the GL frame read identical values.
//
// Resolution: the lobe's angular width is σ ≈ 1/√s (cos^s θ ≈ exp(−sθ²/2)); the map's pixels are
// π/H on a side, and H = the power of two ≥ 3π√s (three pixels per σ), between 16 and 256 rows (s ≲ 700 at three pixels
// per σ). Quadrature: the probe is first resampled (area-preserving) to a lat-long of H rows, and (1) is summed over
// its pixels with exact solid angles inside the lobe's support (r·ω)^s ≥ 10⁻⁶ only (rows and, per row, azimuths outside
// it are skipped).
#pragma once
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::render {

struct GlossyMap {
  double exponent = 20;  // Phong exponent s of the lobe the map is convolved with
  Image latlong;         // RGB, 2H × H, G_s(r) for r through each pixel centre (docs/conventions.md lat-long)
};

// Rows of the map for exponent s (the rule above).
int glossy_map_height(double exponent);
// Equation (1) for one exponent; height 0 picks glossy_map_height(exponent).
GlossyMap prefilter_phong(const sphere::EnvMap& probe, double exponent, int height = 0,
                          const ProgressFn& progress = {});
// Bilinear lookup of G_s at unit reflection direction r (the filter the GL renderer uses).
Vec3 lookup(const GlossyMap& map, Vec3 r);

}  // namespace ibl::render
