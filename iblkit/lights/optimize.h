// Irradiance optimisation (Madsen, Sørensen & Vittrup 2003; Madsen & Laursen 2007 §4.2): N directional
// lights whose irradiance at M normals matches the probe's ground truth, by Levenberg–Marquardt with
// an analytic Jacobian.
//
// What makes it converge for every N from 1 to 256 (the paper's version failed above 64), fast:
//  - variable projection [1]: for fixed directions the irradiance is linear in the lights' RGB
//    irradiance, so each iteration solves that part exactly — non-negative least squares per channel
//    (nnls.h) — and Levenberg–Marquardt moves only the 2N directions, on the reduced Gauss–Newton
//    matrix (the Schur complement of the irradiance block [2]). Irradiance is never negative, a light
//    that should be dark is exactly 0 (no slow crawl of log E towards −∞), and there is no scaling
//    mismatch between irradiance and angle parameters;
//  - directions move on each light's tangent plane (normalize(d + a·t + b·s)): no poles;
//  - initialisation from a cut with N lights (variance cut by default), residuals relative to the
//    ground truth (1/max(E_gt, 1% of the mean)), as the error is reported;
//  - the Jacobian's sparsity: a light affects only the normals within 90° of it; the Gram matrices are
//    built from 64-normal patches, each with only the lights in front of it (optimize.cpp);
//  - coarse to fine: converged solves on the 1280 and 5120 normals of level-3 and level-4 icospheres
//    (where they are at least 10× over-determined) warm-start the solve on the full set;
//  - the curvature that Gauss–Newton misses at the kink of max(0, n·d) (the "horizon term", optimize.cpp)
//    in the step's model;
//  - a real stopping rule, not an iteration cap. With τ = OptimizeDesc::tolerance, a stage has converged
//    when (a) the last accepted step lowered the cost by less than τ of it AND the Gauss–Newton decrement
//    ½gᵀH⁻¹g (what a full Gauss–Newton step would still gain if the model held — a scale-free gradient
//    test) is below τ of the cost; or (b) the last 3 accepted steps together lowered it by less than τ.
//    (b) is needed because the cost is only piecewise smooth: every normal that crosses a light's horizon
//    puts a kink in it, so at 20480 normals the gradient does not vanish at the minimum (the decrement
//    stays at a few 10⁻⁶ of the cost while the cost no longer moves in its 7th digit). Steps damped past
//    λ = 10¹² without a decrease also end the stage ("converged" only if the decrement test holds).
//
// References
//  [1] Golub & Pereyra, "Separable nonlinear least squares: the variable projection method and its
//      applications", Inverse Problems 19 (2003).
//  [2] Kaufman, "A variable projection method for solving separable nonlinear least squares problems",
//      BIT 15 (1975): the Jacobian approximation whose Gauss–Newton matrix is that Schur complement.
//  [3] Nielsen, "Damping parameter in Marquardt's method", IMM-REP-1999-05 (the damping update).
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/error.h"
#include "iblkit/core/progress.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::lights {

// The icosphere levels the M normals may have: 20·4^level face centres, 20 to 327680.
inline constexpr int kMinNormalsLevel = 0, kMaxNormalsLevel = 7;

struct OptimizeDesc {
  int count = 16;                     // number of lights N ≥ 1
  int normals_level = 5;              // icosphere level of the M normals (5: the 20480 of Madsen & Laursen)
  std::string init = "variance-cut";  // initial lights: "variance-cut" or "median-cut"
  double floor_fraction = 0.01;       // residual weight 1/max(E_gt, floor_fraction·mean E_gt), per channel
  double tolerance = 1e-6;            // τ of the stopping rule above (relative cost decrease)
  double coarse_tolerance = 1e-4;     // the same for the coarse (warm-start) stages
  int max_iterations = 1000;          // safety cap on Levenberg–Marquardt steps per stage (reported when hit)
  bool coarse_to_fine = true;         // warm starts on level-3 and level-4 normals before the full set
  double min_separation_deg = 0;      // merge lights that end closer than this and re-solve (0: off)
  ProgressFn progress;                // optional progress callback
};

struct OptimizeReport {
  int iterations = 0;         // Levenberg–Marquardt steps tried, all stages (each costs one Gram pass)
  int final_iterations = 0;   // of those, on the full normal set
  int coarse_iterations = 0;  // of those, on the coarse normal sets
  int dark_lights = 0;        // lights that ended with zero irradiance (the fit has no use for them)
  double initial_cost = 0;    // ½ Σ r² of the initial lights on the final normals
  double final_cost = 0;      // ½ Σ r² at the end
  double last_decrease = 0;   // relative cost decrease of the last accepted step (full set)
  double decrement = 0;       // ½ gᵀH⁻¹g / cost at the end: what a full Gauss–Newton step would still gain
  double seconds = 0;         // wall time of the optimisation (ground truth excluded)
  bool converged = false;     // the stopping rule was met on the full set (false: iteration cap)
  std::string termination;    // which test ended the final stage, with its figures
};

// The optimiser is part of every build (it needs only Eigen).
inline constexpr bool kHaveOptimizer = true;

// Throws ibl::Error (Value) unless level ∈ [kMinNormalsLevel, kMaxNormalsLevel].
void check_normals_level(int level);

// The starting lights of the optimiser: desc.init's cut ("variance-cut" or "median-cut") of desc.count
// lights. Throws ibl::Error for another name.
LightSet initial_lights(const sphere::EnvMap& env, const OptimizeDesc& desc);

// Optimises N lights for a probe; normals and their ground truth are computed from desc.
LightSet optimize_lights(const sphere::EnvMap& env, const OptimizeDesc& desc, OptimizeReport* report = nullptr);

// The same with given normals and their ground-truth irradiance (to share them between several N).
// `initial` are the starting lights (any count ≥ 1; desc.count and desc.init are ignored).
LightSet optimize_lights_from(const sphere::EnvMap& env, const std::vector<Vec3>& normals,
                              const std::vector<Vec3>& ground_truth, const std::vector<Light>& initial,
                              const OptimizeDesc& desc, OptimizeReport* report = nullptr);

}  // namespace ibl::lights
