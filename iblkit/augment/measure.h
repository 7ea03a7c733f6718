// How far a composite is from the truth (a lab photograph of the scene with the object really in it),
// in three parts (docs/augment.md):
//   object     Σ|c − t| / Σ t over the pixels the object covers wholly (mask = 1), RGB L1
//   shadow     Σ|c − t| / Σ |p − t| over the pixels the object darkens: Y(p) − Y(t) > τ·Y(p) (p the
//              photograph without the object): the error relative to the shadow signal
//   unchanged  Σ|c − t| / Σ t over the other pixels the object does not touch (|Y(p) − Y(t)| ≤ τ·Y(p))
// Y is the luminance averaged over the pixel's 3×3 neighbourhood (only for deciding which pixel is which:
// a path-traced truth's grain is not a shadow); the sums are over single pixels.
#pragma once
#include <cstdint>

#include "iblkit/core/image.h"

namespace ibl::augment {

struct CompositeErrors {
  double object = 0, shadow = 0, unchanged = 0;
  int64_t object_pixels = 0, shadow_pixels = 0, brightened_pixels = 0, unchanged_pixels = 0;
  double shadow_signal = 0;  // mean darkening over the shadow pixels, relative to the photograph
};

// All four images of one size (mask: 1 channel, the object's coverage). τ = threshold.
CompositeErrors measure(const Image& photo, const Image& composite, const Image& truth, const Image& mask, double threshold = 0.02);

}  // namespace ibl::augment
