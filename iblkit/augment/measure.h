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
#include <vector>

#include "iblkit/core/image.h"

namespace ibl::augment {

struct CompositeErrors {
  double object = 0, shadow = 0, unchanged = 0;
  int64_t object_pixels = 0, shadow_pixels = 0, brightened_pixels = 0, unchanged_pixels = 0;
  double shadow_signal = 0;  // mean darkening over the shadow pixels, relative to the photograph
};

// All four images of one size (mask: 1 channel, the object's coverage). τ = threshold.
CompositeErrors measure(const Image& photo, const Image& composite, const Image& truth, const Image& mask,
                        double threshold = 0.02);

// A Monte Carlo truth is noisy; K ≥ 2 truths of different seeds measure how much. The composite is measured
// against their mean T̄, and the mean's own noise is estimated on the same pixels as
//   noise = measure(photo, T_1, T̄) / √(K − 1)
// (T_1 − T̄ has (K − 1)/K of one truth's variance, T̄ − T* has 1/K of it; for zero-mean noise the mean absolute
// values scale alike): the error a perfect composite would still show against T̄. errors − noise bounds the
// composite's own error from below, errors + noise from above (the triangle inequality, per pixel).
struct TruthErrors {
  CompositeErrors errors;  // the composite against the truths' mean
  CompositeErrors noise;   // the mean's own error, estimated (all zero for one truth)
  Image mean;              // T̄
};
// For looking at: red = luminance the composite has too much, green = too little, relative to the truth
// ((c − t)/t per pixel; 1 = 100 %).
Image error_picture(const Image& composite, const Image& truth);

TruthErrors measure_against(const Image& photo, const Image& composite, const std::vector<Image>& truths,
                            const Image& mask, double threshold = 0.02);

}  // namespace ibl::augment
