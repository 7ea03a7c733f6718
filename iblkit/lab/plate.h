// The lab shoots a backplate (docs/capture.md, "The lab shoots a backplate"): the scene photographed by a
// camera (its lens too: geometry::Camera's intrinsics and distortion) through capture/'s sensor model, with a
// chessboard printed on the floor for `camera solve` and without the object; and the truth, the same
// photograph with the object really in the scene: the same exposure, the same noise stream (the sensor's noise
// is keyed by pixel, so the pixels the object does not change come out as the backplate's), the same JPEG.
#pragma once
#include <optional>

#include "iblkit/capture/camera_solve.h"
#include "iblkit/capture/sensor.h"
#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/lab/scene.h"

namespace ibl::lab {

// Prints `board` onto the floor it lies on: its (cols + 1) × (rows + 1) squares, dark where the board's
// convention has them (capture::Board: the square between the first four inner corners is dark; a ChArUco
// board as OpenCV draws it, through the "cv" plugin), on a white margin of one square, 1 mm above the board's
// plane on the side u × v points to. Not part of the proxy.
inline constexpr double kBoardDark = 0.04, kBoardWhite = 0.85;  // the print's albedos
void add_board(Scene& scene, const capture::Board& board);

struct PlateDesc {
  geometry::Camera camera;     // pose, lens and frame size
  int samples = 8;             // n×n rays per pixel
  capture::SensorDesc sensor;  // exposure_s ≤ 0 (not its default): metered, the median at middle grey (0.18),
                               // the 99.5th percentile at most at 80 % of saturation
  geometry::TriMesh object;    // the inserted object, for the truth (empty: no truth)
  Vec3 albedo{0.7, 0.7, 0.7};  // its Lambertian albedo
  RenderDesc render;           // light estimation (bounces: the scene's)
};

struct Plate {
  Image backplate;        // code values in [0, 1], 3 channels, the scene without the object
  Image truth;            // the same with the object (empty without one)
  Image truth_mask;       // one channel: 1 where the pixel centre sees the object
  double exposure_s = 0;  // the exposure used
  // The light on the sensor (before it: the radiance as the lens forms it) and the sensor with the exposure
  // used, for a raw file of the same shot (capture::expose_dng).
  Image backplate_radiance, truth_radiance;
  capture::SensorDesc sensor;
  int64_t saturated = 0;  // backplate pixels with a channel at the top code
};

// `scene` not built (the object is added to a copy). Board, if any, already added (add_board).
Plate shoot_plate(const Scene& scene, const PlateDesc& desc, const ProgressFn& progress = {});

}  // namespace ibl::lab
