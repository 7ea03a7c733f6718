#include "iblkit/engine/diffuse.h"

#include <algorithm>

#include "iblkit/core/error.h"

namespace ibl::engine {

Image irradiance_cube(const sphere::EnvMap& probe, int size, const Mat3& rotation, const ProgressFn& progress) {
  if (size < 1 || size > 256) fail(ErrorKind::Value, "irradiance cube size {} outside 1..256", size);
  const int src = std::clamp(2 * size, 8, 32);
  CubeChain chain = build_cube_chain(probe, src, rotation, 1);
  return convolve_cube(
      chain.levels[0], size, [](double c) { return c; }, progress);
}

}  // namespace ibl::engine
