// lab::photograph against closed forms: a sphere under a point light, photographed by a pinhole
// camera, shows ρ/π · I · max(0, n·l)/d² at every pixel it covers, and the surface image names it.
#include "iblkit/lab/view.h"

#include <gtest/gtest.h>

#include <cmath>

#include "iblkit/core/error.h"

namespace ibl::lab {
namespace {

TEST(LabView, SphereUnderPointLightMatchesClosedForm) {
  // Flat facets of a 96×192 UV sphere against the true sphere's normal and position.
  constexpr double kFacetTol = 0.02;
  Scene s;
  const double R = 0.5, rho = 0.6;
  const Vec3 I{3, 2, 1}, q{1.5, 2.0, 1.0};
  int id = add_object(s, "ball", geometry::make_sphere({0, 0, 0}, R, 96, 192), {rho, rho, rho});
  Emitter e;
  e.type = EmitterType::Point;
  e.position = q;
  e.intensity = I;
  s.emitters.push_back(e);
  s.build();
  const Vec3 eye{0, 0.3, 2.5};
  const int W = 64, H = 48;
  const double tan_half = std::tan(20 * kPi / 180);
  auto ray = [&](double px, double py, Vec3* o, Vec3* d) {
    *o = eye;
    Vec3 f = normalize(Vec3{0, 0, 0} - eye), r = normalize(cross(f, {0, 1, 0})), u = cross(r, f);
    *d = normalize(f + r * ((2 * px / W - 1) * tan_half * W / H) + u * ((1 - 2 * py / H) * tan_half));
  };
  ViewDesc vd;
  vd.width = W;
  vd.height = H;
  vd.samples = 1;
  View v = photograph(s, ray, vd);
  int checked = 0, background = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      Vec3 o, d;
      ray(x + 0.5, y + 0.5, &o, &d);
      double b = dot(o, d), c = dot(o, o) - R * R, disc = b * b - c;
      if (disc < 0) {
        EXPECT_EQ(v.surface.at(x, y, 0), -1.0f);
        ++background;
        continue;
      }
      if (disc < 0.02) continue;  // the silhouette, where facets and the sphere disagree
      EXPECT_EQ(static_cast<int>(v.surface.at(x, y, 0)), id);
      Vec3 p = o + d * (-b - std::sqrt(disc)), n = normalize(p), to = q - p;
      double cosl = std::max(0.0, dot(n, normalize(to)));
      Vec3 want = I * (rho / kPi * cosl / dot(to, to));
      for (int ch = 0; ch < 3; ++ch)
        ASSERT_NEAR(v.radiance.at(x, y, ch), want[ch], kFacetTol * I.x * rho / kPi) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 300);
  EXPECT_GT(background, 300);
}

TEST(LabView, AddingObjectsAfterBuildIsAnError) {
  Scene s;
  add_object(s, "a", geometry::make_box({0, 0, 0}, {1, 1, 1}), {0.5, 0.5, 0.5});
  s.build();
  EXPECT_THROW(add_object(s, "b", geometry::make_box({0, 0, 0}, {1, 1, 1}), {0.5, 0.5, 0.5}), Error);
}

}  // namespace
}  // namespace ibl::lab
