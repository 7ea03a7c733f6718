#include "iblkit/sphere/mapping.h"

#include <gtest/gtest.h>

#include <random>

#include "iblkit/core/error.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::sphere {
namespace {

// Round trips go through double-precision trig; 1e-9 px leaves room for acos near the poles.
constexpr double kRoundTripPixelTol = 1e-6;
// Σ solid angles = 4π: exact formulas for latlong, cube, mirror ball, octahedral (rounding only);
// the angular map's rim pixels use a 48×48 midpoint rule.
constexpr double kExactSumTol = 1e-9;
constexpr double kAngularSumTol = 1e-6;

std::vector<Mapping> all_mappings() {
  return {Mapping(MappingKind::LatLong, 64, 32),    Mapping(MappingKind::MirrorBall, 48, 48),
          Mapping(MappingKind::Angular, 48, 48),    Mapping(MappingKind::CubeHCross, 64, 48),
          Mapping(MappingKind::CubeVCross, 48, 64), Mapping(MappingKind::CubeStrip, 96, 16),
          Mapping(MappingKind::Octahedral, 32, 32), Mapping(MappingKind::Octahedral, 33, 33)};
}

TEST(Mapping, LatLongMatchesDesignFormula) {
  Mapping m(MappingKind::LatLong, 360, 180);
  // u = atan2(d.z, d.x)/(2π) + 0.5 and θ = π v from +Y (docs/conventions.md).
  Vec3 d;
  ASSERT_TRUE(m.to_direction(0.25 * 360, 0.5 * 180, &d));  // u = 0.25: φ = π/2 → d = (0, 0, −1)
  EXPECT_NEAR(d.x, 0, 1e-12);
  EXPECT_NEAR(d.y, 0, 1e-12);
  EXPECT_NEAR(d.z, -1, 1e-12);
  ASSERT_TRUE(m.to_direction(0.5 * 360, 0.5 * 180, &d));  // u = 0.5 → +X
  EXPECT_NEAR(d.x, 1, 1e-12);
  ASSERT_TRUE(m.to_direction(180, 0, &d));  // top row edge → +Y
  EXPECT_NEAR(d.y, 1, 1e-12);
}

TEST(Mapping, RoundTripEveryMapping) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0, 1);
  for (const Mapping& m : all_mappings()) {
    int tested = 0;
    for (int i = 0; i < 20000; ++i) {
      double px = U(rng) * m.width(), py = U(rng) * m.height();
      Vec3 d;
      if (!m.to_direction(px, py, &d)) continue;
      EXPECT_NEAR(length(d), 1.0, 1e-12);
      double qx, qy;
      ASSERT_TRUE(m.to_pixel(d, &qx, &qy));
      Vec3 d2;
      m.to_direction(qx, qy, &d2);
      // Compare directions (pixels are ambiguous only on seams and at the poles).
      EXPECT_LT(length(d - d2), 1e-9) << mapping_name(m.kind()) << " at " << px << "," << py;
      if (m.kind() != MappingKind::LatLong || (py > 1 && py < m.height() - 1)) {
        bool seam = m.kind() == MappingKind::MirrorBall || m.kind() == MappingKind::Angular;
        if (!seam) {
          EXPECT_NEAR(qx, px, kRoundTripPixelTol) << mapping_name(m.kind());
          EXPECT_NEAR(qy, py, kRoundTripPixelTol) << mapping_name(m.kind());
        }
      }
      ++tested;
    }
    EXPECT_GT(tested, 5000) << mapping_name(m.kind());
  }
  // And direction → pixel → direction from random directions.
  std::normal_distribution<double> N(0, 1);
  for (const Mapping& m : all_mappings())
    for (int i = 0; i < 20000; ++i) {
      Vec3 d = normalize({N(rng), N(rng), N(rng)});
      double px, py;
      ASSERT_TRUE(m.to_pixel(d, &px, &py));
      Vec3 d2;
      ASSERT_TRUE(m.to_direction(px, py, &d2)) << mapping_name(m.kind());
      EXPECT_LT(length(d - d2), 1e-9) << mapping_name(m.kind());
    }
}

// Hostile input: odd-sized mirror balls, whose middle column touches the disc at its top and bottom
// edge, once summed to more than 4π (a 1×1 ball to 16 sr).
TEST(Mapping, OddMirrorBallsSumToFourPi) {
  for (int n : {1, 3, 5, 9}) {
    Mapping m(MappingKind::MirrorBall, n, n);
    double sum = 0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) sum += m.solid_angle(x, y);
    EXPECT_NEAR(sum, 4 * kPi, 1e-9) << n << "×" << n;
  }
}

TEST(Mapping, SolidAnglesSumToFourPi) {
  for (const Mapping& m : all_mappings()) {
    double sum = 0;
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) {
        double w = m.solid_angle(x, y);
        EXPECT_GE(w, 0.0);
        sum += w;
      }
    double tol = m.kind() == MappingKind::Angular ? kAngularSumTol : kExactSumTol;
    EXPECT_NEAR(sum / kFourPi, 1.0, tol) << mapping_name(m.kind());
  }
}

// Each pixel's solid angle against a brute-force estimate (fine grid of sub-pixel directions,
// each weighted by the Jacobian measured with finite differences).
TEST(Mapping, SolidAngleMatchesBruteForce) {
  constexpr double kBruteTol = 2e-3;  // the brute force itself: 64² sub-samples, finite differences
  constexpr double kFoldBruteTol = 1.5e-2;
  for (const Mapping& m : all_mappings()) {
    std::mt19937 rng(3);
    for (int k = 0; k < 25; ++k) {
      int x = std::uniform_int_distribution<int>(0, m.width() - 1)(rng);
      int y = std::uniform_int_distribution<int>(0, m.height() - 1)(rng);
      const int n = 64;
      double est = 0, h = 1e-4;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          double px = x + (i + 0.5) / n, py = y + (j + 0.5) / n;
          Vec3 d, dx, dy;
          if (!m.to_direction(px, py, &d)) {
            if (m.kind() == MappingKind::MirrorBall || m.kind() == MappingKind::Angular) {
              double a = 2 * px / m.width() - 1, b = 1 - 2 * py / m.height();
              if (a * a + b * b > 1) continue;
            } else {
              continue;
            }
          }
          m.to_direction(px + h, py, &dx);
          m.to_direction(px, py + h, &dy);
          est += length(cross(dx - d, dy - d)) / (h * h) / (n * n);
        }
      double exact = m.solid_angle(x, y);
      // Across the octahedral fold the Jacobian jumps and the midpoint rule converges only O(1/n)
      // (checked: 64² → 1.0%, 1024² → 0.06% off the exact value on a fold pixel).
      double tol = m.kind() == MappingKind::Octahedral ? kFoldBruteTol : kBruteTol;
      EXPECT_NEAR(est, exact, tol * std::max(exact, 1e-3 * kFourPi / (m.width() * m.height())))
          << mapping_name(m.kind()) << " pixel " << x << "," << y;
    }
  }
}

// The mirror ball's equal-weight property (docs/conventions.md): every pixel fully inside the disc covers
// 4π/(π r²) steradians per unit image area.
TEST(Mapping, MirrorBallEqualSolidAngle) {
  Mapping m(MappingKind::MirrorBall, 250, 250);
  double r = 125.0, expected = kFourPi / (kPi * r * r);
  int inside = 0;
  for (int y = 0; y < 250; ++y)
    for (int x = 0; x < 250; ++x) {
      double a = std::max(std::abs(x - 125.0), std::abs(x + 1 - 125.0));
      double b = std::max(std::abs(y - 125.0), std::abs(y + 1 - 125.0));
      if (a * a + b * b > r * r) continue;
      EXPECT_NEAR(m.solid_angle(x, y) / expected, 1.0, 1e-12);
      ++inside;
    }
  EXPECT_GT(inside, 48000);
}

TEST(Mapping, MirrorBallDeadAngle) {
  Mapping m(MappingKind::MirrorBall, 200, 200, 10.0);
  double px, py;
  EXPECT_FALSE(m.to_pixel(normalize({0.05, 0, -1}), &px, &py));  // 2.9° from −Z
  EXPECT_TRUE(m.to_pixel(normalize({0.5, 0, -1}), &px, &py));    // 26.6° from −Z
  Vec3 d;
  EXPECT_TRUE(m.to_direction(100, 100, &d));
  EXPECT_NEAR(d.z, 1.0, 1e-3);                   // centre reflects +Z, back towards the camera
  EXPECT_FALSE(m.to_direction(199.9, 100, &d));  // rim: within the dead angle
}

TEST(Mapping, CubeFacesMatchConvention) {
  // shared/probes/README.md: +X (1,−t,−s), … texel (s,t) with s right, t down.
  Mapping m(MappingKind::CubeHCross, 400, 300);
  Vec3 d;
  ASSERT_TRUE(m.to_direction(250, 150, &d));  // centre of +X cell (2,1)
  EXPECT_NEAR(d.x, 1, 1e-12);
  ASSERT_TRUE(m.to_direction(150, 50, &d));  // +Y
  EXPECT_NEAR(d.y, 1, 1e-12);
  ASSERT_TRUE(m.to_direction(150, 150, &d));  // +Z
  EXPECT_NEAR(d.z, 1, 1e-12);
  ASSERT_TRUE(m.to_direction(350, 150, &d));  // −Z
  EXPECT_NEAR(d.z, -1, 1e-12);
  EXPECT_FALSE(m.to_direction(50, 50, &d));  // unused cell
  // Upper-left texel of +X looks to (1, +, +): s = −1 → z = +1, t = −1 → y = +1.
  ASSERT_TRUE(m.to_direction(200.01, 100.01, &d));
  EXPECT_GT(d.y, 0.5);
  EXPECT_GT(d.z, 0.5);
  // Neighbouring cells join seamlessly: the last column of +Z and the first of +X see the same edge.
  Vec3 a, b;
  m.to_direction(199.999, 130, &a);
  m.to_direction(200.001, 130, &b);
  EXPECT_LT(length(a - b), 1e-3);
  Mapping v(MappingKind::CubeVCross, 300, 400);
  v.to_direction(150, 299.999, &a);  // bottom edge of −Y
  v.to_direction(150, 300.001, &b);  // top edge of −Z (turned 180°)
  EXPECT_LT(length(a - b), 1e-3);
}

TEST(Mapping, DetectFromShapeAndName) {
  EXPECT_EQ(detect_mapping(1024, 512), MappingKind::LatLong);
  EXPECT_EQ(detect_mapping(512, 512), MappingKind::MirrorBall);
  EXPECT_EQ(detect_mapping(640, 640, "campus_angular.hdr"), MappingKind::Angular);
  EXPECT_EQ(detect_mapping(1024, 768), MappingKind::CubeHCross);
  EXPECT_EQ(detect_mapping(768, 1024), MappingKind::CubeVCross);
  EXPECT_EQ(detect_mapping(1536, 256), MappingKind::CubeStrip);
  EXPECT_THROW(detect_mapping(1000, 300), Error);
  EXPECT_THROW(Mapping(MappingKind::CubeHCross, 100, 100), Error);
}

}  // namespace
}  // namespace ibl::sphere
