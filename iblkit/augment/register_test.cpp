// The light's turn about +Y registered from the floor both see (augment/register.h).
#include <gtest/gtest.h>

#include <cmath>

#include "iblkit/augment/register.h"
#include "iblkit/core/error.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::augment {
namespace {

// A floor whose radiance has no symmetry: a base of 0.2, a bright quadrant (x > 0.3, z < −0.2), a dimmer stripe
// (|z − 0.6| < 0.15) and a ramp along x.
double floor_radiance(double x, double z) {
  double v = 0.2 + 0.05 * (x + 3);
  if (x > 0.3 && z < -0.2) v += 1.5;
  if (std::abs(z - 0.6) < 0.15) v += 0.6;
  return v;
}

// The floor photographed from above (1.5 m up, tilted), one ray per pixel centre.
Image floor_photo(const geometry::Camera& cam) {
  Image img(cam.width, cam.height, 3);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const Vec3 d = cam.pixel_direction(x, y);
      const double v =
          d.y < 0 ? floor_radiance(cam.eye.x - d.x * cam.eye.y / d.y, cam.eye.z - d.z * cam.eye.y / d.y) : 0;
      img.set_rgb(x, y, {0.8 * v, 0.8 * v, 0.8 * v});  // another exposure: the match's scale must not matter
    }
  return img;
}

// The probe at `centre` (0.4 m above the floor): the floor below the horizon, a sky of 1 above, 256 × 128 lat-long.
LocalRadiance floor_probe(Vec3 centre) {
  LocalRadiance l;
  const sphere::Mapping m(sphere::MappingKind::LatLong, 256, 128);
  Image img(256, 128, 3);
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 256; ++x) {
      Vec3 d;
      m.to_direction(x + 0.5, y + 0.5, &d);
      const double v = d.y < 0 ? floor_radiance(centre.x - d.x * centre.y / d.y, centre.z - d.z * centre.y / d.y) : 1.0;
      img.set_rgb(x, y, {v, v, v});
    }
  l.map = sphere::EnvMap(img, m);
  l.centre = centre;
  l.source = "test probe";
  return l;
}

geometry::Camera above() {
  geometry::Camera c;
  c.eye = {0.4, 1.5, 2.0};
  c.target = {0, 0, 0};
  c.fov_y_deg = 60;
  c.width = 160;
  c.height = 120;
  return c;
}

// The scene both tests register in: the camera above, its photograph of the floor, the floor, the probe 0.4 m up.
struct FloorScene {
  geometry::Camera cam = above();
  Image photo = floor_photo(cam);
  geometry::TriMesh floor = geometry::make_quad({0, 0, 0}, {0, 1, 0}, {0, 0, -1}, 8, 8);
  LocalRadiance probe = floor_probe({0, 0.4, 0});
};

}  // namespace

TEST(AugmentRegister, APosedProbeTurnedIsTurnedBack) {
  const FloorScene sc;
  const auto& [cam, photo, floor, probe] = sc;
  // As given: no turn, and nothing to gain.
  const YawFit f0 = register_yaw(photo, cam, floor, probe);
  ASSERT_TRUE(f0.valid);
  EXPECT_NEAR(f0.yaw_deg, 0, 0.5);
  EXPECT_NEAR(f0.spread, f0.spread_given, 1e-3);
  for (double t : {30.0, -75.0, 170.0}) {
    const LocalRadiance wrong = turned(probe, t);
    const YawFit f = register_yaw(photo, cam, floor, wrong);
    ASSERT_TRUE(f.valid) << t;
    double back = f.yaw_deg + t;
    back = std::remainder(back, 360.0);
    EXPECT_NEAR(back, 0, 0.5) << "turned by " << t << "°, registered " << f.yaw_deg << "°";
    EXPECT_LT(f.spread, 0.5 * f.spread_given) << t;
    // The runner-up, more than 20° away, is clearly worse: the floor has no symmetry.
    EXPECT_GT(f.runner_up_spread, 1.5 * f.spread) << t;
  }
  // Turning is a rotation: turned by 40° then −40° is the probe again (away from the seam's texels).
  const LocalRadiance there_and_back = turned(turned(probe, 40), -40);
  double sum = 0;
  int n = 0;
  for (int y = 70; y < 120; ++y)
    for (int x = 0; x < 256; ++x, ++n)
      sum += std::abs(static_cast<double>(there_and_back.map.image.at(x, y, 1)) - probe.map.image.at(x, y, 1)) /
             probe.map.image.at(x, y, 1);
  EXPECT_LT(sum / n, 0.03) << sum / n;  // bilinear twice: the step edges blur by a texel
  // turn_y: +X goes to −Z for a positive turn.
  const Vec3 d = turn_y({1, 0, 0}, 90);
  EXPECT_NEAR(d.z, -1, 1e-12);
  // A photograph of nothing the probe sees: not valid; a bad range: refused.
  LocalRadiance under = probe;
  under.centre = {0, -0.5, 0};
  EXPECT_FALSE(register_yaw(photo, cam, floor, under).valid);
  EXPECT_THROW(register_yaw(photo, cam, floor, probe, 0, 0), Error);
  EXPECT_THROW(turned(probe, std::nan("")), Error);
}

TEST(AugmentRegister, AProbeSaidToStandElsewhereIsMovedBack) {
  const FloorScene sc;
  const auto& [cam, photo, floor, probe] = sc;
  const PositionFit here = register_position(photo, cam, floor, probe);
  ASSERT_TRUE(here.valid);
  EXPECT_LT(length(here.offset), 0.01) << here.offset.x << "," << here.offset.y << "," << here.offset.z;
  for (Vec3 err : {Vec3{0.06, 0, -0.04}, Vec3{-0.1, 0.05, 0.08}}) {
    LocalRadiance said = probe;
    said.centre = probe.centre + err;
    const PositionFit f = register_position(photo, cam, floor, said);
    ASSERT_TRUE(f.valid);
    const Vec3 back = said.centre + f.offset - probe.centre;
    EXPECT_LT(length(back), 0.01) << back.x << "," << back.y << "," << back.z;
    EXPECT_LT(f.spread, 0.5 * f.spread_given);
  }
  EXPECT_THROW(register_position(photo, cam, floor, probe, 0, 0), Error);
  EXPECT_THROW(register_position(photo, cam, floor, probe, 0, 0.2, std::nan("")), Error);
}

}  // namespace ibl::augment
