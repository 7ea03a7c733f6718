// `iblkit render --truth SCENE`: the same frame photographed in a lab scene (the objects put into
// it, lit by its real emitters, lab::photograph) and the error of the rendered frame against it.
#pragma once
#ifdef IBLKIT_HAVE_GEOMETRY
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/render/frame.h"

namespace iblcli {

struct TruthComparison {
  ibl::Image error;         // |Y_render − Y_truth| / Y_truth per pixel where both see an object, else −1
  double rel_l1 = 0;        // Σ|Y_render − Y_truth| / Σ Y_truth over those pixels (all objects)
  double rel_l1_first = 0;  // the same over the first object only (the one being lit; not the floor)
  double median_rel = 0;    // median of the per-pixel relative error (first object)
  double mean_render = 0, mean_truth = 0;  // mean luminance over the first object's pixels
  int pixels = 0, first_pixels = 0;
};

// d's objects (as Lambertian surfaces of their albedo) photographed inside a lab scene with d's camera.
struct LabPhotograph {
  ibl::Image radiance;       // RGB radiance
  ibl::Image surface;        // scene surface index hit at each pixel centre (−1: none)
  std::vector<int> objects;  // the surface indices of d's objects, in d's order
  double median = 0;         // median luminance over the objects' pixels
  double ms = 0;             // time it took (set by the caller)
};
// n×n rays per pixel and `bounces` indirect bounces (match the capture's for a fair comparison).
LabPhotograph photograph_frame(const std::string& scene_path, const ibl::render::FrameDesc& d, int samples, int bounces,
                               const ibl::ProgressFn& progress = {});
// The rendered frame against the photograph, over the pixels where both see one of the objects.
TruthComparison compare(const LabPhotograph& photo, const ibl::render::RenderResult& rendered);

}  // namespace iblcli
#endif
