// split_light and sphere_occlusion against closed forms: the cap's cosine integral against quadrature,
// the equivalent sphere of a sphere and of an open square, and the split conserving the map's power.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "iblkit/augment/sphere_occlusion.h"
#include "iblkit/augment/split_light.h"
#include "iblkit/core/error.h"
#include "iblkit/render/objects.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::augment {
namespace {

// ∫_cap max(0, n·ω) dω by a midpoint rule over the cap (polar angle t from the cap's axis, azimuth p).
double cap_quadrature(double beta, double alpha) {
  Vec3 axis{std::sin(beta), 0, std::cos(beta)}, n{0, 0, 1};
  Frame f = Frame::from_normal(axis);
  constexpr int kT = 400, kP = 800;
  double sum = 0;
  for (int i = 0; i < kT; ++i) {
    double t = (i + 0.5) / kT * alpha, dt = alpha / kT;
    for (int j = 0; j < kP; ++j) {
      double p = (j + 0.5) / kP * 2 * kPi;
      Vec3 w = f.from_local({std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)});
      sum += std::max(0.0, dot(n, w)) * std::sin(t) * dt * (2 * kPi / kP);
    }
  }
  return sum;
}

TEST(AugmentSphereOcclusion, CapCosineIntegralMatchesQuadratureAcrossTheHorizon) {
  for (double alpha_deg : {5.0, 20.0, 45.0, 70.0})
    for (double beta_deg : {0.0, 30.0, 60.0, 80.0, 90.0, 100.0, 120.0}) {
      double a = alpha_deg * kPi / 180, b = beta_deg * kPi / 180;
      double q = cap_quadrature(b, a), c = cap_cosine_integral(std::cos(b), std::sin(a) * std::sin(a));
      EXPECT_NEAR(c, q, 2e-4 + 1e-3 * q) << "alpha " << alpha_deg << " beta " << beta_deg;
    }
  EXPECT_EQ(cap_cosine_integral(std::cos(2.0), 0.01), 0.0);  // wholly below the horizon
}

TEST(AugmentSphereOcclusion, EquivalentSphereOfASphereAndOfAnOpenSquare) {
  OccluderSphere s = equivalent_sphere(render::make_object({"sphere", 0.4, 0, {1, 2, 3}}));
  EXPECT_NEAR(s.radius, 0.2, 0.004);  // the tessellated sphere's volume is a little smaller
  EXPECT_NEAR(s.bound_radius, 0.2, 1e-3);
  EXPECT_NEAR(length(s.centre - Vec3{1, 2, 3}), 0, 1e-6);
  OccluderSphere q =
      equivalent_sphere(geometry::make_quad({0, 0, 0}, {0, 1, 0}, {0, 0, -1}, 1, 1));  // open: S/4 = π r²
  EXPECT_NEAR(q.radius, std::sqrt(1.0 / (4 * kPi)), 1e-9);
}

TEST(AugmentSphereOcclusion, FacingIrradianceOfASphereIsTheCosineMeanOfItsHemisphere) {
  // E_c(n) = 1 + n_y on a sphere: the side facing d, weighted by projected area (A max(0, n·d)), has the mean
  // normal (2/3) d, so its mean irradiance is 1 + (2/3) d_y. With the lower half's factor 0 (in a shadow),
  // the side facing straight down receives nothing and the side facing up all of it.
  const geometry::TriMesh sphere = render::make_object({"sphere", 0.4, 0, {0, 0, 0}});
  Image irr(64, 32, 3);
  const sphere::Mapping ll(sphere::MappingKind::LatLong, 64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      Vec3 n;
      ll.to_direction(x + 0.5, y + 0.5, &n);
      irr.set_rgb(x, y, Vec3{1, 1, 1} * (1 + n.y));
    }
  const Image f = facing_irradiance(sphere, nullptr, irr);
  const sphere::Mapping out(sphere::MappingKind::LatLong, f.width(), f.height());
  constexpr double kTol = 0.02;  // normals gathered into 11° cells, the map bilinear, the sphere tessellated
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x) {
      Vec3 dir;
      out.to_direction(x + 0.5, y + 0.5, &dir);
      ASSERT_NEAR(f.rgb(x, y).y, 1 + 2.0 / 3 * dir.y, kTol) << "direction " << dir.x << " " << dir.y << " " << dir.z;
    }
  std::vector<Vec3> lit(sphere.triangle_count());
  for (size_t t = 0; t < lit.size(); ++t) lit[t] = sphere.normal(t).y < 0 ? Vec3{} : Vec3{1, 1, 1};
  const Image g = facing_irradiance(sphere, &lit, irr);
  EXPECT_NEAR(g.rgb(0, g.height() - 1).y, 0.0, kTol);  // the bottom row faces (almost) straight down
  EXPECT_NEAR(g.rgb(0, 0).y, f.rgb(0, 0).y, kTol);     // the top row: all of its side is lit
  EXPECT_THROW(facing_irradiance(sphere, &lit, Image(10, 10, 3)), Error);
}

LocalRadiance sky_and_sun(Vec3 centre) {
  Image img(64, 32, 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) img.set_rgb(x, y, y < 16 ? Vec3{0.5, 0.6, 1.0} : Vec3{0.2, 0.2, 0.2});
  img.set_rgb(20, 6, {3000, 2800, 2500});
  img.set_rgb(21, 6, {3000, 2800, 2500});
  LocalRadiance l;
  l.map = sphere::EnvMap(img, sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  l.centre = centre;
  l.source = "test sky";
  return l;
}

TEST(AugmentSplit, HardLightsAndSoftMapHoldAllOfTheMapsPowerAndSitWhereTheProxyIs) {
  LocalRadiance l = sky_and_sun({0, 0.5, 0});
  std::vector<double> total = l.map.integral();
  geometry::TriMesh floor = geometry::make_quad({0, 0, 0}, {0, 1, 0}, {0, 0, -1}, 6, 6);
  SplitLight s = split_light(l, floor);
  ASSERT_EQ(s.hard.lights.size(), 2u);  // the two sun texels, nothing else is 8× the mean
  Vec3 hard;
  for (const auto& h : s.hard.lights) {
    hard += h.irradiance;
    EXPECT_FALSE(h.position);  // above an open floor: directional
  }
  ASSERT_TRUE(s.hard.origin);
  EXPECT_EQ(length(*s.hard.origin - l.centre), 0.0);
  sphere::EnvMap soft(s.soft, sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  std::vector<double> rest = soft.integral();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(hard[c] + rest[c], total[c], 1e-6 * total[c]);
  EXPECT_GT(s.hard_share, 0.5);
  // The soft irradiance on an upward normal: π × the upper hemisphere's radiance (1.0 in blue), the lower
  // hemisphere's (0.2) on a downward one (the output's first and last rows are 2.8° off the poles: the sky view
  // factor (1 + cos 2.8°)/2), less, upwards, the sun's two texels, which are hard and missing from the soft sky.
  const Image& irr = s.soft_irradiance;
  const double c = std::cos(kPi / (2 * irr.height()));
  Vec3 up;
  ASSERT_TRUE(sphere::Mapping(sphere::MappingKind::LatLong, irr.width(), irr.height())
                  .to_direction(irr.width() / 2 + 0.5, 0.5, &up));
  double sun_sky = 0;
  for (int x : {20, 21}) {
    Vec3 w;
    ASSERT_TRUE(l.map.mapping.to_direction(x + 0.5, 6.5, &w));
    sun_sky += 1.0 * l.map.mapping.solid_angle(x, 6) * std::max(0.0, dot(up, w));
  }
  EXPECT_NEAR(irr.rgb(irr.width() / 2, 0).z, kPi * (1.0 * (1 + c) / 2 + 0.2 * (1 - c) / 2) - sun_sky, 2e-3);
  EXPECT_NEAR(irr.rgb(irr.width() / 2, irr.height() - 1).z, kPi * (0.2 * (1 + c) / 2 + 1.0 * (1 - c) / 2), 2e-3);

  // Under a ceiling the sun's light comes from a point on it (intensity E·d² W/sr), placed by the rule of
  // fusion's lights (lights/place.h): the light's direction times its texels' median depth, never beyond what
  // the direction itself sees (the ceiling).
  geometry::TriMesh room = floor;
  room.append(geometry::make_quad({0, 2, 0}, {0, -1, 0}, {0, 0, 1}, 6, 6));
  SplitLight r = split_light(l, room);
  ASSERT_FALSE(r.hard.lights.empty());
  const lights::Light& lamp = r.hard.lights[0];
  ASSERT_TRUE(lamp.position);
  EXPECT_NEAR(lamp.position->y, 2.0, 1e-6);
  Vec3 e = lights::irradiance_at(r.hard, lamp, l.centre, lamp.direction);  // gives back E at the centre
  EXPECT_NEAR(e.x, lamp.irradiance.x, 1e-9 * e.x);

  SplitDesc none;
  none.threshold = 0;
  EXPECT_TRUE(split_light(l, floor, none).hard.lights.empty());
  none.lights = -1;
  EXPECT_THROW(split_light(l, floor, none), Error);
}

TEST(AugmentSplit, SoftIrradianceIsTheCosineSumOfTheSoftTexels) {
  // With nothing hard (threshold 0), E(n) on every normal of the irradiance map is Σ L dω max(0, n·ω) over the
  // map's texels, the sun's two included: against that sum done here texel by texel, within the cells' spread
  // (a 64 × 32 map is its own cells: exact but for float rounding).
  LocalRadiance l = sky_and_sun({0, 0.5, 0});
  geometry::TriMesh floor = geometry::make_quad({0, 0, 0}, {0, 1, 0}, {0, 0, -1}, 6, 6);
  SplitDesc all_soft;
  all_soft.threshold = 0;
  SplitLight s = split_light(l, floor, all_soft);
  const Image& irr = s.soft_irradiance;
  const sphere::Mapping& in = l.map.mapping;
  const sphere::Mapping out(sphere::MappingKind::LatLong, irr.width(), irr.height());
  double worst = 0;
  for (int y = 0; y < irr.height(); y += 3)
    for (int x = 0; x < irr.width(); x += 5) {
      Vec3 n, e;
      ASSERT_TRUE(out.to_direction(x + 0.5, y + 0.5, &n));
      for (int v = 0; v < 32; ++v)
        for (int u = 0; u < 64; ++u) {
          Vec3 w;
          ASSERT_TRUE(in.to_direction(u + 0.5, v + 0.5, &w));
          e += l.map.image.rgb(u, v) * (in.solid_angle(u, v) * std::max(0.0, dot(n, w)));
        }
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(irr.rgb(x, y)[c] - e[c]) / e[c]);
    }
  EXPECT_LT(worst, 1e-4);
}

}  // namespace
}  // namespace ibl::augment
