// engine/: KTX2 container bytes, GGX prefilter against brute force, DFG limits, irradiance cube.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "iblkit/core/testing.h"
#include "iblkit/engine/cube_chain.h"
#include "iblkit/engine/dfg.h"
#include "iblkit/engine/diffuse.h"
#include "iblkit/engine/export.h"
#include "iblkit/engine/ggx.h"
#include "iblkit/engine/ktx2.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/sh/convolve.h"
#include "iblkit/sh/export.h"
#include "iblkit/sh/project.h"

namespace ibl::engine {
namespace {

namespace fs = std::filesystem;

const char* kForest = "/usr/share/blender/datafiles/studiolights/world/forest.exr";

uint32_t u32(const std::string& s, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(static_cast<unsigned char>(s[at + i])) << (8 * i);
  return v;
}

// A smooth analytic probe (lat-long 256×128): sky gradient plus a soft warm lobe, no texture.
sphere::EnvMap smooth_probe() {
  sphere::Mapping m(sphere::MappingKind::LatLong, 256, 128);
  Image im(256, 128, 3);
  const Vec3 sun = normalize(Vec3{0.5, 0.6, -0.62});
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 256; ++x) {
      Vec3 d;
      m.to_direction(x + 0.5, y + 0.5, &d);
      const double lobe = std::exp((dot(d, sun) - 1) / 0.08);
      im.set_rgb(x, y, Vec3{0.3 + 0.2 * d.y, 0.4 + 0.25 * d.y, 0.6 + 0.3 * d.x} + Vec3{8, 6, 3} * lobe);
    }
  return sphere::EnvMap(std::move(im), m);
}

// cube_texel_direction is sphere/'s cubestrip mapping at texel centres, and the chain keeps ∫L dω.
TEST(CubeChain, TexelDirectionsAndPower) {
  sphere::Mapping m(sphere::MappingKind::CubeStrip, 6 * 8, 8);
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < 8; y += 3)
      for (int x = 0; x < 8; x += 2) {
        Vec3 d;
        ASSERT_TRUE(m.to_direction(f * 8 + x + 0.5, y + 0.5, &d));
        const Vec3 e = cube_texel_direction(f, x, y, 8);
        EXPECT_NEAR(dot(d, e), 1.0, 1e-12) << f << " " << x << " " << y;
      }
  const sphere::EnvMap env = smooth_probe();
  CubeChain c = build_cube_chain(env, 32);
  ASSERT_EQ(c.count(), 6);
  const double want = env.integral()[1];
  for (int l = 0; l < c.count(); ++l) {
    const int n = c.size(l);
    const std::vector<double> om = cube_face_solid_angles(n);
    double sum = 0;
    for (int f = 0; f < 6; ++f)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) sum += c.levels[l].at(f * n + x, y, 1) * om[static_cast<size_t>(y) * n + x];
    EXPECT_NEAR(sum / want, 1.0, 5e-3) << "level " << l;  // sphere::resample keeps ∫L dω within 0.5 %
  }
}

TEST(Ktx2, HalfConversionIsIeeeBinary16) {
  EXPECT_EQ(to_half(1.0f), 0x3C00);
  EXPECT_EQ(to_half(-2.0f), 0xC000);
  EXPECT_EQ(to_half(65504.0f), 0x7BFF);
  EXPECT_EQ(to_half(0.0f), 0x0000);
  EXPECT_EQ(to_half(1.0f + 1.0f / 2048), 0x3C00);  // a tie rounds to even
  EXPECT_EQ(from_half(0x3555), 0.333251953125f);
  EXPECT_EQ(from_half(0x0001), std::ldexp(1.0f, -24));  // smallest subnormal
}

// The header, index, DFD and level layout of [1] §3, byte by byte, for a 3-level cube map.
TEST(Ktx2, CubeMapBytesFollowTheSpecification) {
  Ktx2Texture t;
  t.faces = 6;
  for (int m = 0; m < 3; ++m) {
    std::vector<Image> faces;
    for (int f = 0; f < 6; ++f) faces.emplace_back(4 >> m, 4 >> m, 3, float(10 * m + f));
    t.levels.push_back(faces);
  }
  const std::string s = ktx2_bytes(t);
  EXPECT_EQ(s.substr(0, 12), std::string("\xABKTX 20\xBB\r\n\x1A\n", 12));
  EXPECT_EQ(u32(s, 12), 97u);  // VK_FORMAT_R16G16B16A16_SFLOAT
  EXPECT_EQ(u32(s, 16), 2u);   // typeSize
  EXPECT_EQ(u32(s, 20), 4u);
  EXPECT_EQ(u32(s, 24), 4u);
  EXPECT_EQ(u32(s, 28), 0u);  // pixelDepth
  EXPECT_EQ(u32(s, 32), 0u);  // layerCount
  EXPECT_EQ(u32(s, 36), 6u);  // faceCount
  EXPECT_EQ(u32(s, 40), 3u);  // levelCount
  EXPECT_EQ(u32(s, 44), 0u);  // no supercompression
  const uint32_t dfd_at = u32(s, 48), dfd_len = u32(s, 52);
  EXPECT_EQ(dfd_at, 80u + 3 * 24);  // right after the level index
  EXPECT_EQ(dfd_len, 92u);          // 4 + 24 + 4 samples × 16
  EXPECT_EQ(u32(s, dfd_at), 92u);
  EXPECT_EQ(u32(s, dfd_at + 8) >> 16, 88u);              // descriptorBlockSize
  EXPECT_EQ(u32(s, dfd_at + 12) & 0xFFFFFF, 0x010101u);  // RGBSDA, BT709, linear
  EXPECT_EQ(u32(s, dfd_at + 20), 8u);                    // bytesPlane0
  EXPECT_EQ(u32(s, dfd_at + 28 + 3 * 16) >> 24, 0xCFu);  // alpha: channel 15, signed float
  // Levels: the smallest first, each at a multiple of 8, lengths 6·S²·8 bytes.
  uint64_t prev_end = 0, off[3];
  for (int m = 2; m >= 0; --m) {
    off[m] = u32(s, 80 + 24 * m);
    const uint32_t len = u32(s, 80 + 24 * m + 8), side = 4u >> m;
    EXPECT_EQ(len, 6 * side * side * 8);
    EXPECT_EQ(u32(s, 80 + 24 * m + 16), len);
    EXPECT_EQ(off[m] % 8, 0u);
    EXPECT_GE(off[m], prev_end);
    prev_end = off[m] + len;
  }
  EXPECT_EQ(prev_end, s.size());
  // Face 3 (−Y) of level 1 starts 3 faces into the level: its first value is 10 + 3 = 13.
  const size_t at = off[1] + 3 * 2 * 2 * 8;
  EXPECT_EQ(from_half(uint16_t(static_cast<unsigned char>(s[at]) | (static_cast<unsigned char>(s[at + 1]) << 8))),
            13.0f);
  EXPECT_NE(s.find("KTXwriter"), std::string::npos);
  EXPECT_EQ(s.find("KTXorientation"), std::string::npos);  // cube faces have their fixed orientation
}

TEST(Ktx2, RoundTripAndBadChains) {
  Ktx2Texture t;
  t.vk_format = kVkFormatRg16f;
  Image im(8, 4, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) im.set_rgb(x, y, {x * 0.125, y * 0.25, 7});
  t.levels.push_back({im});
  const std::string path = (fs::temp_directory_path() / "iblkit_ktx2_test.ktx2").string();
  write_ktx2(path, t);
  Ktx2Texture back = read_ktx2(path);
  ASSERT_EQ(back.levels.size(), 1u);
  ASSERT_EQ(back.levels[0][0].channels(), 2);
  EXPECT_EQ(back.levels[0][0].at(5, 3, 0), 0.625f);  // exact in binary16
  EXPECT_EQ(back.levels[0][0].at(5, 3, 1), 0.75f);
  std::remove(path.c_str());
  Ktx2Texture bad;
  bad.faces = 6;
  bad.levels.push_back(std::vector<Image>(6, Image(4, 2, 3)));
  test_util::expect_error([&] { ktx2_bytes(bad); }, "square");
  bad.levels[0] = std::vector<Image>(6, Image(4, 4, 3));
  bad.levels.push_back(std::vector<Image>(6, Image(4, 4, 3)));
  test_util::expect_error([&] { ktx2_bytes(bad); }, "level 1 is 4×4 (expected 2×2)");
  test_util::expect_error([] { read_ktx2("/nonexistent.ktx2"); }, "no such file");
}

// A white furnace stays white at every roughness, by both methods: (1) is normalised.
TEST(Specular, ConstantEnvironmentStaysConstant) {
  sphere::EnvMap env(Image(64, 32, 3, 2.5f), sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  for (double budget : {1.5e8, 0.0}) {
    SpecularDesc d;
    d.size = 32;
    d.levels = 4;
    d.exact_budget = budget;
    SpecularCube c = prefilter_ggx(env, d);
    for (int m = 0; m < 4; ++m)
      for (Vec3 r : {Vec3{1, 0, 0}, Vec3{0.3, -0.9, 0.2}, Vec3{0, 0, -1}})
        for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(c.cube.sample(r, m)[ch], 2.5, 2.5 * 2e-3) << m;
  }
}

// Prefiltered texels against (1) summed over the probe's own pixels (ggx_reference), for both the
// exact convolution and filtered importance sampling, at several texels of every level.
// Tolerances, relative to the reference's luminance, measured (docs/engines.md has the table):
constexpr double kExactTol = 0.02;  // exact convolution: source texels and float sums; max seen 0.6 %
constexpr double kFisTol = 0.05;    // FIS, 1024 samples: lod filtering bias; max seen 2.6 %
TEST(Specular, MatchesBruteForceConvolution) {
  const sphere::EnvMap env = smooth_probe();
  const Vec3 dirs[] = {{0.5, 0.6, -0.62}, {1, 0, 0}, {-0.3, 0.2, 0.93}, {0, -1, 0}, {0.7, 0.7, 0.1}};
  for (double budget : {1.5e8, 0.0}) {
    SpecularDesc d;
    d.size = 64;
    d.levels = 4;
    d.exact_budget = budget;
    SpecularCube c = prefilter_ggx(env, d);
    for (int m = 1; m < 4; ++m) {
      const auto& lv = c.info[static_cast<size_t>(m)];
      if (budget == 0) {
        EXPECT_EQ(lv.method, LevelMethod::Importance);
      }
      const int s = c.cube.size(m);
      for (Vec3 dir : dirs) {
        double ts, tt;
        const int f = sphere::cube_face_of(dir, &ts, &tt);
        const int x = std::min(s - 1, int((ts + 1) / 2 * s)), y = std::min(s - 1, int((tt + 1) / 2 * s));
        const Vec3 r = cube_texel_direction(f, x, y, s);
        const Vec3 ref = ggx_reference(env, r, lv.alpha);
        const Vec3 got = c.cube.levels[static_cast<size_t>(m)].rgb(f * s + x, y);
        const double err = std::abs(luminance(got) - luminance(ref)) / luminance(ref);
        std::printf("GGX level %d α %.4f %-10s r (%+.2f %+.2f %+.2f): rel. error %.4f\n", m, lv.alpha,
                    level_method_name(lv.method).c_str(), r.x, r.y, r.z, err);
        EXPECT_LT(err, lv.method == LevelMethod::Exact ? kExactTol : kFisTol)
            << "level " << m << " α " << lv.alpha << " r " << r.x << "," << r.y << "," << r.z;
      }
    }
  }
}

TEST(Specular, LevelsAndOptions) {
  SpecularDesc d;
  EXPECT_EQ(specular_level_count(d), 5);  // 256 → 16
  d.size = 100;
  test_util::expect_error([&] { specular_level_count(d); }, "power of two");
  d.size = 64;
  d.levels = 8;
  test_util::expect_error([&] { specular_level_count(d); }, "outside 1..7");
  EXPECT_DOUBLE_EQ(level_roughness(2, 5, LodMapping::Linear), 0.5);
  // Filament: lod/(N−1) = ρ(2 − ρ) (cmgen prints ρ = 0.134, 0.293, 0.5 for 5 levels).
  for (int m = 0; m < 5; ++m) {
    const double r = level_roughness(m, 5, LodMapping::Filament);
    EXPECT_NEAR(r * (2 - r), m / 4.0, 1e-12);
  }
  EXPECT_NEAR(level_roughness(1, 5, LodMapping::Filament), 0.134, 5e-4);
  test_util::expect_error([] { parse_lod_mapping("cubic"); }, "linear");
}

// ρ → 0 is a mirror: scale = 1 − (1 − μ)⁵, bias = (1 − μ)⁵ (G₂ → 1, D → δ). Everywhere else the
// sum is an albedo ≤ 1, falling with roughness at normal incidence.
constexpr double kDfgLimitTol = 2e-3;  // ρ = 0.02 is not quite 0
constexpr double kDfgQuadTol = 2e-3;   // n = 128 against n = 1024
TEST(Dfg, ClosedFormLimitsAndConvergence) {
  for (double mu : {0.05, 0.3, 0.7, 1.0}) {
    const Vec2 sb = dfg(mu, 0.02);
    EXPECT_NEAR(sb.x, 1 - std::pow(1 - mu, 5), kDfgLimitTol) << mu;
    EXPECT_NEAR(sb.y, std::pow(1 - mu, 5), kDfgLimitTol) << mu;
  }
  double prev = 2;
  for (double rho : {0.1, 0.3, 0.5, 0.7, 0.9, 1.0}) {
    for (double mu : {0.1, 0.5, 0.9}) {
      const Vec2 a = dfg(mu, rho), b = dfg(mu, rho, 1024);
      EXPECT_NEAR(a.x, b.x, kDfgQuadTol) << mu << " " << rho;
      EXPECT_NEAR(a.y, b.y, kDfgQuadTol) << mu << " " << rho;
      EXPECT_LE(b.x + b.y, 1.0 + 1e-9);
      EXPECT_GE(b.y, 0.0);
    }
    const Vec2 n = dfg(1.0, rho);
    EXPECT_LT(n.x + n.y, prev);
    prev = n.x + n.y;
  }
  Image t = dfg_table({16, 32});
  EXPECT_NEAR(t.at(15, 0, 0), 1 - std::pow(1 - 31.0 / 32, 5), 0.01);  // top row: ρ = 1/32
}

// E/π of a constant environment is that constant; of a real probe it matches the SH irradiance
// (9 bands: the cosine kernel's Â_l beyond l = 8 is < 0.2 % of Â_0).
constexpr double kIrradianceTol =
    0.015;  // of the mean: SH truncation at 9 bands plus the 32² source cube (measured 1.2 %)
TEST(Diffuse, IrradianceCubeMatchesShIrradiance) {
  sphere::EnvMap flat(Image(64, 32, 3, 1.5f), sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  Image f = irradiance_cube(flat, 8);
  EXPECT_NEAR(f.at(3, 4, 1), 1.5, 1.5e-4);
  if (!fs::exists(kForest)) GTEST_SKIP() << "blender-data probes absent";
  sphere::EnvMap env = io::read_envmap(kForest);
  Image irr = irradiance_cube(env, 16);
  sh::Coeffs c = sh::project(env, 9);
  double worst = 0, mean = luminance(c.c[0]) / std::sqrt(kFourPi);  // mean radiance = E/π of the mean
  for (int face = 0; face < 6; ++face)
    for (int y = 1; y < 16; y += 5)
      for (int x = 2; x < 16; x += 6) {
        const Vec3 n = cube_texel_direction(face, x, y, 16);
        const double e = luminance(sh::irradiance_at(c, n)) / kPi, got = luminance(irr.rgb(face * 16 + x, y));
        worst = std::max(worst, std::abs(got - e) / mean);
      }
  std::printf("irradiance cube vs 9-band SH, forest: max |Δ| / mean = %.4f\n", worst);
  EXPECT_LT(worst, kIrradianceTol);
}

// The Filament frame turns iblkit's +X to +Z and +Z to −X (sh::filament_from_iblkit).
TEST(Frames, FilamentFrame) {
  const Mat3 m = frame_rotation(EngineFrame::Filament);
  const Vec3 x = m * Vec3{1, 0, 0}, z = m * Vec3{0, 0, 1}, y = m * Vec3{0, 1, 0};
  EXPECT_DOUBLE_EQ(x.z, 1);
  EXPECT_DOUBLE_EQ(z.x, -1);
  EXPECT_DOUBLE_EQ(y.y, 1);
  EXPECT_EQ(parse_engine_frame("threejs"), EngineFrame::Iblkit);
}

}  // namespace
}  // namespace ibl::engine
