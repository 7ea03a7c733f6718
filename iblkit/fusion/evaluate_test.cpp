// fusion/evaluate.h against closed forms: a box room whose walls all send the same radiance, so every
// blend fuses the same constant map, and references that are that constant or twice it.
#include "iblkit/fusion/evaluate.h"

#include <gtest/gtest.h>

#include <cmath>

#include "iblkit/core/error.h"

namespace ibl::fusion {
namespace {

constexpr Vec3 kWall{0.8, 0.5, 0.25};  // radiance of every wall, W/(sr·m²)

sphere::EnvMap constant_map(int h, Vec3 c) {
  Image img(2 * h, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 2 * h; ++x) img.set_rgb(x, y, c);
  return sphere::EnvMap(img, sphere::Mapping(sphere::MappingKind::LatLong, 2 * h, h));
}

ProbeSet constant_room() {
  ProbeSet set;
  set.proxy = geometry::make_box({-2, 0, -3}, {2, 3, 3}, true);
  for (Vec3 p : {Vec3{-1, 1.5, -1}, Vec3{1, 1.5, 1.5}}) {
    Probe pr;
    pr.position = p;
    pr.radiance = constant_map(16, kWall);
    set.probes.push_back(pr);
  }
  prepare(set);
  return set;
}

Reference constant_reference(double k) {
  Reference ref;
  ref.radiance_map = [k](Vec3, int size) { return constant_map(size, kWall * k); };
  ref.radiance_along = [k](Vec3, const std::vector<Vec3>& d) { return std::vector<Vec3>(d.size(), kWall * k); };
  return ref;
}

TEST(FusionEvaluate, ConstantRoomAgainstExactAndTwiceTheTruth) {
  // Lookups interpolate a constant: float rounding only (the maps are float32).
  constexpr double kFloatTol = 1e-5;
  const ProbeSet set = constant_room();
  EvalDesc d;
  d.fuse.size = 8;
  d.view = Vec3{1, 0, 0};
  const Vec3 x{0, 1.5, 0};
  const PointEval exact = evaluate_point(set, x, constant_reference(1), d);
  ASSERT_EQ(exact.rows.size(), 6u);
  ASSERT_EQ(exact.maps.size(), 6u);
  const Blend order[] = {Blend::Nearest, Blend::Angle, Blend::Footprint};
  for (size_t i = 0; i < 6; ++i) {
    const auto& r = exact.rows[i];
    EXPECT_EQ(r.blend, order[i / 2]);
    EXPECT_EQ(r.visibility, i % 2 == 1);
    EXPECT_EQ(r.point.x, x.x);
    EXPECT_NEAR(r.image_rmse, 0, kFloatTol);
    EXPECT_NEAR(r.irradiance_mean_rel, 0, kFloatTol);
    EXPECT_NEAR(r.irradiance_max_rel, 0, kFloatTol);
    EXPECT_NEAR(r.coverage.fused, 1, kFloatTol);  // a closed room that both probes see everywhere
    EXPECT_EQ(exact.maps[i].radiance.mapping.kind(), sphere::MappingKind::LatLong);
    EXPECT_EQ(exact.maps[i].radiance.mapping.height(), 8);
  }
  EXPECT_EQ(exact.truth.mapping.height(), 8);
  // The views: the truth and angle/footprint × visibility off, on, all the wall's radiance.
  ASSERT_EQ(exact.views.size(), 4u);
  EXPECT_EQ(exact.views[0].blend, Blend::Angle);
  EXPECT_FALSE(exact.views[0].visibility);
  EXPECT_EQ(exact.views[3].blend, Blend::Footprint);
  EXPECT_TRUE(exact.views[3].visibility);
  for (const auto& v : exact.views) {
    ASSERT_EQ(v.image.width(), 320);
    ASSERT_EQ(v.image.height(), 200);
    EXPECT_NEAR(v.image.rgb(17, 150).y, kWall.y, kFloatTol);
  }
  EXPECT_NEAR(exact.view_truth.rgb(319, 0).z, kWall.z, kFloatTol);

  // Against a truth twice as bright: |L − 2L| / 2L = ½ in the image and in irradiance.
  d.view.reset();
  const PointEval twice = evaluate_point(set, x, constant_reference(2), d);
  for (const auto& r : twice.rows) {
    EXPECT_NEAR(r.image_rmse, 0.5, kFloatTol);
    EXPECT_NEAR(r.irradiance_mean_rel, 0.5, kFloatTol);
  }
  EXPECT_TRUE(twice.views.empty());
}

TEST(FusionEvaluate, ViewCameraIsNinetyDegreesAcross) {
  constexpr double kTol = 1e-12;  // closed forms in double precision
  const geometry::Camera c = view_camera({1, 2, 3}, {0, 0, -2});
  EXPECT_EQ(c.width, 320);
  EXPECT_EQ(c.height, 200);
  // The frame's left and right edges at ±45° from forward, its top edge at atan(200/320).
  const Vec3 left = c.ray_direction(0, 100), right = c.ray_direction(320, 100), top = c.ray_direction(160, 0);
  EXPECT_NEAR(left.x, -std::sqrt(0.5), kTol);
  EXPECT_NEAR(right.x, std::sqrt(0.5), kTol);
  EXPECT_NEAR(top.y / -top.z, 200.0 / 320.0, kTol);
  // Looking straight down, +Z is up in the frame.
  const geometry::Camera down = view_camera({0, 0, 0}, {0, -1, 0});
  EXPECT_GT(down.ray_direction(160, 0).z, 0.5);
  const auto dirs = pixel_directions(c);
  ASSERT_EQ(dirs.size(), 320u * 200u);
  EXPECT_EQ(dirs[199 * 320 + 5].x, c.pixel_direction(5, 199).x);  // row-major
  EXPECT_THROW(view_camera({0, 0, 0}, {0, 0, 0}), Error);
  EXPECT_THROW(view_image(c, std::vector<Vec3>(3)), Error);
}

TEST(FusionEvaluate, ImageErrorNeedsMatchingMapsAndAReferenceMap) {
  EXPECT_EQ(image_rmse(constant_map(4, kWall), constant_map(4, kWall)), 0);
  EXPECT_EQ(image_rmse(constant_map(4, kWall), constant_map(4, {0, 0, 0})), 0);  // black truth
  EXPECT_THROW(image_rmse(constant_map(4, kWall), constant_map(8, kWall)), Error);
  const ProbeSet set = constant_room();
  EXPECT_THROW(evaluate_point(set, {0, 1.5, 0}, Reference{}, EvalDesc{}), Error);
  EvalDesc with_view;
  with_view.view = Vec3{1, 0, 0};
  Reference maps_only = constant_reference(1);
  maps_only.radiance_along = nullptr;
  EXPECT_THROW(evaluate_point(set, {0, 1.5, 0}, maps_only, with_view), Error);
}

}  // namespace
}  // namespace ibl::fusion
