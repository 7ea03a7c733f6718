// Registration of the light's turn about the world's up axis from what the light and the photograph both see of
// the proxy (docs/augment.md, "Registration"). A probe's position is easy to measure with a tape; which way its
// camera faced (north) is what users get wrong. A Lambertian surface looks the same from every side, so where
// the probe is turned right, the photograph's value over the light's at each proxy point both see differs only by
// the exposure's one scale and the surfaces' gloss: the spread of log2(photo / light) over the points (the
// radiometric match's, augment/match.h) is smallest. The turn is searched over ±range_deg in 1° steps on at most
// 10,000 of the points, then refined by golden section to 0.05° on all of them; their geometry is traced once.
#pragma once
#include <cstdint>
#include <vector>

#include "iblkit/augment/light.h"
#include "iblkit/augment/match.h"
#include "iblkit/core/image.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::augment {

struct YawFit {
  double yaw_deg = 0;        // turn the light by this about +Y (right-handed: +X towards −Z for a positive turn)
  double spread = 0;         // the match's spread (stops) at that turn
  double spread_given = 0;   // and as the light was given (0°)
  double runner_up_deg = 0;  // the best turn more than 20° from it, and its spread: an ambiguous scene has both close
  double runner_up_spread = 0;
  int64_t points = 0;  // proxy points both saw
  bool valid = false;  // enough points (kMinMatchPoints)
};

YawFit register_yaw(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                    const LocalRadiance& light, double saturated = 0, double range_deg = 180);

// The light's position the same way (`--register pose`): where the light stands changes the direction in which it
// sees each proxy point (the floor 15 cm under a ball moves by 18° for a 5 cm error), so the disagreement is least at
// its true centre. The offset is searched on a grid of 11³ over ±range_m, then twice on 5³ a quarter as fine (the
// last on all the points): to range_m / 80. The points are those the given centre sees (an offset of centimetres
// hides or shows few of them). yaw_deg: the light's turn, held.
struct PositionFit {
  Vec3 offset{0, 0, 0};     // move the light's centre by this (world metres)
  double spread = 0;        // the disagreement there (register_yaw's measure)
  double spread_given = 0;  // and where the light was given
  int64_t points = 0;
  bool valid = false;
};
PositionFit register_position(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                              const LocalRadiance& light, double saturated = 0, double range_m = 0.2,
                              double yaw_deg = 0);

// The light turned by yaw_deg about +Y through its centre: its map (and depth) resampled, L'(d) = L(R⁻¹ d).
LocalRadiance turned(const LocalRadiance& light, double yaw_deg);

// d turned by deg about +Y.
Vec3 turn_y(Vec3 d, double deg);

}  // namespace ibl::augment
