// Synthetic light probes: radiance (and depth) seen from a point, in any sphere mapping, or through
// a physical mirror-ball camera.
#pragma once
#include <cstdint>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/lab/scene.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::lab {

enum class Camera {
  Ideal,       // each pixel looks along the mapping's directions (sphere::Mapping::to_direction)
  MirrorBall,  // an orthographic camera looking along −Z at a chrome ball (mirrorball mapping only)
};

struct CaptureDesc {
  sphere::MappingKind mapping = sphere::MappingKind::LatLong;  // pixel layout
  int size = 64;                    // lat-long height, cube face edge, or disc/octahedral diameter (pixels)
  double dead_angle_deg = 0;        // ideal mirror balls: cone around −Z left without data
  Mat3 rotation;                    // probe frame -> world (the probe's +Z, +Y in the world)
  int samples = 1;                  // n: n×n stratified sub-pixel samples (1: the pixel centre)
  Camera camera = Camera::Ideal;    // how pixels map to rays
  double ball_radius = 0.04;        // MirrorBall: radius of the chrome ball, metres
  bool ball_parallax = false;       // MirrorBall: rays leave the ball's surface (non-single viewpoint)
  double ball_reflectance = 1;      // MirrorBall: mirror reflectance (chrome is ~0.6–0.7)
  bool depth = false;               // also compute the distance to the first hit at each pixel centre
  bool integrate_apertures = true;  // Ideal camera: a lamp aperture smaller than kSmallApertureFactor
                                    // pixels is integrated per pixel (≥ 256 points with shadow rays),
                                    // not point-sampled by the sub-pixel rays (which alias it)
  RenderDesc render;                // light estimation settings and seed
  // Ideal camera: with Outside (Inside) only the sub-samples and aperture points whose direction lies
  // outside (inside) the cone of `cone_deg` around `cone_axis` carry light; the rest count as
  // black. ground_truth uses Inside to leave a mirror ball's dead angle out of its answer exactly.
  enum class Cone { All, Outside, Inside };
  Cone cone = Cone::All;
  double cone_deg = 0;       // half-angle of that cone, degrees
  Vec3 cone_axis{0, 0, -1};  // its axis in the world (unit)
};

// A spot/projector aperture whose solid angle is below this many pixels (at the pixel it falls in)
// is integrated analytically: each pixel then holds the exact pixel average of the lamp's radiance,
// E_pixel = Σ_points I(−ω)/(K·d²) / Ω_pixel, with K ≥ 256 stratified points of the disc and at least
// 16 per pixel it covers, instead of n×n point samples of a disc that covers a fraction of a pixel at
// 10⁴× the scene's radiance (or a few hundred pixels with an aliased rim: 2.6 % of its light at 22
// pixels with 4×4 samples; 9–13 % for a disc centred on a lat-long pole, whose rim runs along the
// rows). Larger apertures are resolved by the pixels.
inline constexpr double kSmallApertureFactor = 4096;

struct Capture {
  Image radiance;  // RGB, W/(sr·m²); 0 where a pixel carries no direction
  Image depth;     // one channel, metres; 0 where a pixel carries no direction or the
                   // ray leaves the scene (empty unless CaptureDesc::depth)
  sphere::Mapping mapping{sphere::MappingKind::LatLong, 2, 1};  // the layout of both images
};

// The mapping of a capture: width × height from `size` (see CaptureDesc::size).
sphere::Mapping capture_mapping(sphere::MappingKind kind, int size, double dead_angle_deg = 0);

// Captures the probe at `position`. `probe_index` keys the random streams of this probe, so probe
// k of a sequence is the same whether it is captured alone or with the others.
Capture capture_probe(const Scene& scene, Vec3 position, const CaptureDesc& desc, uint64_t probe_index = 0,
                      const ProgressFn& progress = {});

}  // namespace ibl::lab
