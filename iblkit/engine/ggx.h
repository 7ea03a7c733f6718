// GGX-prefiltered radiance for the split-sum approximation [1], with n = v = r: mip level m of a
// cube map holds, for every reflection direction r through a texel centre,
//
//   L̄_α(r) = ∫ L(l) D_α(h) (r·l)⁺ dl / ∫ D_α(h) (r·l)⁺ dl,     h = (r + l)/|r + l|        (1)
//
//   D_α(h) = α² / (π ((α² − 1)(r·h)² + 1)²),   (r·h)² = (1 + r·l)/2,
//
// with α = roughness² (the perceptual roughness of Filament and glTF). (1) is what Karis's
// estimator Σ L(l_k)(n·l_k) / Σ (n·l_k) over GGX-sampled l_k converges to; Filament's cmgen
// means the same (libs/ibl CubemapIBL::roughnessFilter) but reads its mips half a texel off their
// centres (Cubemap::filterAt): docs/engines.md, `Cmgen.SpecularMatchesIblLd`.
//
// Level m of N holds perceptual roughness ρ_m:
//   linear:   ρ_m = m/(N−1)                       (the iblkit/glTF/three.js-viewer convention)
//   filament: ρ_m = 1 − √(1 − m/(N−1))            (Filament picks lod = (N−1)·ρ(2−ρ); cmgen's levels)
//
// How each level is computed (measured in docs/engines.md):
//   - ρ = 0: the probe resampled to the cube (area-preserving; sphere::resample).
//   - exact: (1) summed over every texel of a level of the probe's cube chain fine enough for the
//     lobe (face size ≥ 4/α, at least 8), whenever (output texels × source texels) ≤ exact_budget.
//   - filtered importance sampling [2, 3] otherwise: `samples` Hammersley points of D_α(h)(n·h),
//     l = 2(n·h)h − n, weight (n·l), each read from the chain at
//     lod = ½ log₂(Ω_s/Ω_p) + 1, Ω_s = 4/(N D_α(h)), Ω_p = 4π/(6 S₀²) (Křivánek & Colbert; the +1
//     is their K = 4), trilinear.
//
// References
//  [1] B. Karis, "Real Shading in Unreal Engine 4", SIGGRAPH 2013 course notes.
//  [2] J. Křivánek, M. Colbert, "Real-time Shading with Filtered Importance Sampling", EGSR 2008.
//  [3] Filament, libs/ibl CubemapIBL.cpp (roughnessFilter) and Filament.md §9.5.
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/progress.h"
#include "iblkit/engine/cube_chain.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::engine {

enum class LodMapping { Linear, Filament };
std::string lod_mapping_name(LodMapping m);
LodMapping parse_lod_mapping(const std::string& name);  // "linear", "filament"; throws otherwise

// Perceptual roughness of level m of n (n ≥ 1; level 0 of 1 is 0).
double level_roughness(int m, int n, LodMapping mapping);

struct SpecularDesc {
  int size = 256;                       // face size of level 0 (a power of two, 8..4096)
  int levels = 0;                       // mip levels N; 0: log2(size) − 3 (cmgen's count: down to 16²)
  LodMapping lod = LodMapping::Linear;  // level → roughness rule above
  int samples = 1024;                   // importance samples per texel on FIS levels (16..65536)
  double exact_budget = 1.5e8;          // largest output × source texel count summed exactly
  Mat3 rotation = Mat3::identity();     // the environment is turned by this first (engine frames)
};

enum class LevelMethod { Resample, Exact, Importance };
std::string level_method_name(LevelMethod m);

struct SpecularLevel {
  double roughness = 0;  // perceptual
  double alpha = 0;      // roughness²
  LevelMethod method = LevelMethod::Resample;
  int source_size = 0;  // face size of the chain level read (exact) or of the chain's base (FIS)
  double seconds = 0;   // time this level took
};

struct SpecularCube {
  CubeChain cube;                   // level m: face size max(1, size >> m)
  std::vector<SpecularLevel> info;  // one per level
};

// The number of levels `levels` 0 stands for, and the checks of the desc (throws ibl::Error).
int specular_level_count(const SpecularDesc& desc);
SpecularCube prefilter_ggx(const sphere::EnvMap& probe, const SpecularDesc& desc, const ProgressFn& progress = {});

// Kernel of (1) for c = r·l (0 for c ≤ 0), unnormalised.
inline double ggx_kernel(double c, double alpha) {
  if (c <= 0) return 0;
  const double a2 = alpha * alpha, nh2 = 0.5 * (1 + c), d = (a2 - 1) * nh2 + 1;
  return a2 / (kPi * d * d) * c;
}

// (1) by brute force over the probe's own pixels (exact solid angles, `sub`² sub-pixel directions
// each), for direction r of the rotated frame: for tests and the accuracy table, not for maps.
Vec3 ggx_reference(const sphere::EnvMap& probe, Vec3 r, double alpha, const Mat3& rotation = Mat3::identity(),
                   int sub = 2);

}  // namespace ibl::engine
