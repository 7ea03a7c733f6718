// An environment map: an image of radiance plus the mapping that says which direction each pixel sees.
#pragma once
#include <string>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/core/vec.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::sphere {

struct EnvMap {
  Image image;
  Mapping mapping;

  EnvMap(Image img, Mapping m);
  // Builds the mapping from the image's shape (detect_mapping) unless `kind` is given.
  static EnvMap from_image(Image img, std::optional<MappingKind> kind = std::nullopt, std::string_view name = {},
                           double dead_angle_deg = 0.0);

  // Bilinear radiance towards unit direction d (all channels into out; RGB via sample_rgb).
  // Cube layouts filter within a face; directions without data give 0.
  void sample(Vec3 d, float* out) const;
  Vec3 sample_rgb(Vec3 d) const;

  // ∫ L dω per channel, with exact pixel solid angles (pixels without data count 0).
  std::vector<double> integral() const;
};

// Per-pixel solid angles as a one-channel image (0 where the pixel has no data).
Image solid_angle_image(const Mapping& m);

struct ResampleDesc {
  int max_supersampling = 8;         // most sub-samples per axis for one output pixel
  Mat3 rotation = Mat3::identity();  // output direction d looks up the input at rotationᵀ·d
                                     // (i.e. the environment is rotated by `rotation`)
  ProgressFn progress;               // "resample", by rows done
};

// Resamples src into mapping dst (any size). Each output pixel averages n×n bilinear sub-samples,
// n growing with the ratio of output to input pixel solid angle, so that ∫L dω is preserved when
// shrinking and nothing aliases. Output pixels without a direction are 0.
Image resample(const EnvMap& src, const Mapping& dst, const ResampleDesc& desc = {});

}  // namespace ibl::sphere
