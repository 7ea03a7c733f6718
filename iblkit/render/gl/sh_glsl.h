// GLSL source of the real SH basis, generated from the same normalisation constants and the same
// recurrence as the C++ basis (iblkit/sh/basis.h): a test renders it on GL and compares with
// sh::eval_basis at many directions.
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/vec.h"

namespace ibl::render::gl {

// Defines SH_BANDS, SH_K and `void sh_eval(vec3 d, out float Y[SH_K])` (index k = l(l+1)+m).
std::string sh_glsl_source(int bands);

// The precomputed-table variant (Löw et al. §5 suggest it against their per-fragment evaluation):
// the same `sh_eval`, but reading Y_k(d) from a cube-map array with hardware bilinear filtering —
// layer j holds Y_{4j}…Y_{4j+3} in RGBA, each face table_size² texels (sampler u_sh_table).
std::string sh_table_glsl_source(int bands);

// The table's texels (RGBA float, ⌈bands²/4⌉ layers × 6 faces × size² in GL's cube-map face order
// +X −X +Y −Y +Z −Z, rows by t): sh::eval_basis at each texel centre's direction, the centres
// spread from edge to edge of the face (face coordinate (2i + 1 − size)/(size − 1)).
std::vector<float> sh_table_texels(int bands, int size);
// Uploads that table as a GL_TEXTURE_CUBE_MAP_ARRAY; the caller deletes the texture and sets the
// shader's u_sh_table_warp to sh_table_warp(size), which maps lookups onto those centres.
unsigned make_sh_table_texture(int bands, int size);
float sh_table_warp(int size);

// Runs sh_eval on the GPU at each direction (needs a current context); returns bands² values per
// direction. table_size > 0 runs the table variant with faces of that size. For tests and for
// checking a driver.
std::vector<float> sh_eval_on_gl(int bands, const std::vector<Vec3>& directions, int table_size = 0);

}  // namespace ibl::render::gl
