// The soft light that reaches each triangle of the virtual object, as the CPU reference computes it, for
// the real-time path (augment/gl/), which shades the object with the soft map's irradiance as seen from the
// map's centre.
#pragma once
#include <cstdint>
#include <vector>

#include "iblkit/augment/light.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::augment {

// For the real-time path (augment/gl/), which shades the object with the soft map's irradiance E_c(n) as seen
// from the map's centre c: the factor that turns it into what each object triangle receives, as this reference
// computes it. Per triangle (its centre z, its face normal n, the side the normal points to), per channel,
//
//   f = Σ_k c_k(z) V(z, q_k) s_k / Σ_k c_k(c)      over patch samples k of the light (light.h) that are soft,
//
// c_k(x) patch k's contribution at x with normal n, V the visibility past the proxy and the object itself, s_k the
// patch's shadow factor (the object's shadow on the proxy it sees, from all of the light: the floor under an
// object does not light its underside). The denominator estimates E_c(n) from the same samples, so f carries the
// parallax between c and z as well as what is hidden (a triangle near a lit floor sees more of it than c does; one
// facing down 15 cm below c does not see the walls between the two heights): f may exceed 1, and is clamped to
// [0, 16] (docs/augment.md measures what the parallax term changes). "Soft": the texels split_light leaves in the soft
// map (mean RGB radiance at most `threshold` × the map's mean; 0: every texel). Where every sampled patch is distant
// and nothing is hidden, f is exactly 1. proxy = false: the object's own occlusion alone (V past the object, s = 1,
// both sums at z), which stays right while the object moves (iblkit view).
struct SoftVisibilityDesc {
  int samples = 64;         // patch samples per triangle
  int pool_rays = 1536;     // each triangle's f pools the sums of the triangles around it (up to 3 rings of
                            // shared vertices) until they hold this many rays (≤ samples: none pooled)
  double threshold = 8;     // as SplitDesc::threshold
  bool proxy = true;        // the proxy occludes and carries the object's shadow (as composite())
  int shadow_samples = 64;  // as CompositeDesc::light_samples, for the shadow on the proxy's patches
  int shadow_cone = 64;     // as CompositeDesc::bounce_samples
  uint64_t seed = 1;
};
std::vector<Vec3> soft_visibility(const LocalRadiance& light, const geometry::TriMesh& proxy,
                                  const geometry::TriMesh& object, const SoftVisibilityDesc& desc = {});

}  // namespace ibl::augment
