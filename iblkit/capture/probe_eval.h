// How far a probe made from photographs is from the truth (docs/capture.md): the irradiance it gives at a
// set of normals, and the mean relative luminance difference of two such sets — the figure the chrome-ball
// tests, `lab shoot`'s chain and the demo's capture step report.
#pragma once
#include <vector>

#include "iblkit/core/vec.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::capture {

// E(n) = Σ L·max(0, n·ω)·dω over the probe's pixels (exact solid angles), a 4-channel probe's pixels
// weighted by their alpha (0 where no view saw the direction).
std::vector<Vec3> probe_irradiance(const sphere::EnvMap& probe, const std::vector<Vec3>& normals);

// mean over i of |Y(a_i) − Y(b_i)| / Y(b_i) (Y the luminance); b is the reference. Throws ibl::Error on sizes
// that differ or a reference of no light.
double mean_relative_luminance_error(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

}  // namespace ibl::capture
