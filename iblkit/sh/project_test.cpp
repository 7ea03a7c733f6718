#include "iblkit/sh/project.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sh/convolve.h"
#include "iblkit/sh/rotate.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::sh {
namespace {

using sphere::EnvMap;
using sphere::Mapping;
using sphere::MappingKind;

const char* kProbeDir = "/usr/share/blender/datafiles/studiolights/world/";

std::vector<Mapping> every_mapping(int s) {
  return {Mapping(MappingKind::LatLong, 2 * s, s),
          Mapping(MappingKind::MirrorBall, s, s),
          Mapping(MappingKind::Angular, s, s),
          Mapping(MappingKind::CubeHCross, 4 * s / 4, 3 * s / 4),
          Mapping(MappingKind::CubeVCross, 3 * s / 4, 4 * s / 4),
          Mapping(MappingKind::CubeStrip, 6 * s / 4, s / 4),
          Mapping(MappingKind::Octahedral, s, s)};
}

// Unit radiance everywhere: c00 = √(4π) (the solid angles are exact), every other coefficient 0,
// irradiance π in every direction.
TEST(ShProject, WhiteFurnaceEveryMapping) {
  constexpr double kLatLongTol = 1e-9;        // separable path: exact pixel integrals, rounding only
  constexpr double kLatLongHigherTol = 1e-7;  // … of the float cos/sin column tables (2⁻²⁴ each)
  constexpr double kC00Tol = 3e-5;            // mirror ball: disc-edge slivers no 8×8 sub-point lands in
  constexpr double kHigherTol = 1e-3;         // l ≤ 4 by sub-pixel quadrature on 32-px cube faces / 128-px discs
  constexpr double kIrradianceTol = 1e-4;     // the figure
  for (const Mapping& m : every_mapping(128)) {
    EnvMap env(Image(m.width(), m.height(), 3, 1.0f), m);
    // Pixels without data must not count: zero them so a wrong weight would show.
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x)
        if (m.solid_angle(x, y) == 0) env.image.set_rgb(x, y, {0, 0, 0});
    Coeffs c = project(env, 5);
    std::string name = sphere::mapping_name(m.kind());
    bool ll = m.kind() == MappingKind::LatLong;
    EXPECT_NEAR(c.c[0].x, std::sqrt(kFourPi), ll ? kLatLongTol : kC00Tol) << name;
    for (int k = 1; k < 25; ++k) EXPECT_NEAR(c.c[k].y, 0.0, ll ? kLatLongHigherTol : kHigherTol) << name << " k=" << k;
    for (Vec3 n : {Vec3{0, 1, 0}, Vec3{0, -1, 0}, normalize(Vec3{1, 0.3, -0.2})})
      EXPECT_NEAR(irradiance_at(c, n).z, kPi, kIrradianceTol) << name;
  }
}

// A single basis function rendered into every mapping projects back onto itself.
TEST(ShProject, RecoversABasisFunctionInEveryMapping) {
  constexpr double kSelfTol = 2e-3;   // pixel-centre quadrature error on 128-pixel maps (mirror ball rim worst)
  constexpr double kCrossTol = 2e-3;  // leakage into other coefficients, same cause
  const int bands = 5;
  for (int k : {index(1, 1), index(2, -1), index(3, 2), index(4, -3)}) {
    Coeffs one(bands);
    one.c[k] = {1, 1, 1};
    for (const Mapping& m : every_mapping(128)) {
      EnvMap env(reconstruct(one, m), m);
      Coeffs c = project(env, bands);
      std::string name = sphere::mapping_name(m.kind());
      for (int j = 0; j < coeff_count(bands); ++j)
        EXPECT_NEAR(c.c[j].x, j == k ? 1.0 : 0.0, j == k ? kSelfTol : kCrossTol) << name << " k=" << k << " j=" << j;
    }
  }
}

// The separable lat-long path agrees with the per-pixel path on a real probe, 9 bands.
TEST(ShProject, LatLongFastPathMatchesGeneric) {
  std::string path = std::string(kProbeDir) + "courtyard.exr";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "blender-data not installed";
  constexpr double kPathTol = 2e-4;  // relative to c00: pixel integral vs pixel centre, float row sums
  EnvMap env = io::read_envmap(path);
  Coeffs a = project(env, 9), b = project_generic(env, 9);
  double scale = a.c[0].y;
  for (int k = 0; k < 81; ++k)
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(a.c[k][ch] / scale, b.c[k][ch] / scale, kPathTol) << k;
}

// Rotating the coefficients equals projecting the rotated env map (resampled with the same R).
TEST(ShProject, RotationMatchesRotatedEnvMap) {
  std::string path = std::string(kProbeDir) + "interior.exr";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "blender-data not installed";
  constexpr double kResampleTol = 3e-3;  // relative to c00: bilinear resampling of a 1024×512 probe
  EnvMap env = io::read_envmap(path);
  Mat3 R = Mat3::rotation(normalize(Vec3{0.4, 1, -0.3}), 0.9);
  sphere::ResampleDesc rd;
  rd.rotation = R;
  Mapping m(MappingKind::LatLong, 512, 256);
  EnvMap turned(sphere::resample(env, m, rd), m);
  Coeffs a = rotate(project(env, 5), R), b = project(turned, 5);
  double scale = a.c[0].y;
  for (int k = 0; k < 25; ++k)
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(a.c[k][ch] / scale, b.c[k][ch] / scale, kResampleTol) << k;
}

// reconstruct ∘ project is the identity on band-limited functions; project_function is exact.
TEST(ShProject, ReconstructRoundTrip) {
  constexpr double kFunctionTol = 1e-12;  // exact quadrature
  constexpr double kRoundTripTol = 1e-4;  // 512×256 lat-long, piecewise-constant pixels
  Coeffs c(4);
  for (int k = 0; k < 16; ++k) c.c[k] = {std::cos(k), 0.5 * std::sin(2.0 * k), k == 0 ? 3.0 : 0.1};
  Coeffs f = project_function([&](Vec3 d) { return c.evaluate(d); }, 4);
  for (int k = 0; k < 16; ++k) EXPECT_NEAR(f.c[k].x, c.c[k].x, kFunctionTol);
  Mapping m(MappingKind::LatLong, 512, 256);
  Coeffs back = project(EnvMap(reconstruct(c, m), m), 4);
  for (int k = 0; k < 16; ++k) EXPECT_NEAR(back.c[k].y, c.c[k].y, kRoundTripTol) << k;
  EXPECT_THROW(project(EnvMap(reconstruct(c, m), m), 0), Error);
}

}  // namespace
}  // namespace ibl::sh
