// The mirror ball's optics ([1] §5.2, Unger et al. 2007; Swaminathan et al. 2006): a camera looking
// along the probe frame's −Z at a chrome ball of radius r centred on the probe position does not see
// the world from one point. Pixel rays reflect off the ball's surface, so each pixel's ray starts at
// its own reflection point, up to r from the centre, and (for a camera at a finite distance) its
// direction differs from the ideal mirror-ball mapping's.
//
// Camera models (probe frame: ball centre at the origin, camera on +Z):
//   orthographic (distance 0): the frame's disc is the ball's outline; image point (a, b) ∈ unit disc
//     (a = 2px/W − 1, b = 1 − 2py/H) sees the surface point r·n, n = (a, b, √(1 − a² − b²)), and the
//     ray reflects into d = (0, 0, −1) + 2 n_z n — the mirrorball mapping's direction;
//   perspective (distance D > r): a pinhole at C = (0, 0, D); the disc is the ball's silhouette, of
//     angular radius α = asin(r/D), so (a, b) looks along v = normalize(a·tan α, b·tan α, −1), meets
//     the ball at h = C + t·v (the nearer root of |C + t·v| = r) and reflects into d = v − 2(v·n)n,
//     n = h/r. Directions within α of −Z are hidden behind the ball.
#pragma once
#include "iblkit/core/vec.h"

namespace ibl::ilf {

struct BallOptics {
  double radius = 0;    // metres; 0: a single viewpoint (every ray through the probe position)
  double distance = 0;  // camera to ball centre, metres; 0: orthographic (a camera far away)
  bool single_viewpoint() const { return radius <= 0; }
};

// The ray of image point (px, py) of a W×H mirror-ball frame, in the probe frame: its start on the
// ball (relative to the centre; zero when radius is 0) and its unit direction. False outside the disc.
bool ball_ray(const BallOptics& o, int width, int height, double px, double py, Vec3* start, Vec3* dir);

// Solid angle (sr) of the directions pixel (x, y) sees under a perspective camera: the area of the
// reflected-direction map over the pixel, ∫|∂d/∂px × ∂d/∂py|, by n×n sub-points with central
// differences (sub-points off the disc count zero). Over the whole frame it sums to 2π(1 + cos α).
double ball_pixel_solid_angle(const BallOptics& o, int width, int height, int x, int y, int n = 4);

}  // namespace ibl::ilf
