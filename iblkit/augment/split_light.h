// The captured light split for a real-time compositor (augment/gl/): its concentrated part — the texels
// brighter than `threshold` × the map's mean radiance (the sun, lamps, bright windows) — becomes a few
// localised lights (median cut of that part, Debevec 2005; each light placed by lights/place.h's rule, the
// one fusion's lights follow: its texels' energy-weighted median depth, a texel's depth where the probe's
// depth map says a lamp hangs in front of the proxy, else where its ray from the map's centre meets the
// proxy; directional where most of its light comes from beyond the proxy), which cast shadow maps; the rest of the map
// (sky, walls, floor) stays a smooth environment, whose shadow is the soft term (sphere_occlusion.h) and whose
// irradiance shades the object (its cosine convolution). The lights and the soft map together hold all of the map's
// power (test AugmentSplit.*).
#pragma once
#include <algorithm>
#include <vector>

#include "iblkit/augment/light.h"
#include "iblkit/core/image.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/lights/light_set.h"

namespace ibl::augment {

// What the threshold is compared with: a texel's mean RGB radiance, negative channels as 0.
inline double split_measure(Vec3 L) { return (std::max(0.0, L.x) + std::max(0.0, L.y) + std::max(0.0, L.z)) / 3; }

struct SplitDesc {
  int lights = 16;           // most hard lights (fewer when fewer texels are bright)
  double threshold = 8;      // a texel is hard when its mean RGB radiance exceeds this × the map's mean (0: none hard)
  int irradiance_size = 32;  // lat-long height of the soft irradiance map (and of the soft map it is summed over)
};

struct SplitLight {
  Vec3 centre;            // the map's centre, world metres
  lights::LightSet hard;  // the concentrated light: lights::Light's (direction from the centre, irradiance there,
                          // solid angle; a position when placed on the proxy or by the depth map: a point light),
                          // origin = centre; lights::irradiance_at evaluates them
  Image soft;             // lat-long radiance (RGB, 2H × H): the map less the hard texels
  Image soft_irradiance;  // lat-long (RGB, 2·irradiance_size × irradiance_size): E_soft(n) = ∫ L_soft max(0, n·ω) dω,
                          // summed over the soft map (render::prefilter_phong, exponent 1, times π)
  double hard_share = 0;  // share of the map's ∫ mean(RGB) dω in the hard lights
};

// `proxy` places the lights (the map's own depth map, where it has one, places lamps in front of it).
// Throws ibl::Error on a bad description or a map without light.
SplitLight split_light(const LocalRadiance& light, const geometry::TriMesh& proxy, const SplitDesc& desc = {});

}  // namespace ibl::augment
