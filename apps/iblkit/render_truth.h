// `iblkit render --truth SCENE`: the same frame photographed in a lab scene (the objects put into
// it, lit by its real emitters, lab::photograph) and the error of the rendered frame against it.
#pragma once
#ifdef IBLKIT_HAVE_GEOMETRY
#include <string>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/render/frame.h"

namespace iblcli {

struct TruthComparison {
  ibl::Image truth;        // the lab's photograph, RGB radiance
  ibl::Image error;        // |Y_render − Y_truth| / Y_truth per pixel where both see an object, else −1
  double rel_l1 = 0;       // Σ|Y_render − Y_truth| / Σ Y_truth over those pixels (all objects)
  double rel_l1_first = 0; // the same over the first object only (the one being lit; not the floor)
  double median_rel = 0;   // median of the per-pixel relative error (first object)
  double mean_render = 0, mean_truth = 0;  // mean luminance over the first object's pixels
  int pixels = 0, first_pixels = 0;
};

// Photographs d's objects (as Lambertian surfaces of their albedo) inside the lab scene file with
// d's camera, n×n rays per pixel and `bounces` indirect bounces, and compares `rendered` with it.
TruthComparison compare_with_lab(const std::string& scene_path, const ibl::render::FrameDesc& d,
                                 const ibl::render::RenderResult& rendered, int samples, int bounces,
                                 const ibl::ProgressFn& progress = {});

}  // namespace iblcli
#endif
