// Ground truth at a point: the local radiance map at any resolution, its SH coefficients and the
// irradiance for any normals — the answers the ILF, fusion and near-field modules are judged against.
#pragma once
#include <vector>

#include "iblkit/core/progress.h"
#include "iblkit/lab/scene.h"
#include "iblkit/sh/coeffs.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::lab {

struct TruthDesc {
  int size = 128;             // lat-long height of the radiance map (width 2·size)
  int samples = 4;            // n×n sub-pixel samples per pixel (the map is a pixel-area average)
  int area_samples = 64;      // shadow rays per area light per diffuse hit (more than a capture: less noise)
  int bands = 3;              // SH bands of the projection (0: none)
  std::vector<Vec3> normals;  // irradiance is computed for each (normalised here)
  uint64_t seed = 1;          // random streams
  double blind_cone_deg = 0;  // > 0: also project `sh_visible`, the map without the directions within
                              // this angle of blind_axis (a mirror-ball sequence's dead angle)
  Vec3 blind_axis{0, 0, -1};  // world axis of that cone (−Z: a ball seen along −Z, identity rotation)
};

struct Truth {
  sphere::EnvMap radiance{Image(2, 1, 3), sphere::Mapping(sphere::MappingKind::LatLong, 2, 1)};  // lat-long map
  sh::Coeffs sh;                 // SH projection of `radiance` (sh::project; empty when bands = 0)
  sh::Coeffs sh_visible;         // the same without the light from inside the blind cone (per sub-sample:
                                 // what a sequence with that dead angle can see; empty unless asked)
  std::vector<Vec3> normals;     // the unit normals of `irradiance`
  std::vector<Vec3> irradiance;  // E(n) = ∫ L(ω) max(0, n·ω) dω, W/m²
};

// Irradiance of a radiance map for normal n by quadrature over its pixels with exact solid angles.
Vec3 irradiance(const sphere::EnvMap& map, Vec3 n);

Truth ground_truth(const Scene& scene, Vec3 position, const TruthDesc& desc, const ProgressFn& progress = {});

// Radiance arriving at `position` from each unit direction (lab::radiance along the ray leaving it), the
// mean of `streams` independent random streams per ray (keyed by desc.seed and the ray's index); in
// parallel. For pictures other than sphere maps, e.g. the true view beside a fused one.
std::vector<Vec3> radiance_along(const Scene& scene, Vec3 position, const std::vector<Vec3>& directions,
                                 const RenderDesc& desc, int streams = 4);

}  // namespace ibl::lab
