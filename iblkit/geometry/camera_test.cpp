#include "iblkit/geometry/camera.h"

#include <gtest/gtest.h>

#include "iblkit/core/error.h"

using namespace ibl;
using namespace ibl::geometry;

namespace {

Camera lens_camera() {
  Camera c;
  c.eye = {0.4, 1.3, 2.1};
  c.target = {-0.1, 0.2, 0.05};
  c.width = 1024;
  c.height = 768;
  c.intrinsics = Intrinsics{812.5, 806.0, 530.25, 371.75};
  // A strong wide-angle barrel distortion with some decentring: the corner moves by about 120 px.
  c.distortion = {-0.32, 0.11, 0.0012, -0.0009, -0.018};
  return c;
}

}  // namespace

TEST(GeometryCamera, ProjectInvertsRayDirectionOverTheFrameWithStrongDistortion) {
  Camera c = lens_camera();
  EXPECT_NO_THROW(require_camera(c));
  double worst = 0;
  for (int j = 0; j <= 32; ++j)
    for (int i = 0; i <= 32; ++i) {
      double px = c.width * i / 32.0, py = c.height * j / 32.0;
      Vec3 d = c.ray_direction(px, py);
      EXPECT_NEAR(length(d), 1.0, 1e-12);
      auto q = c.project(c.eye + d * 3.7);
      ASSERT_TRUE(q.has_value());
      worst = std::max(worst, std::hypot(q->x - px, q->y - py));
    }
  EXPECT_LT(worst, 1e-6) << "worst round trip " << worst << " px";
  // The distortion is really there: the corner's ray is not the pinhole's.
  Camera pin = c;
  pin.distortion = {};
  Vec3 a = c.ray_direction(0, 0), b = pin.ray_direction(0, 0);
  auto moved = pin.project(c.eye + a);
  ASSERT_TRUE(moved);
  EXPECT_GT(std::hypot(moved->x, moved->y), 50.0);
  EXPECT_GT(length(a - b), 0.05);
}

TEST(GeometryCamera, UndistortionMeetsItsTolerance) {
  Distortion d{-0.32, 0.11, 0.0012, -0.0009, -0.018};
  for (double x = -0.7; x <= 0.7; x += 0.05)
    for (double y = -0.5; y <= 0.5; y += 0.05) {
      bool ok = false;
      Vec2 u = d.invert({x, y}, &ok);
      EXPECT_TRUE(ok) << x << ", " << y;
      Vec2 back = d.apply(u);
      EXPECT_LT(std::hypot(back.x - x, back.y - y), Distortion::kUndistortTolerance);
    }
}

TEST(GeometryCamera, WithoutIntrinsicsTheFovPathIsUnchanged) {
  Camera c;
  c.eye = {0.4, 1.3, 2.1};
  c.width = 640;
  c.height = 480;
  c.fov_y_deg = 50;
  // The pinhole's formula, written out as it always was (the code path is the old one, line for line; here
  // the compiler may fold constants or fuse multiply-adds differently, hence a few ulps).
  Vec3 f = normalize(c.target - c.eye), r = normalize(cross(f, c.up)), u = cross(r, f);
  double t = std::tan(50 * kPi / 360.0), aspect = 640.0 / 480;
  for (double px : {0.0, 0.5, 123.25, 639.5})
    for (double py : {0.0, 7.5, 479.5}) {
      double sx = (2 * px / 640 - 1) * t * aspect, sy = (1 - 2 * py / 480) * t;
      Vec3 want = normalize(f + r * sx + u * sy), got = c.ray_direction(px, py);
      EXPECT_NEAR(want.x, got.x, 1e-15);
      EXPECT_NEAR(want.y, got.y, 1e-15);
      EXPECT_NEAR(want.z, got.z, 1e-15);
      // project inverts it too, and the pinhole's intrinsics give the same rays.
      auto q = c.project(c.eye + got * 2);
      ASSERT_TRUE(q);
      EXPECT_NEAR(q->x, px, 1e-9);
      EXPECT_NEAR(q->y, py, 1e-9);
      Camera k = c;
      k.intrinsics = c.effective_intrinsics();
      EXPECT_LT(length(k.ray_direction(px, py) - got), 1e-14);
    }
  // And so is its GL projection: intrinsics equal to the pinhole's give the same matrix.
  Camera k = c;
  k.intrinsics = c.effective_intrinsics();
  auto a = c.projection(), b = k.projection();
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(a[i], b[i], 1e-6) << i;
}

TEST(GeometryCamera, ProjectionMatrixPlacesPointsWhereProjectDoes) {
  Camera c = lens_camera();
  c.distortion = {};
  auto m = mul(c.projection(), c.view());
  for (Vec3 p : {Vec3{0, 0, 0}, Vec3{0.3, -0.2, 0.4}, Vec3{-0.5, 0.6, -0.3}}) {
    double clip[4];
    for (int row = 0; row < 4; ++row)
      clip[row] = m[0 * 4 + row] * p.x + m[1 * 4 + row] * p.y + m[2 * 4 + row] * p.z + m[3 * 4 + row];
    double px = (clip[0] / clip[3] + 1) / 2 * c.width, py = (1 - clip[1] / clip[3]) / 2 * c.height;
    auto q = c.project(p);
    ASSERT_TRUE(q);
    EXPECT_NEAR(px, q->x, 2e-3);
    EXPECT_NEAR(py, q->y, 2e-3);
  }
}

TEST(GeometryCamera, PointsBehindTheEyeDoNotProject) {
  Camera c = lens_camera();
  EXPECT_FALSE(c.project(c.eye - (c.target - c.eye)));
  EXPECT_FALSE(c.project(c.eye));
}

TEST(GeometryCamera, BadLensesAreRefused) {
  Camera c = lens_camera();
  c.intrinsics->fx = -3;
  EXPECT_THROW(require_camera(c), Error);
  c = lens_camera();
  c.intrinsics->cy = std::nan("");
  EXPECT_THROW(require_camera(c), Error);
  c = lens_camera();
  c.distortion.k1 = 1e9;
  EXPECT_THROW(require_camera(c), Error);
  c = lens_camera();
  c.intrinsics.reset();
  EXPECT_THROW(require_camera(c), Error);  // distortion without intrinsics
}
