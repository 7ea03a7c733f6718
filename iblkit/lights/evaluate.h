// Irradiance of a probe and of a light set at a set of normals, and the errors between them as
// Madsen & Laursen 2007 §5 measure them (per colour channel, mean and max, averaged over RGB).
#pragma once
#include <vector>

#include "iblkit/core/progress.h"
#include "iblkit/core/vec.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::lights {

struct GroundTruthDesc {
  int tile = 16;          // pixels per side of the tiles that are classified against a normal's hemisphere
  bool cull = true;       // false: every pixel through the SIMD kernel for every normal (pure brute force)
  int normal_block = 64;  // normals per task (each task streams every tile once)
  ProgressFn progress;    // optional progress callback
};

// Ground-truth irradiance E(n) = Σ_pixels L·max(0, n·ω)·dω for every normal (RGB), exact pixel solid
// angles, every pixel with data and light, any mapping. Pixels without light are skipped.
std::vector<Vec3> irradiance_ground_truth(const sphere::EnvMap& env, const std::vector<Vec3>& normals,
                                          const GroundTruthDesc& desc = {});

// E(n) = Σ_i E_i·max(0, n·d_i) of a light set.
std::vector<Vec3> irradiance_from_lights(const std::vector<Light>& lights, const std::vector<Vec3>& normals);

struct ErrorDesc {
  // Guard for E_gt near 0: the relative error divides by max(E_gt, floor·mean_n E_gt) per channel, so
  // normals that see almost no light (the dark side of a sun-only sky) count an error relative to 1% of
  // the channel's mean irradiance instead of dividing by ~0.
  double floor_fraction = 0.01;
};

struct ErrorStats {
  double mean_rel = 0;  // mean over normals of |E_est − E_gt| / E_gt, averaged over RGB
  double max_rel = 0;   // max over normals of the same, averaged over RGB (as the paper's Fig. 4)
  double rms_rel = 0;   // √(mean of the squared relative error), averaged over RGB
  double rms_abs = 0;   // √(mean (E_est − E_gt)²), averaged over RGB (Pedersen's "RMS")
  Vec3 mean_est;        // mean over normals of E_est (RGB)
  Vec3 mean_gt;         // mean over normals of E_gt (RGB)
};

ErrorStats compare_irradiance(const std::vector<Vec3>& est, const std::vector<Vec3>& gt, const ErrorDesc& desc = {});

// Relative error of luminance per normal (same guard), for pictures.
std::vector<double> relative_error_luminance(const std::vector<Vec3>& est, const std::vector<Vec3>& gt,
                                             const ErrorDesc& desc = {});

}  // namespace ibl::lights
