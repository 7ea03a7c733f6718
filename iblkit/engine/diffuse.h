// The irradiance cube map engines read for diffuse lighting: for every normal n through a texel
// centre, the radiance of a white Lambertian surface,
//
//   L_d(n) = E(n)/π = (1/π) ∫ L(l) (n·l)⁺ dl,
//
// computed exactly (cube_chain.h convolve_cube with k(c) = c, normalised by Σ k Ω, which is the
// quadrature's π) over the probe's cube at face size min(32, size·2) — the cosine lobe is a
// hemisphere wide, so 32² texels a face leave < 0.1 % of quadrature error (diffuse_test).
// Filament's cmgen --ibl-irradiance and the glTF sample viewer's Lambertian map store the same
// E/π; three.js's PMREM stores radiance too.
#pragma once
#include "iblkit/core/progress.h"
#include "iblkit/engine/cube_chain.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::engine {

// Face size `size` (1..256); the environment turned by `rotation` first (as SpecularDesc).
Image irradiance_cube(const sphere::EnvMap& probe, int size = 32, const Mat3& rotation = Mat3::identity(),
                      const ProgressFn& progress = {});

}  // namespace ibl::engine
