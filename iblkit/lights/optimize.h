// Irradiance optimisation (Madsen, Sørensen & Vittrup 2003; Madsen & Laursen 2007 §4.2): N directional
// lights whose irradiance at M normals matches the probe's ground truth, by Levenberg–Marquardt with
// an analytic Jacobian (Ceres). Built only when Ceres is found (IBLKIT_HAVE_CERES); otherwise
// optimize_lights throws ibl::Error (Unsupported) saying so.
//
// What makes it converge for every N from 1 to 256 (the paper's version failed above 64):
//  - initialisation from a cut with N lights (variance cut by default), so every light starts on energy;
//  - irradiance as exp(q) per channel: never negative, and dark lights keep a gradient;
//  - the two angles of each light are measured in a frame where its initial direction is the equator's
//    origin, so no light starts near a parameterisation pole;
//  - residuals relative to the ground truth (1/max(E_gt, 1% of the mean)), as the error is reported;
//  - coarse to fine: solves on the 1280 and 5120 normals of level-3 and level-4 icospheres, then a few
//    iterations on the full set.
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/progress.h"
#include "iblkit/core/error.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::lights {

struct OptimizeDesc {
  int count = 16;                  // number of lights N ≥ 1
  int normals_level = 5;           // icosphere level of the M normals (5: the 20480 of Madsen & Laursen)
  std::string init = "variance-cut";  // initial lights: "variance-cut" or "median-cut"
  double floor_fraction = 0.01;    // residual weight 1/max(E_gt, floor_fraction·mean E_gt), per channel
  int max_iterations = 40;         // Levenberg–Marquardt iterations on the level-3 normals (or in all, without coarse stages)
  int mid_iterations = 20;         // iterations on the level-4 normals
  int final_iterations = 30;       // iterations on the full normal set after the coarse stages
  double function_tolerance = 1e-5;  // Ceres: converged when the cost changes by less than this fraction
  bool coarse_to_fine = true;      // warm starts on level-3 and level-4 normals before the full set
  double min_separation_deg = 0;   // merge lights that end closer than this and re-solve (0: off)
  ProgressFn progress;             // optional progress callback
};

struct OptimizeReport {
  int iterations = 0;          // LM iterations over all stages
  double initial_cost = 0;     // ½ Σ r² of the initial lights on the final normals
  double final_cost = 0;       // ½ Σ r² at the end
  double seconds = 0;          // wall time of the optimisation (ground truth excluded)
  bool converged = false;      // Ceres ended with CONVERGENCE on the final stage
  std::string termination;     // Ceres's termination message of the final stage
};

// True when this build has the optimiser.
#ifdef IBLKIT_HAVE_CERES
inline constexpr bool kHaveOptimizer = true;

// Optimises N lights for a probe; normals and their ground truth are computed from desc.
LightSet optimize_lights(const sphere::EnvMap& env, const OptimizeDesc& desc, OptimizeReport* report = nullptr);

// The same with given normals and their ground-truth irradiance (to share them between several N).
// `initial` are the starting lights (any count ≥ 1; desc.count and desc.init are ignored).
LightSet optimize_lights_from(const sphere::EnvMap& env, const std::vector<Vec3>& normals,
                              const std::vector<Vec3>& ground_truth, const std::vector<Light>& initial,
                              const OptimizeDesc& desc, OptimizeReport* report = nullptr);
#else
inline constexpr bool kHaveOptimizer = false;

[[noreturn]] inline LightSet optimize_lights(const sphere::EnvMap&, const OptimizeDesc&, OptimizeReport* = nullptr) {
  fail(ErrorKind::Unsupported,
       "the irradiance optimiser is not in this build: Ceres Solver was not found when iblkit was configured "
       "(install libceres-dev and reconfigure)");
}
[[noreturn]] inline LightSet optimize_lights_from(const sphere::EnvMap& env, const std::vector<Vec3>&,
                                                  const std::vector<Vec3>&, const std::vector<Light>&,
                                                  const OptimizeDesc& desc, OptimizeReport* report = nullptr) {
  optimize_lights(env, desc, report);
}
#endif

}  // namespace ibl::lights
