// The captured light split for a real-time compositor (augment/gl/): its concentrated part — the texels
// brighter than `threshold` × the map's mean radiance (the sun, lamps, bright windows) — becomes a few
// localised lights (median cut of that part, Debevec 2005; each light put where its ray from the map's
// centre meets the proxy, or the probe's depth map says a lamp hangs, or at infinity where the ray leaves
// the proxy), which cast shadow maps; the rest of the map (sky, walls, floor) stays a smooth environment,
// whose shadow is the soft term (sphere_occlusion.h) and whose irradiance shades the object (its cosine convolution).
// The lights and the soft map together hold all of the map's power (test AugmentSplit.*).
#pragma once
#include <algorithm>
#include <vector>

#include "iblkit/augment/light.h"
#include "iblkit/core/image.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::augment {

struct HardLight {
  Vec3 direction;          // unit, from the map's centre towards the light
  Vec3 irradiance;         // RGB W/m² at the centre, normal incidence (Σ L dω of its region)
  double solid_angle = 0;  // sr of its region, seen from the centre
  bool distant = true;     // false: a point light at `position`
  Vec3 position;           // world metres (local lights); intensity irradiance · |position − centre|² W/sr
  // Irradiance on a surface at x with unit normal n (no visibility): inverse square from a local light.
  Vec3 at(Vec3 centre, Vec3 x, Vec3 n) const;
};

// What the threshold is compared with: a texel's mean RGB radiance, negative channels as 0.
inline double split_measure(Vec3 L) { return (std::max(0.0, L.x) + std::max(0.0, L.y) + std::max(0.0, L.z)) / 3; }

struct SplitDesc {
  int lights = 16;           // most hard lights (fewer when fewer texels are bright)
  double threshold = 8;      // a texel is hard when its mean RGB radiance exceeds this × the map's mean (0: none hard)
  int irradiance_size = 32;  // lat-long height of the soft irradiance map (and of the soft map it is summed over)
};

struct SplitLight {
  Vec3 centre;                  // the map's centre, world metres
  std::vector<HardLight> hard;  // the concentrated light
  Image soft;                   // lat-long radiance (RGB, 2H × H): the map less the hard texels
  Image soft_irradiance;  // lat-long (RGB, 2·irradiance_size × irradiance_size): E_soft(n) = ∫ L_soft max(0, n·ω) dω,
                          // summed over the soft map (render::prefilter_phong, exponent 1, times π)
  double hard_share = 0;  // share of the map's ∫ mean(RGB) dω in the hard lights
};

// `proxy` places the lights (the map's own depth map, where it has one, places lamps in front of it).
// Throws ibl::Error on a bad description or a map without light.
SplitLight split_light(const LocalRadiance& light, const geometry::TriMesh& proxy, const SplitDesc& desc = {});

}  // namespace ibl::augment
