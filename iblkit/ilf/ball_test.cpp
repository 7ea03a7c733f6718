// Tests of the mirror ball's optics (ilf/ball.h, [1] §5.2): closed-form rays of a ball seen by an
// orthographic and by a perspective camera, the solid angles they cover, the manifest fields, and a
// closed-form light field captured with parallax, resampled with and without the compensation.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "iblkit/core/testing.h"
#include "iblkit/ilf/analytic.h"
#include "iblkit/ilf/ball.h"
#include "iblkit/ilf/build.h"
#include "iblkit/io/image_io.h"

using ibl::test_util::expect_error;

namespace ibl::ilf {
namespace {
namespace fs = std::filesystem;

std::string temp_dir(const std::string& name) {
  auto d = fs::temp_directory_path() / fmt::format("iblkit_ilfball_{}_{}", name, ::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

void expect_vec(Vec3 a, Vec3 b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// Orthographic camera: the image point at a = sin 45° sees the ball's surface at 45° from the axis,
// whose normal (√½, 0, √½) turns the ray along −Z into +X; the centre reflects the ray back at the
// camera from the ball's pole.
TEST(IlfBall, OrthographicClosedForm) {
  BallOptics o{0.05, 0};
  const int W = 1000;
  Vec3 s, d;
  double a = std::sqrt(0.5);
  ASSERT_TRUE(ball_ray(o, W, W, (a + 1) * W / 2, W / 2.0, &s, &d));
  expect_vec(s, Vec3{a, 0, a} * 0.05, 1e-12);
  expect_vec(d, {1, 0, 0}, 1e-12);
  ASSERT_TRUE(ball_ray(o, W, W, W / 2.0, W / 2.0, &s, &d));
  expect_vec(s, {0, 0, 0.05}, 1e-12);
  expect_vec(d, {0, 0, 1}, 1e-12);
  EXPECT_FALSE(ball_ray(o, W, W, 0.5, 0.5, &s, &d));  // a corner pixel misses the ball
  // Zero radius: the same directions from the centre.
  ASSERT_TRUE(ball_ray({0, 0}, W, W, (a + 1) * W / 2, W / 2.0, &s, &d));
  expect_vec(s, {0, 0, 0}, 0);
  expect_vec(d, {1, 0, 0}, 1e-12);
}

// Perspective camera at C = (0, 0, D): pick a surface point h = r·n by its normal, find the pixel that
// sees it (the pinhole ray towards h), and check that ball_ray returns h and the mirror reflection of
// the incoming ray u = (h − C)/|h − C| about n, d = u − 2(u·n)n.
TEST(IlfBall, PerspectiveReflectsTheKnownRay) {
  const double r = 0.05, D = 0.4;
  BallOptics o{r, D};
  const int W = 2000;
  double tan_a = r / std::sqrt(D * D - r * r);
  for (double th_deg : {0.0, 10.0, 30.0, 50.0, 65.0}) {
    for (double phi_deg : {0.0, 70.0, 200.0}) {
      double th = th_deg * kPi / 180, ph = phi_deg * kPi / 180;
      Vec3 n{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
      Vec3 h = n * r, C{0, 0, D};
      Vec3 u = normalize(h - C);
      ASSERT_LT(dot(u, n), 0) << "the point must face the camera";
      double a = (u.x / -u.z) / tan_a, b = (u.y / -u.z) / tan_a;
      Vec3 s, d;
      ASSERT_TRUE(ball_ray(o, W, W, (a + 1) * W / 2, (1 - b) * W / 2, &s, &d)) << th_deg;
      expect_vec(s, h, 1e-9);
      expect_vec(d, u - n * (2 * dot(u, n)), 1e-9);
    }
  }
  // The centre pixel reflects straight back; the silhouette grazes (d ≈ the view ray, α from −Z).
  Vec3 s, d;
  ASSERT_TRUE(ball_ray(o, W, W, W / 2.0, W / 2.0, &s, &d));
  expect_vec(s, {0, 0, r}, 1e-12);
  expect_vec(d, {0, 0, 1}, 1e-12);
  ASSERT_TRUE(ball_ray(o, W, W, W * (1 - 1e-9), W / 2.0, &s, &d));
  EXPECT_NEAR(std::acos(-d.z), std::asin(r / D), 1e-3);
}

// Σ solid angles: the orthographic ball sees the whole sphere, the perspective one all but the cone
// of half-angle α = asin(r/D) behind the ball: 2π(1 + cos α).
TEST(IlfBall, SolidAnglesCoverTheVisibleSphere) {
  const int W = 128;
  for (double D : {0.15, 0.4, 2.0}) {
    BallOptics o{0.05, D};
    double sum = 0;
    for (int y = 0; y < W; ++y)
      for (int x = 0; x < W; ++x) sum += ball_pixel_solid_angle(o, W, W, x, y);
    double alpha = std::asin(0.05 / D);
    EXPECT_NEAR(sum, 2 * kPi * (1 + std::cos(alpha)), 0.01 * 4 * kPi) << D;
  }
}

TEST(IlfBall, ManifestFieldsAndDirectionTable) {
  auto d = temp_dir("manifest");
  auto m = d + "/s.json";
  auto write = [&](const std::string& extra) {
    std::ofstream(m)
        << R"({"format":"iblkit.sequence/1","mapping":"mirrorball",)" << extra
        << R"("volume":{"min":[0,0,0],"max":[1,1,1]},"probes":[{"image":"a.exr","position":[0.5,0.5,0.5]}]})";
  };
  write(R"("ball_radius":-1,)");
  expect_error([&] { read_sequence(m); }, {"\"ball_radius\"", "outside"});
  write(R"("ball_radius":"big",)");
  expect_error([&] { read_sequence(m); }, {"\"ball_radius\"", "not a number"});
  write(R"("ball_radius":0.05,"ball_distance":0.03,)");
  expect_error([&] { read_sequence(m); }, {"\"ball_distance\"", "below it"});
  write(R"("ball_distance":0.5,)");
  expect_error([&] { read_sequence(m); }, {"\"ball_distance\""});
  std::ofstream(m)
      << R"({"format":"iblkit.sequence/1","mapping":"latlong","ball_radius":0.05,"volume":{"min":[0,0,0],"max":[1,1,1]},"probes":[{"image":"a.exr","position":[0.5,0.5,0.5]}]})";
  expect_error([&] { read_sequence(m); }, {"mirrorball"});
  write(R"("ball_radius":0.05,"ball_distance":0.6,)");
  Sequence seq = read_sequence(m);
  EXPECT_EQ(seq.ball.radius, 0.05);
  EXPECT_EQ(seq.ball.distance, 0.6);
  write_sequence(d + "/t.json", seq);
  Sequence back = read_sequence(d + "/t.json");
  EXPECT_EQ(back.ball.radius, 0.05);
  EXPECT_EQ(back.ball.distance, 0.6);
  // The table: every slot starts on the ball (rotated to the world), its direction the reflection there.
  seq.rotation = Mat3::rows({0, 0, 1}, {1, 0, 0}, {0, 1, 0});
  auto t = make_direction_table(seq, 32, 32, BucketDesc{}, 1);
  ASSERT_EQ(t.start.size(), t.dir.size());
  double sum = 0;
  for (int64_t s = 0; s < t.slots(); ++s) {
    Vec3 st{t.start[3 * s], t.start[3 * s + 1], t.start[3 * s + 2]};
    EXPECT_NEAR(length(st), 0.05, 1e-6);
    int px = t.pixel[s] % 32, py = t.pixel[s] / 32;
    Vec3 s0, d0;
    ASSERT_TRUE(ball_ray(seq.ball, 32, 32, px + 0.5, py + 0.5, &s0, &d0));
    expect_vec(st, seq.rotation * s0, 1e-6);
    expect_vec({t.dir[3 * s], t.dir[3 * s + 1], t.dir[3 * s + 2]}, seq.rotation * d0, 1e-6);
    sum += t.weight[s];
  }
  EXPECT_NEAR(sum, 2 * kPi * (1 + std::cos(std::asin(0.05 / 0.6))), 0.03 * 4 * kPi);
  // A single viewpoint keeps no starts.
  seq.ball = {};
  EXPECT_TRUE(make_direction_table(seq, 32, 32, BucketDesc{}, 1).start.empty());
}

// The closed-form field of analytic.h captured by balls of 15 cm radius (each pixel = the field along
// its ray from the ball's surface), resampled with and without the compensation, against the exact SH
// at the grid points: starting the rays on the ball must remove most of the parallax error.
TEST(IlfBall, ParallaxCompensationOnAClosedFormField) {
  auto field = AnalyticField::three_spheres();
  std::string dir = temp_dir("parallax");
  fs::create_directories(dir + "/frames");
  Sequence seq;
  seq.mapping = sphere::MappingKind::MirrorBall;
  seq.ball = {0.15, 0};
  seq.volume = {{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}};
  seq.volume_given = true;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-0.5, 0.5);
  const int S = 32, ss = 2;
  for (int p = 0; p < 300; ++p) {
    Vec3 x{U(rng), U(rng), U(rng)};
    Image img(S, S, 3);
    for (int y = 0; y < S; ++y)
      for (int xx = 0; xx < S; ++xx) {
        Vec3 acc{0, 0, 0};
        int n = 0;
        for (int k = 0; k < ss * ss; ++k) {
          Vec3 s, d;
          if (!ball_ray(seq.ball, S, S, xx + (k % ss + 0.5) / ss, y + (k / ss + 0.5) / ss, &s, &d)) continue;
          acc += field.radiance(x + s, normalize(d));
          ++n;
        }
        if (n) img.set_rgb(xx, y, acc / n);
      }
    std::string f = fmt::format("{}/frames/{:04d}.pfm", dir, p);
    io::write_image(f, img);
    seq.probes.push_back({f, x});
  }
  write_sequence(dir + "/sequence.json", seq);
  seq = read_sequence(dir + "/sequence.json");
  double err[2];
  std::vector<sh::Coeffs> exact;
  for (int with = 0; with < 2; ++with) {
    BuildDesc bd;
    bd.nx = bd.ny = bd.nz = 8;
    bd.buckets.dir = dir + "/buckets";
    bd.ball_parallax = with == 1;
    SHGrid g = build_shgrid(seq, bd);
    if (exact.empty()) {
      std::vector<Vec3> pts;
      for (int64_t i = 0; i < g.grid().count(); ++i) pts.push_back(g.grid().point(i));
      exact = field.exact_sh(pts, g.bands(), seq, 96, 2);
    }
    double num = 0, den = 0;
    int K = g.coeff_count();
    for (int64_t i = 0; i < g.grid().count(); ++i)
      for (int k = 0; k < K; ++k)
        for (int c = 0; c < 3; ++c) {
          num += std::pow(g.data()[(size_t(i) * K + k) * 3 + c] - exact[i].c[k][c], 2);
          den += std::pow(exact[i].c[k][c], 2);
        }
    err[with] = std::sqrt(num / den);
  }
  std::printf("[ilf] ball radius 0.15 m, 8^3: rel L2 %.4f without, %.4f with the compensation\n", err[0], err[1]);
  EXPECT_LT(err[1], 0.8 * err[0]);
}

}  // namespace
}  // namespace ibl::ilf
