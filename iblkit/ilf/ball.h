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

// The same optics for any view ray: a ray from the pinhole C = (0, 0, distance) along unit v (probe
// frame) meets the ball at `start` (relative to the centre, radius·n) and leaves along `dir`. False when
// it misses. Needs a perspective camera (distance > radius > 0). ball_ray uses it; capture/'s chrome
// ball unwarp and the lab's photographs of a chrome ball (lab shoot) do too.
bool ball_reflect(const BallOptics& o, Vec3 v, Vec3* start, Vec3* dir);

// The inverse: the view ray that leaves the ball along unit direction d. Writes the unit view ray
// (from the pinhole; (0, 0, −1) for the orthographic camera) and the unit normal at the reflection
// point. The normal lies in the plane of +Z and d, at the angle from +Z where the reflection turns
// +Z into d (a monotonic function of it, solved by bisection to 1e-12 rad); orthographic:
// n = normalize(d + (0, 0, 1)). False for directions in the blind cone (within asin(r/D) of −Z; for
// the orthographic camera only −Z itself).
bool ball_view_for(const BallOptics& o, Vec3 d, Vec3* view, Vec3* normal);

// Where a view ray lands in the image of a ball whose silhouette has centre (cx, cy) and radius r
// (continuous pixel coordinates, y down): the unit-disc point (a, b) of ball_ray scaled to the
// silhouette. Perspective: (a, b) = (v.x, v.y)/(−v.z·tan α); orthographic: (a, b) = (n.x, n.y).
void ball_image_point(const BallOptics& o, Vec3 view, Vec3 normal, double cx, double cy, double r, double* px,
                      double* py);

// Solid angle (sr) of the directions pixel (x, y) sees under a perspective camera: the area of the
// reflected-direction map over the pixel, ∫|∂d/∂px × ∂d/∂py|, by n×n sub-points with central
// differences (sub-points off the disc count zero). Over the whole frame it sums to 2π(1 + cos α).
double ball_pixel_solid_angle(const BallOptics& o, int width, int height, int x, int y, int n = 4);

}  // namespace ibl::ilf
