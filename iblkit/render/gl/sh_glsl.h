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

// Runs sh_eval on the GPU at each direction (needs a current context); returns bands² values per
// direction. For tests and for checking a driver.
std::vector<float> sh_eval_on_gl(int bands, const std::vector<Vec3>& directions);

}  // namespace ibl::render::gl
