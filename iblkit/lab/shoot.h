// The lab shoots like a camera (issue 29 §3, docs/capture.md "The lab shoots a chrome ball"): a
// chrome ball (capture::BallReflectance: its reflectance and the conductor's Fresnel rise) at a point of
// a lab scene, photographed by a pinhole camera at a given distance aimed at the ball's centre, with the
// camera body and a photographer (dark boxes at and behind the camera) in the scene so that they appear
// in the reflection. Each view is its own scene: the photographer of one side is not in the other's.
// Rays that meet the ball reflect with ilf/ball.h's optics (ilf::ball_reflect in the view's ball frame,
// the same code `probe from-ball` inverts) and carry lab::radiance from the reflection point; the others
// see the scene. The ball itself is not in the scene (it casts no shadow and is not seen in the room),
// so the lab's probe at its centre (ground_truth) is the exact answer.
#pragma once
#include <optional>
#include <vector>

#include "iblkit/capture/ball.h"
#include "iblkit/capture/sensor.h"
#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/lab/scene.h"

namespace ibl::lab {

struct ShootDesc {
  Vec3 ball_center{0, 1, 0};         // metres
  double ball_radius = 0.05;         // metres
  double distance = 0.5;             // camera (pinhole) to ball centre, metres (> radius)
  double azimuth_deg = 0;            // view 0's camera stands at the ball + distance·(sin az, 0, cos az) turned up by
  double elevation_deg = 0;          // the elevation: az 0, el 0 puts it on the ball's +Z side, level
  std::vector<double> views_deg{0};  // each view's camera turned about +Y from view 0's ({0, 90}: two sides)
  int width = 512, height = 512;     // pixels
  double fill = 0.9;                 // the ball's silhouette diameter over the frame's height
  int samples = 2;                   // n×n rays per pixel
  capture::BallReflectance reflectance;
  bool photographer = true;  // the camera body and the photographer in the scene
  RenderDesc render;         // light estimation (the scene's by default)
};

struct Shot {
  Image radiance;             // linear RGB, W/(sr·m²)
  Image occluder;             // one channel: the fraction of each pixel's rays whose reflection first meets the
                              // camera body or the photographer
  capture::BallCircle ball;   // the silhouette in pixels (centre of the frame)
  double distance_radii = 0;  // camera to ball centre, in ball radii
  double angle_deg = 0;       // this view's turn about +Y from view 0 (what from-ball's --angle takes)
  geometry::Camera camera;    // the pinhole
  Mat3 ball_frame;            // the ball frame (camera on +Z, +Y up in the frame) -> world
};

// The views of desc.views_deg. `scene` is not built (its copies get the boxes and are built here).
std::vector<Shot> shoot(const Scene& scene, const ShootDesc& desc, const ProgressFn& progress = {});

// A bracket of exposures through capture/'s sensor model (the code `hdr merge` inverts): frame k is
// expose(radiance shifted by shifts[k], sensor with exposure_s = exposures_s[k] and noise seed
// sensor.seed + k). Hand-held: frames after the first are moved by whole pixels, each offset uniform in
// [−shift_px, shift_px] along x and y (fixed seed; the edge pixels repeat), as Ward's alignment undoes.
struct BracketDesc {
  std::vector<double> exposures_s;  // seconds, one per frame
  capture::SensorDesc sensor;       // f-number, ISO, response, noise, vignetting, white balance, bits
  int shift_px = 0;                 // hand-held shift bound, pixels (0: a tripod)
  // Raw frames: each frame's sensor values (capture::expose_dng) instead of code values.
  std::optional<capture::RawSensor> raw;
};

struct BracketFrame {
  Image codes;         // code values in [0, 1], 3 channels (empty for a raw frame)
  io::DngDesc raw;     // a raw frame (BracketDesc::raw): the sensor's values, levels and exposure
  double exposure_s;   // this frame's exposure time
  int dx = 0, dy = 0;  // its shift: frame pixel (x, y) shows the scene's (x − dx, y − dy)
};

std::vector<BracketFrame> bracket(const Image& radiance, const BracketDesc& desc);

// Exposure times of n frames `ev_step` stops apart around `middle_s` (n odd: the middle frame is
// middle_s), shortest first.
std::vector<double> bracket_times(int n, double ev_step, double middle_s);

// As a photographer of a light probe brackets (Madsen & Laursen: "gradually lowering the exposure time until no
// pixels in the image are saturated"): from `longest_s` down by `ev_step` stops until a frame leaves no pixel of
// `radiance` above 90 % of saturation (before noise; its brightest channel times the white balance), at least two
// frames and at most `max_frames`; longest first. Throws when max_frames do not reach it, naming --bracket.
std::vector<double> bracket_until_unsaturated(const Image& radiance, const capture::SensorDesc& s, double longest_s,
                                              double ev_step, int max_frames);

// The exposure time that puts the median luminance of the ball's pixels (inside `ball`) at relative
// exposure 0.18 (middle grey) for this sensor's f-number and ISO.
double middle_grey_exposure(const Image& radiance, const capture::BallCircle& ball, const capture::SensorDesc& s);

}  // namespace ibl::lab
