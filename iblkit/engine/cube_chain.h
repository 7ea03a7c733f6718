// Cube maps with a mip chain, as engines sample them: level m is a strip of six square faces
// +X −X +Y −Y +Z −Z of S_m = max(1, S >> m) texels (sphere/'s `cubestrip` layout: face f at
// x ∈ [f·S_m, (f+1)·S_m); texel (s, t) with s right, t down, the GL/Vulkan cube orientation of
// docs/conventions.md). Lookups are bilinear within a face (clamped at its edges) and linear
// between levels, like a GL sampler without seamless filtering.
#pragma once
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/core/vec.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::engine {

struct CubeChain {
  std::vector<Image> levels;  // RGB strips, 6·S_m × S_m

  int size(int level = 0) const { return levels[static_cast<size_t>(level)].height(); }
  int count() const { return static_cast<int>(levels.size()); }
  // Bilinear radiance of level `level` towards d (any length > 0).
  Vec3 sample(Vec3 d, int level) const;
  // Linear between levels ⌊lod⌋ and ⌊lod⌋ + 1 (lod clamped to [0, count − 1]).
  Vec3 sample(Vec3 d, double lod) const;
};

// Direction (unit) through the centre of texel (x, y) of face `face` of an S×S face.
Vec3 cube_texel_direction(int face, int x, int y, int size);
// Exact solid angles of the S×S texels of one face (the same for all six), row-major.
std::vector<double> cube_face_solid_angles(int size);

// The probe resampled (area-preserving, sphere::resample) to a cube of face size `size`, after
// turning the environment by `rotation` (g(d) = f(rotationᵀ d)) — or, for a cube-map probe of that
// face size and a rotation that maps texel centres onto texel centres (a mirror, quarter turns),
// its texels moved as they are — then halved down to 1×1 by
// solid-angle-weighted 2×2 averages (each level keeps ∫L dω of the one above).
// `levels` 0 keeps the whole chain; otherwise the first `levels` levels.
CubeChain build_cube_chain(const sphere::EnvMap& probe, int size, const Mat3& rotation = Mat3::identity(),
                           int levels = 0);

// Exact convolution of a cube level with a rotationally symmetric kernel k(c) ≥ 0 of c = r·l
// (zero for c ≤ 0):
//
//   out(r) = Σ_j L_j k(r·l_j) Ω_j / Σ_j k(r·l_j) Ω_j      over every texel j of `source`,
//
// for r through the centre of every texel of an output cube of face size `out_size`. Cost: the
// product of the two texel counts; the caller picks a source fine enough for the kernel.
template <typename Kernel>
Image convolve_cube(const Image& source, int out_size, const Kernel& kernel, const ProgressFn& progress = {});

}  // namespace ibl::engine

#include "iblkit/engine/cube_chain_impl.h"
