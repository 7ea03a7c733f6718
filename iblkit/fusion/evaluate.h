// Fused maps judged against a reference (`iblkit fuse eval`, the accuracy table of docs/fusion.md): at a
// point x, the fused lat-long map for every blend with and without the visibility test against the true
// local radiance map — the image error and the irradiance error on 20480 normals (an icosphere's face
// centres, as Madsen & Laursen's evaluation) — and, with a view direction, a pinhole view of the
// back-projected probes from x beside the true view (the thesis's Fig. 7.8).
//
// The reference is two functions, so that any source of truth will do: the lab's exact answers
// (lab::ground_truth, lab::radiance_along), a denser capture, a measured map.
#pragma once
#include <functional>
#include <optional>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/fusion/fuse.h"
#include "iblkit/fusion/probe_set.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::fusion {

struct Reference {
  // The true local radiance map at x: lat-long, `size` pixels high (FuseDesc::size; width 2·size).
  std::function<sphere::EnvMap(Vec3 x, int size)> radiance_map;
  // The true radiance arriving at x from each direction (needed only with EvalDesc::view).
  std::function<std::vector<Vec3>(Vec3 x, const std::vector<Vec3>& directions)> radiance_along;
};

struct EvalDesc {
  FuseDesc fuse;             // every fusing setting but those swept: blend, visibility (and mapping: lat-long)
  std::optional<Vec3> view;  // also a pinhole view (view_camera) from each point along this direction
};

struct EvalRow {
  Vec3 point;  // x
  Blend blend = Blend::Footprint;
  bool visibility = true;
  double image_rmse = 0;           // image_rmse(fused, truth)
  double irradiance_mean_rel = 0;  // mean relative irradiance error over the normals
  double irradiance_max_rel = 0;   // largest relative irradiance error
  CoverageStats coverage;          // of the fused map
};

struct ViewEval {
  Blend blend = Blend::Angle;
  bool visibility = true;
  Image image;  // RGB radiance, camera.width × camera.height
};

struct PointEval {
  sphere::EnvMap truth{Image(2, 1, 3), sphere::Mapping(sphere::MappingKind::LatLong, 2, 1)};  // the reference map
  std::vector<EvalRow> rows;   // nearest, angle, footprint (outer) × visibility off, on
  std::vector<LocalMap> maps;  // the fused map of each row
  // With EvalDesc::view:
  geometry::Camera camera;      // view_camera(x, *view)
  Image view_truth;             // the reference's view
  std::vector<ViewEval> views;  // visibility off, on (outer) × angle, footprint
};

// Solid-angle weighted RMS of the luminance difference, over the truth's mean luminance (0 for a black
// truth). Both maps in the same mapping and size; throws ibl::Error otherwise.
double image_rmse(const sphere::EnvMap& estimate, const sphere::EnvMap& truth);

// The pinhole of the views: 320×200 pixels, a 90° horizontal field of view, at x looking along
// `forward` (up +Y, or +Z when looking nearly straight up or down).
geometry::Camera view_camera(Vec3 x, Vec3 forward);

// Every pixel's centre direction, row-major; and radiances in that order back into an image.
std::vector<Vec3> pixel_directions(const geometry::Camera& camera);
Image view_image(const geometry::Camera& camera, const std::vector<Vec3>& radiance);

// Evaluates every blend × visibility at x (see the top of this file).
PointEval evaluate_point(const ProbeSet& set, Vec3 x, const Reference& reference, const EvalDesc& desc);

}  // namespace ibl::fusion
