// Projection of environment maps onto SH and reconstruction into any mapping.
#pragma once
#include <functional>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/sh/coeffs.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::sh {

// c_lm = ∫ L(ω) Y_lm(ω) dω over the image, every pixel weighted by its exact solid angle (pixels
// without data count 0). RGB: grey images repeat channel 0; extra channels are ignored.
//
// Lat-long images take a separable path (project.cpp): the pixel's own integral of the basis is
// computed exactly in φ (a sinc factor per m) and with 4-point Gauss–Legendre in cos θ per row,
// i.e. the exact projection of the piecewise-constant image. Other mappings evaluate the basis at
// pixel centres (project_generic). Throws ibl::Error for bands outside 1..kMaxBands.
Coeffs project(const sphere::EnvMap& env, int bands, const ProgressFn& progress = {});
// The same on a view of pixels in mapping m (view and mapping of one size; rows may have any stride):
// the Python module projects numpy arrays with it without copying them.
Coeffs project(const ImageView& img, const sphere::Mapping& m, int bands, const ProgressFn& progress = {});
// The per-pixel path for any mapping (also the reference the lat-long path is tested against).
Coeffs project_generic(const sphere::EnvMap& env, int bands, const ProgressFn& progress = {});
Coeffs project_generic(const ImageView& img, const sphere::Mapping& m, int bands, const ProgressFn& progress = {});

// Projection of an analytic function f(d) → RGB with a quadrature exact for band-limited f of
// up to `degree` (default 2·(bands−1) + 8: exact for products with polynomials of degree ≤ 8).
Coeffs project_function(const std::function<Vec3(Vec3)>& f, int bands, int degree = -1);

// Radiance image (3 channels) of Σ c_k Y_k(d) in mapping m; pixels without a direction are 0.
Image reconstruct(const Coeffs& c, const sphere::Mapping& m);

}  // namespace ibl::sh
