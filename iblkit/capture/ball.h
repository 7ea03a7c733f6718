// Light probes from photographs of a chrome ball (docs/capture.md, "Probes from a chrome ball").
//
// A linear HDR photograph of a mirror ball is unwarped with the real optics: a pinhole camera at a
// finite distance aimed at the ball (ilf/ball.h's BallOptics, the one implementation of the mirror
// sphere that the ILF build and the lab's photographs use too), not the orthographic approximation.
// Each probe direction d is traced back to the image point whose reflection leaves along d
// (ilf::ball_view_for), the photograph is sampled there (bilinear) and divided by the ball's
// reflectance at that point's angle of incidence (a conductor's Fresnel rise towards grazing).
//
// Frames: each view's frame is the one `convert` gives a mirror-ball image (docs/conventions.md): the
// camera looks along −Z at the ball, +Y up in the photograph. The probe is in view 0's frame, turned by
// `rotation` (the environment turned: probe(d) = view0(Rᵀ d)). A second view's `angle_deg` is where its
// camera stands, turned about +Y from view 0's camera: R_y(angle)·(0, 0, 1) = (sin a, 0, cos a), so +90°
// puts it on view 0's +X side (the photographer walked a quarter circle to their right).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::capture {

// A metal's complex index of refraction n + ik (per channel R, G, B) against air.
struct Conductor {
  Vec3 n{3.1, 3.1, 3.1}, k{3.3, 3.3, 3.3};
};
Conductor chrome();  // n = 3.1, k = 3.3 in every channel (normal-incidence reflectance 0.552)
Conductor steel();   // n = 2.9, k = 3.0 (0.519)
// Unpolarised Fresnel reflectance of a conductor at incidence cos θ (exact: Born & Wolf's a², b² form).
Vec3 fresnel_conductor(const Conductor& m, double cos_theta);

// The ball's reflectance at an angle of incidence: r0 at normal incidence (the metal's own F(0) when
// r0 is absent), rising towards grazing incidence as the metal's Fresnel curve does:
// R(θ) = r0 · F(θ)/F(0) (constant r0 without `fresnel`).
struct BallReflectance {
  std::optional<Vec3> r0;  // normal-incidence reflectance per channel, in (0, 1]
  bool fresnel = true;     // the conductor's rise towards grazing
  Conductor metal = chrome();
  Vec3 at(double cos_theta) const;
};
// "chrome", "steel", "none" (no rise) or "n,k" (one metal, every channel) -> the reflectance's metal
// and fresnel flag. Throws naming `what`.
void parse_fresnel(const std::string& s, BallReflectance* r, const std::string& what = "--fresnel");

// The ball's silhouette in a photograph: centre and radius in continuous pixel coordinates (the image
// spans [0, W] × [0, H], pixel i's centre at i + ½, y down).
struct BallCircle {
  double cx = 0, cy = 0, r = 0;
};

struct CircleFit {
  BallCircle circle;
  double residual_px = 0;  // RMS distance of the inlier edge points to the circle, pixels
  int edge_points = 0;     // edge points on the circle (inliers)
  double coverage = 0;     // fraction of the circumference with an inlier edge point (of 360 1° bins)
};

// Finds the ball: the strongest edges of log luminance (Sobel), a circle by RANSAC (fixed seed) and a
// least-squares refinement on its inliers. Throws (naming `option`, the flag that gives the ball by hand)
// when no circle covers at least half its circumference or the circle leaves the frame.
CircleFit find_ball(const Image& photo, const std::string& file = "the photograph",
                    const std::string& option = "--ball");

struct BallView {
  Image photo;           // linear RGB (or more channels: the first three are used)
  BallCircle ball;       // the silhouette
  double distance = 0;   // camera to ball centre in ball radii (> 1); 0: an orthographic camera
  double angle_deg = 0;  // where this view's camera stands about +Y from view 0's (view 0: 0)
  std::string name;      // for messages
};

// The distance in ball radii from the silhouette's radius in pixels and the lens: focal length f_px
// = focal_mm / sensor_mm · image width (sensor_mm the sensor's width), tan α = r / f_px, D = 1/sin α.
double distance_from_lens(double radius_px, int image_width, double focal_mm, double sensor_mm);

struct FromBallDesc {
  sphere::MappingKind mapping = sphere::MappingKind::LatLong;
  int size = 256;                    // lat-long height, cube face edge or disc diameter, pixels
  Mat3 rotation = Mat3::identity();  // --rotate: the probe turned by R
  BallReflectance reflectance;
  int samples = 2;  // n×n sub-samples per output pixel
  // Two views: each view's directions within exclude_deg of its camera axis (±Z: the camera and
  // photographer in front, the stretched rim and the blind cone behind) get weight 0, rising linearly in
  // sin(angle from the axis) to 1 at exclude_deg + ramp_deg; the views blend by these weights.
  double exclude_deg = 40, ramp_deg = 10;
};

struct FromBallResult {
  sphere::EnvMap probe{Image(2, 1, 4),
                       sphere::Mapping(sphere::MappingKind::LatLong, 2,
                                       1)};  // RGBA: alpha 1 where a view sees the direction, 0 in the blind cone
  Image weights;               // one channel, the probe's layout: view 0's share of each pixel (two views), else alpha
  double blind_cone_deg = 0;   // one view: the cone around −Z (view frame) without data, degrees
  int64_t invalid_pixels = 0;  // output pixels with alpha 0
};

// The probe. One or two views (the second's angle_deg says where it stood).
FromBallResult probe_from_ball(const std::vector<BallView>& views, const FromBallDesc& desc);

// The second view's angle (degrees about +Y) estimated from the views' overlap: over 2048 Fibonacci
// directions that both views see away from their axes (weight 1 under desc's exclusion cones), the
// mean squared difference of log luminance (each view divided by its reflectance) is minimised over
// [lo_deg, hi_deg] in 1° steps, then refined by golden-section search to 0.01°. `residual` is that mean
// absolute log difference at the optimum. views[1].angle_deg is ignored.
struct AngleEstimate {
  double angle_deg = 0, residual = 0;
  int directions = 0;  // overlap directions at the optimum
};
AngleEstimate estimate_angle(const std::vector<BallView>& views, const FromBallDesc& desc, double lo_deg = 45,
                             double hi_deg = 135);

// Output size of a mapping from FromBallDesc::size (lat-long 2s × s, crosses 4s × 3s, …).
sphere::Mapping output_mapping(sphere::MappingKind kind, int size);

}  // namespace ibl::capture
