// The ray offsets of every augment estimator, CPU and GL paths alike (one place, so that the albedo
// estimate, the composite, the light split and the soft-light factor start and stop their rays alike).
#pragma once
#include <cmath>
#include <limits>

namespace ibl::augment {

constexpr double kRayEpsilon = 1e-4;       // metres: secondary rays start this far off the surface
constexpr double kShadowShorten = 1e-3;    // relative: rays towards a patch stop this short of it
constexpr double kUnlitIrradiance = 1e-9;  // W/m²: below this the proxy's albedo is unknown
constexpr double kDepthInFront = 0.98;     // a probe depth this much shorter than the proxy's hit is a lamp

// Where a ray towards a patch `dist` metres away stops (the patch itself not counted as an occluder).
inline double patch_tfar(double dist) {
  return std::isinf(dist) ? std::numeric_limits<double>::infinity() : dist * (1 - kShadowShorten) - kRayEpsilon;
}

}  // namespace ibl::augment
