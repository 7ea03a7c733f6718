// Tone mapping of HDR images into displayable previews.
#pragma once
#include "iblkit/core/image.h"

namespace ibl::io {

enum class ToneCurve { Clamp, Reinhard, Aces };

struct ToneMapDesc {
  bool auto_exposure = true;    // scale so that the median luminance lands on `key`
  double key = 0.18;            // target for the median luminance with auto exposure
  double exposure_stops = 0.0;  // added on top (or alone when auto_exposure is false)
  ToneCurve curve = ToneCurve::Aces;
};

// The linear scale that auto exposure would pick for img (1 for an all-black image).
double auto_exposure_scale(const Image& img, double key = 0.18);

// Returns a linear-light RGB image in [0,1] (write it as .png to get sRGB encoding).
Image tonemap(const Image& img, const ToneMapDesc& desc = {});

// False colour for a one-channel image of values in [0, vmax] (errors, differences): black → blue →
// green → yellow → red, clamped above vmax; negative or NaN values show as grey. Linear-light RGB.
Image false_colour(const Image& values, double vmax);

}  // namespace ibl::io
