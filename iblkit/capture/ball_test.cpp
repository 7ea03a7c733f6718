// Chrome-ball probes (issue 29 §2): the inverse optics, the conductor's Fresnel curve, the circle fit,
// and probes unwarped from photographs of known light against the exact answer.
#include "iblkit/capture/ball.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "iblkit/capture/ball_calibrate.h"
#include "iblkit/capture/probe_eval.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/ilf/ball.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::capture {
namespace {

using Env = std::function<Vec3(Vec3)>;

// A smooth, lopsided sky: a warm lobe up and to +X, a blue lobe towards +Z (where the camera stands),
// a dim floor. Strong enough variation that the orthographic approximation's errors show.
Vec3 sky(Vec3 d) {
  Vec3 s1 = normalize(Vec3{0.6, 0.7, -0.4}), s2 = normalize(Vec3{-0.3, 0.2, 1});
  double a = std::pow(std::max(0.0, dot(d, s1)), 6), b = std::pow(std::max(0.0, dot(d, s2)), 3);
  double up = 0.5 + 0.5 * d.y;
  return Vec3{0.05, 0.05, 0.06} + Vec3{4.0, 3.0, 1.5} * a + Vec3{0.3, 0.6, 1.4} * b + Vec3{0.2, 0.25, 0.3} * up;
}

// A photograph of a chrome ball: W×W pixels, the silhouette at the centre with radius r, the pinhole at
// D radii (the camera stands at R_y(angle)·(0, 0, D) and looks at the ball). n×n rays per pixel; the
// background black.
Image photograph(const Env& env, int W, double r, double D, double angle_deg, const BallReflectance& refl, int n = 2,
                 Vec3 background = {}) {
  Image img(W, W, 3);
  const ilf::BallOptics o{1.0, D};
  const double tan_a = 1 / std::sqrt(D * D - 1), c = W / 2.0;
  const Mat3 to_world = Mat3::rotation({0, 1, 0}, angle_deg * kPi / 180);
  parallel_for(0, W, [&](int64_t y) {
    for (int x = 0; x < W; ++x) {
      Vec3 sum;
      for (int s = 0; s < n * n; ++s) {
        double a = (x + (s % n + 0.5) / n - c) / r, b = (c - (y + (s / n + 0.5) / n)) / r;
        Vec3 v = normalize(Vec3{a * tan_a, b * tan_a, -1}), start, dir;
        if (!ilf::ball_reflect(o, v, &start, &dir)) {
          sum += background;
          continue;
        }
        Vec3 R = refl.at(-dot(v, start));
        Vec3 L = env(to_world * dir);
        sum += Vec3{L.x * R.x, L.y * R.y, L.z * R.z};
      }
      img.set_rgb(x, static_cast<int>(y), sum / (n * n));
    }
  });
  return img;
}

// The exact lat-long map of env (n×n sub-samples per pixel), alpha-weighted like `like`: only the
// sub-directions a probe with that validity sees.
sphere::EnvMap truth_like(const Env& env, const sphere::EnvMap& like, const std::function<bool(Vec3)>& seen,
                          int n = 2) {
  const int W = like.image.width(), H = like.image.height();
  Image img(W, H, 4);
  parallel_for(0, H, [&](int64_t y) {
    for (int x = 0; x < W; ++x) {
      Vec3 sum;
      int k = 0, used = 0;
      for (int s = 0; s < n * n; ++s) {
        Vec3 d;
        if (!like.mapping.to_direction(x + (s % n + 0.5) / n, y + (s / n + 0.5) / n, &d)) continue;
        ++used;
        if (!seen(d)) continue;
        sum += env(d);
        ++k;
      }
      if (k) img.set_rgb(x, static_cast<int>(y), sum / k);
      img.at(x, static_cast<int>(y), 3) = used ? float(k) / used : 0.0f;
    }
  });
  return {img, like.mapping};
}

TEST(CaptureBall, InverseOpticsRoundTrip) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  for (double D : {0.0, 1.5, 5.0, 40.0}) {
    ilf::BallOptics o = D > 0 ? ilf::BallOptics{1.0, D} : ilf::BallOptics{};
    double alpha = D > 0 ? std::asin(1 / D) : 0;
    int checked = 0;
    for (int i = 0; i < 2000; ++i) {
      Vec3 d = normalize(Vec3{g(rng), g(rng), g(rng)}), view, n;
      bool blind = std::acos(std::clamp(-d.z, -1.0, 1.0)) <= alpha * (1 - 1e-9);
      bool ok = ilf::ball_view_for(o, d, &view, &n);
      ASSERT_EQ(ok, !blind) << "D " << D;
      if (!ok) continue;
      Vec3 back = view.z < -0.999999 && D == 0 ? Vec3{0, 0, -1} + n * (2 * n.z) : Vec3{};
      if (D > 0) {
        Vec3 start, dir;
        ASSERT_TRUE(ilf::ball_reflect(o, view, &start, &dir));
        back = dir;
        EXPECT_LT(length(start - n), 1e-6);
      }
      EXPECT_LT(length(back - d), 1e-6) << "D " << D;
      ++checked;
    }
    EXPECT_GT(checked, 2000 * (1 - (1 - std::cos(alpha)) / 2) * 0.95);  // all but the blind cone
  }
}

TEST(CaptureBall, ImagePointMatchesBallRay) {
  // ball_image_point inverts ilf::ball_ray for a silhouette filling a W×H frame.
  for (double D : {0.0, 5.0}) {
    ilf::BallOptics o = D > 0 ? ilf::BallOptics{1.0, D} : ilf::BallOptics{};
    for (double px : {10.3, 64.0, 100.7})
      for (double py : {20.1, 64.0, 90.2}) {
        Vec3 start, dir, view, n;
        if (!ilf::ball_ray(o, 128, 128, px, py, &start, &dir)) continue;  // off the disc
        ASSERT_TRUE(ilf::ball_view_for(o, dir, &view, &n));
        double qx, qy;
        ilf::ball_image_point(o, view, n, 64, 64, 64, &qx, &qy);
        EXPECT_NEAR(qx, px, 1e-5);
        EXPECT_NEAR(qy, py, 1e-5);
      }
  }
}

TEST(CaptureBall, ConductorFresnel) {
  Conductor c = chrome();
  Vec3 f0 = fresnel_conductor(c, 1.0);
  double n = 3.1, k = 3.3;
  EXPECT_NEAR(f0.x, ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k), 1e-12);
  EXPECT_NEAR(fresnel_conductor(c, 0.0).y, 1.0, 1e-12);
  // A metal's dip below F(0) near 80° is shallow; the rise to 1 comes after it.
  EXPECT_GT(fresnel_conductor(c, std::cos(88 * kPi / 180)).x, f0.x);
  BallReflectance r;
  r.r0 = Vec3{0.6, 0.6, 0.6};
  EXPECT_NEAR(r.at(1.0).x, 0.6, 1e-12);
  EXPECT_NEAR(r.at(0.0).x, 0.6 / f0.x, 1e-12);  // scaled curve (R rises by 1/F(0))
  r.fresnel = false;
  EXPECT_DOUBLE_EQ(r.at(0.1).z, 0.6);
  EXPECT_THROW(parse_fresnel("gold", &r), Error);
  parse_fresnel("2.5,3", &r);
  EXPECT_DOUBLE_EQ(r.metal.k.y, 3.0);
}

TEST(CaptureBall, FindsTheBallAndSaysWhenItCannot) {
  BallReflectance refl;
  // A grey backdrop behind the ball, as a room would be.
  Image photo = photograph(sky, 320, 120, 5, 0, refl, 4, {0.02, 0.02, 0.02});
  CircleFit f = find_ball(photo);
  std::printf("circle fit: (%.3f, %.3f) r %.3f (true 160, 160, 120), residual %.3f px, %.0f %% of the outline\n",
              f.circle.cx, f.circle.cy, f.circle.r, f.residual_px, 100 * f.coverage);
  EXPECT_NEAR(f.circle.cx, 160, 0.5);
  EXPECT_NEAR(f.circle.cy, 160, 0.5);
  EXPECT_NEAR(f.circle.r, 120, 0.75);
  EXPECT_LT(f.residual_px, 0.6);
  EXPECT_GT(f.coverage, 0.9);
  Image flat(200, 200, 3, 0.5f);
  try {
    find_ball(flat, "flat.exr");
    FAIL() << "a flat image has no ball";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--ball"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("flat.exr"), std::string::npos) << e.what();
  }
}

// One view, exact optics: irradiance over 20480 normals against the exact map of the same directions;
// the orthographic approximation of the same photograph for comparison (issue: ~8 % at 5 radii).
TEST(CaptureBall, OneViewPerspectiveIsExactOrthographicIsNot) {
  BallReflectance refl;  // chrome with its Fresnel rise
  const double D = 5;
  Image photo = photograph(sky, 512, 250, D, 0, refl);
  FromBallDesc fd;
  fd.size = 64;
  FromBallResult persp = probe_from_ball({{photo, {256, 256, 250}, D, 0, "persp"}}, fd);
  FromBallResult ortho = probe_from_ball({{photo, {256, 256, 250}, 0, 0, "ortho"}}, fd);
  EXPECT_NEAR(persp.blind_cone_deg, std::asin(1 / D) * 180 / kPi, 1e-9);
  EXPECT_GT(persp.invalid_pixels, 0);
  const ilf::BallOptics o{1.0, D};
  auto seen = [&](Vec3 d) {
    Vec3 v, n;
    return ilf::ball_view_for(o, d, &v, &n);
  };
  sphere::EnvMap truth = truth_like(sky, persp.probe, seen);
  auto normals = sphere::fibonacci_sphere(20480);
  auto Et = probe_irradiance(truth, normals), Ep = probe_irradiance(persp.probe, normals),
       Eo = probe_irradiance(ortho.probe, normals);
  double ep = mean_relative_luminance_error(Ep, Et), eo = mean_relative_luminance_error(Eo, Et);
  std::printf("one view at %.0f radii, 20480 normals: perspective %.3f %%, orthographic %.3f %% mean relative\n", D,
              100 * ep, 100 * eo);
  EXPECT_LT(ep, 0.01);
  EXPECT_GT(eo, 0.03);
  // Without the Fresnel division the rim is too bright by the rise.
  FromBallDesc flat = fd;
  flat.reflectance.fresnel = false;
  FromBallResult nofresnel = probe_from_ball({{photo, {256, 256, 250}, D, 0, "flat"}}, flat);
  double en = mean_relative_luminance_error(probe_irradiance(nofresnel.probe, normals), Et);
  std::printf("  without the Fresnel rise: %.3f %%\n", 100 * en);
  EXPECT_GT(en, 2 * ep);
}

TEST(CaptureBall, TwoViewsCoverTheSphere) {
  BallReflectance refl;
  const double D = 5;
  Image a = photograph(sky, 384, 180, D, 0, refl), b = photograph(sky, 384, 180, D, 90, refl);
  FromBallDesc fd;
  fd.size = 64;
  FromBallResult r = probe_from_ball({{a, {192, 192, 180}, D, 0, "a"}, {b, {192, 192, 180}, D, 90, "b"}}, fd);
  EXPECT_EQ(r.invalid_pixels, 0);
  sphere::EnvMap truth = truth_like(sky, r.probe, [](Vec3) { return true; });
  auto normals = sphere::fibonacci_sphere(4096);
  double e = mean_relative_luminance_error(probe_irradiance(r.probe, normals), probe_irradiance(truth, normals));
  std::printf("two views 90° apart: %.3f %% mean relative irradiance\n", 100 * e);
  EXPECT_LT(e, 0.01);
  // The weights: view 0 owns view 1's axis (±X in view 0's frame), view 1 owns view 0's (±Z).
  auto share = [&](Vec3 d) {
    double px, py;
    r.probe.mapping.to_pixel(d, &px, &py);
    return r.weights.at(static_cast<int>(px), static_cast<int>(py), 0);
  };
  EXPECT_FLOAT_EQ(share({0, 0, 1}), 0.0f);
  EXPECT_FLOAT_EQ(share({0, 0, -1}), 0.0f);
  EXPECT_FLOAT_EQ(share({1, 0, 0}), 1.0f);
  EXPECT_FLOAT_EQ(share({-1, 0, 0}), 1.0f);
  // The angle from the overlap.
  AngleEstimate est = estimate_angle({{a, {192, 192, 180}, D, 0, "a"}, {b, {192, 192, 180}, D, 0, "b"}}, fd);
  std::printf("estimated angle %.3f° (true 90°), mean |log difference| %.4f over %d directions\n", est.angle_deg,
              est.residual, est.directions);
  EXPECT_NEAR(est.angle_deg, 90, 0.5);
  // A wrong angle shows: the views disagree.
  FromBallResult wrong = probe_from_ball({{a, {192, 192, 180}, D, 0, "a"}, {b, {192, 192, 180}, D, -90, "b"}}, fd);
  EXPECT_GT(mean_relative_luminance_error(probe_irradiance(wrong.probe, normals), probe_irradiance(truth, normals)),
            5 * e);
}

TEST(CaptureBall, BadInput) {
  Image photo(100, 100, 3, 0.1f);
  FromBallDesc fd;
  EXPECT_THROW(probe_from_ball({}, fd), Error);
  EXPECT_THROW(probe_from_ball({{photo, {90, 50, 30}, 5, 0, "x"}}, fd), Error);    // partly outside
  EXPECT_THROW(probe_from_ball({{photo, {50, 50, 30}, 0.5, 0, "x"}}, fd), Error);  // inside the ball
  EXPECT_DOUBLE_EQ(distance_from_lens(100, 1000, 50, 36), 1 / std::sin(std::atan(100 / (50.0 / 36 * 1000))));
}

// The reflectance calibrated from a light seen in the ball and directly: a dim room with a window of
// radiance (8, 6, 4) filling a 12° cone, photographed in a ball of r0 = (0.6, 0.55, 0.5) with chrome's rise,
// at 8 radii; the light's own image a block of the same radiance. r0 comes back within 0.5 % near normal
// incidence and at 59–71° (where chrome's F(θ)/F(0) dips 5 %, which a plain ratio keeps); bad boxes are refused.
TEST(CaptureBall, ReflectanceCalibratedFromAKnownLight) {
  const Vec3 Lw{8, 6, 4}, r0{0.6, 0.55, 0.5};
  BallReflectance refl;
  refl.r0 = r0;
  const double D = 8, r = 230;
  const int W = 512;
  Image direct(64, 64, 3, 0.05f);
  for (int y = 20; y < 44; ++y)
    for (int x = 20; x < 44; ++x) direct.set_rgb(x, y, Lw);
  for (double from_axis_deg : {30.0, 124.0}) {  // the window's direction from +Z (the camera's side)
    const double t = from_axis_deg * kPi / 180;
    const Vec3 dl{std::sin(t), 0.2, std::cos(t)};
    const Vec3 dw = normalize(dl);
    Env room = [&](Vec3 d) { return dot(d, dw) > std::cos(12 * kPi / 180) ? Lw : Vec3{0.05, 0.05, 0.05}; };
    BallView v{photograph(room, W, r, D, 0, refl, 3), {W / 2.0, W / 2.0, r}, D, 0, "ball"};
    Vec3 view, nrm;
    ASSERT_TRUE(ilf::ball_view_for({1.0, D}, dw, &view, &nrm));
    double px = 0, py = 0;
    ilf::ball_image_point({1.0, D}, view, nrm, v.ball.cx, v.ball.cy, v.ball.r, &px, &py);
    const PixelBox in_ball{px - 30, py - 30, 60, 60}, in_direct{10, 10, 44, 44};
    ReflectanceFit f = calibrate_reflectance(v, refl, in_ball, direct, in_direct);
    std::printf(
        "[capture] window %.0f° from the camera: r0 %.4f %.4f %.4f from %d ball pixels at %.1f–%.1f°, "
        "spread %.4f\n",
        from_axis_deg, f.r0.x, f.r0.y, f.r0.z, f.ball_pixels, f.incidence_min_deg, f.incidence_max_deg, f.spread);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(f.r0[c] / r0[c], 1, 0.005) << from_axis_deg << " channel " << c;
    EXPECT_NEAR(f.light.x, Lw.x, 1e-6);
    EXPECT_GT(f.ball_pixels, 20);
    EXPECT_EQ(f.direct_pixels, 24 * 24);
    if (from_axis_deg > 90) {
      EXPECT_GT(f.incidence_min_deg, 50);
      BallReflectance flat = refl;  // the ratio without the metal's curve taken out is off by F(θ)/F(0)
      flat.fresnel = false;
      ReflectanceFit g = calibrate_reflectance(v, flat, in_ball, direct, in_direct);
      std::printf("[capture] without the metal's curve: r0 %.4f (%.1f %% off)\n", g.r0.y, 100 * (g.r0.y / r0.y - 1));
      EXPECT_GT(std::abs(g.r0.y / r0.y - 1), 0.02);
    }
  }
  Image photo(W, W, 3, 0.0f);  // a black ball: no light in any box
  BallView v{photo, {W / 2.0, W / 2.0, r}, D, 0, "ball"};
  EXPECT_THROW(calibrate_reflectance(v, refl, {500, 500, 40, 40}, direct, {10, 10, 44, 44}), Error);  // leaves it
  EXPECT_THROW(calibrate_reflectance(v, refl, {0, 0, 20, 20}, direct, {10, 10, 44, 44}), Error);      // beside the ball
  EXPECT_THROW(calibrate_reflectance(v, refl, {200, 200, 40, 40}, direct, {10, 10, 44, 44}), Error);  // no light
  EXPECT_THROW(calibrate_reflectance(v, refl, {200, 200, 40, 40}, direct, {10, 10, NAN, 44}), Error);
}

}  // namespace
}  // namespace ibl::capture
