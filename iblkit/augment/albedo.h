// The proxy's diffuse albedo per photograph pixel, by the CPU composite's own estimator (proxy_light.h's
// proxy_terms and proxy_albedo, composite.h's method): the camera ray through the pixel's centre meets the
// proxy at y, E₀(y) is the captured light there (`samples` stratified patch samples with the proxy's
// visibility) and ρ = π · photo / E₀ per channel. Independent of the object: a real-time compositor (augment/gl/)
// computes it once per photograph and light, and then moves the object freely.
#pragma once
#include <cstdint>

#include "iblkit/augment/light.h"
#include "iblkit/core/image.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::augment {

struct AlbedoEstimate {
  Image albedo;              // RGB, ρ (0 off the proxy and where unlit; > 1 where the light misses some)
  int64_t proxy_pixels = 0;  // pixels whose centre ray meets the proxy
  int64_t over_one = 0;      // of those, with ρ > 1 in some channel
  int64_t unlit = 0;         // of those, with E₀ = 0 in some channel
};

// photo: RGB, cam's size. Throws ibl::Error on sizes that disagree or samples < 1.
AlbedoEstimate estimate_albedo(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                               const LocalRadiance& light, int samples = 64, uint64_t seed = 1);

}  // namespace ibl::augment
