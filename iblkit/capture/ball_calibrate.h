// The chrome ball's reflectance calibrated from a light seen both in the ball and directly
// (docs/capture.md, "Calibrating the ball's reflectance"): the ball's view of a light whose radiance a
// second linear image gives in the same units — a photograph of the light itself by the same camera at the
// same exposure (after `hdr merge` with the same curve and scale) — so that r0 = the reflection's
// radiance / the light's, with the metal's rise towards grazing taken out at each pixel's own incidence.
// Radiance is kept by a mirror (only scaled by the reflectance), so a reflection pixel wholly inside the
// light's image reads R(θ)·L whatever the ball's magnification; the light must be larger than a few pixels
// in the ball (a window, a softbox, a panel; not a bulb).
#pragma once
#include "iblkit/capture/ball.h"
#include "iblkit/core/image.h"

namespace ibl::capture {

// A rectangle in continuous pixel coordinates: [x, x + w] × [y, y + h] (y down).
struct PixelBox {
  double x = 0, y = 0, w = 0, h = 0;
};

struct ReflectanceFit {
  Vec3 r0;                       // normal-incidence reflectance per channel (probe from-ball --reflectance)
  Vec3 light;                    // the light's radiance (median of the direct image's light pixels)
  double incidence_min_deg = 0;  // incidence angles of the reflection pixels used
  double incidence_max_deg = 0;
  int ball_pixels = 0, direct_pixels = 0;  // pixels used
  double spread = 0;  // the reflection pixels' ratios: (p75 − p25) / median of their luminance; ≈ 0 for a
                      // uniform light wholly resolved
};

// The light's pixels in each box are those whose luminance (in the ball: divided by the metal's rise
// F(θ)/F(0) at the pixel's incidence) is at least `plateau` × the box's 95th percentile; ball pixels
// count only inside 0.97 of the silhouette's radius. r0 per channel = median over the reflection pixels
// of their rise-corrected value / the light's median. Throws naming `what` (the options) when a box
// leaves its image, misses the ball, holds fewer than 4 light pixels, the light is not positive, or the
// reflection comes out brighter than the light (r0 > 1.05: different lights, or different units).
ReflectanceFit calibrate_reflectance(const BallView& view, const BallReflectance& metal, PixelBox in_ball,
                                     const Image& direct, PixelBox in_direct, double plateau = 0.8,
                                     const std::string& what = "--light-in-ball/--light");

}  // namespace ibl::capture
