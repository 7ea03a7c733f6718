// AdaptiveGrid: a linear field prunes to the top level and stays exact, refined regions equal the
// dense grid bit for bit, the tolerance bound holds at every fine point, .shtree round trips and
// hostile files give one-line errors naming the file and the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "iblkit/core/testing.h"
#include "iblkit/ilf/adaptive.h"

namespace ibl::ilf {
namespace {
namespace fs = std::filesystem;
using test_util::expect_error;

// A fine grid whose value (point, k, c) is f(point, k, c).
template <typename F>
SHGrid make_grid(const GridDesc& gd, int bands, F&& f) {
  SHGrid g(gd, bands);
  for (int z = 0; z < gd.nz; ++z)
    for (int y = 0; y < gd.ny; ++y)
      for (int x = 0; x < gd.nx; ++x)
        for (int k = 0; k < bands * bands; ++k)
          for (int c = 0; c < 3; ++c) g.at(x, y, z)[3 * k + c] = float(f(gd.point(x, y, z), k, c));
  return g;
}

// A smooth field with a sharp bump at (0.3, 0.2, 0.6): what the tree refines around.
SHGrid bump_grid() {
  GridDesc gd{33, 17, 25, {{0, 0, 0}, {1, 0.5, 1}}};
  return make_grid(gd, 2, [](Vec3 p, int k, int c) {
    Vec3 d = p - Vec3{0.3, 0.2, 0.6};
    return 1.0 + 0.2 * p.x - 0.1 * k + 0.05 * c + (k == 0 ? 4.0 : 1.0) * std::exp(-dot(d, d) / (2 * 0.04 * 0.04));
  });
}

double norm_diff(const float* a, const float* b, int n) {
  double e = 0;
  for (int q = 0; q < n; ++q) e += (double(a[q]) - b[q]) * (double(a[q]) - b[q]);
  return std::sqrt(e);
}

TEST(Adaptive, LinearFieldPrunesToTheTopLevelAndStaysExact) {
  // Non-powers of two per axis: the last cell of a coarse level is shorter than the others.
  GridDesc gd{17, 10, 13, {{-1, 0, 2}, {1, 0.5, 4}}};
  auto f = [](Vec3 p, int k, int c) { return 0.5 + 0.3 * p.x - 0.7 * p.y + 0.2 * p.z + 0.1 * k + 0.05 * c; };
  SHGrid fine = make_grid(gd, 2, f);
  AdaptiveGrid t = make_adaptive(fine, {.tolerance = 1e-5, .brick = 4});
  EXPECT_EQ(t.stored_points(), 8);  // the top level's one 2×2×2 brick
  for (int l = 0; l + 1 < t.levels(); ++l) EXPECT_TRUE(t.level(l).bricks.empty()) << "level " << l;
  EXPECT_EQ(t.level(t.levels() - 1).step, 16);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0, 1);
  for (int i = 0; i < 100; ++i) {
    Vec3 p{-1 + 2 * U(rng), 0.5 * U(rng), 2 + 2 * U(rng)};
    auto c = t.coeffs_at(p);
    EXPECT_EQ(t.level_at(p), t.levels() - 1);
    for (int k = 0; k < 4; ++k)
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(c.c[size_t(k)][ch], f(p, k, ch), 2e-6);  // float corner values ≈ 1
  }
}

TEST(Adaptive, RefinedEverywhereItEqualsTheDenseGridBitForBit) {
  GridDesc gd{11, 9, 14, {{0, 0, 0}, {2, 1, 1.5}}};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  SHGrid fine = make_grid(gd, 3, [&](Vec3, int, int) { return U(rng); });  // noise: no coarse level fits
  AdaptiveGrid t = make_adaptive(fine, {.tolerance = 0, .brick = 4});
  for (int z = 0; z < gd.nz; ++z)
    for (int y = 0; y < gd.ny; ++y)
      for (int x = 0; x < gd.nx; ++x) EXPECT_EQ(t.level_at(gd.point(x, y, z)), 0);
  // Level 0 covers everything: the levels between it and the top brick hold nothing.
  for (int l = 1; l + 1 < t.levels(); ++l) EXPECT_TRUE(t.level(l).bricks.empty()) << "level " << l;
  EXPECT_EQ(t.level(t.levels() - 1).bricks.size(), 1u);
  for (int i = 0; i < 300; ++i) {
    Vec3 p{1 + 1.2 * U(rng), 0.5 + 0.6 * U(rng), 0.75 + 0.9 * U(rng)};  // some outside: both clamp
    auto a = t.coeffs_at(p), b = fine.coeffs_at(p);
    for (int k = 0; k < 9; ++k)
      for (int ch = 0; ch < 3; ++ch) ASSERT_EQ(a.c[size_t(k)][ch], b.c[size_t(k)][ch]) << "point " << i;
  }
  SHGrid back = t.to_dense();
  ASSERT_EQ(back.data().size(), fine.data().size());
  EXPECT_EQ(std::memcmp(back.data().data(), fine.data().data(), fine.data().size() * 4), 0);
}

TEST(Adaptive, ToleranceBoundHoldsEverywhereAndTheBumpIsRefined) {
  SHGrid fine = bump_grid();
  const auto& gd = fine.grid();
  const int KC = 12;
  double sum = 0;
  for (float v : fine.data()) sum += double(v) * v;
  const double rms = std::sqrt(sum / double(gd.count()));
  for (int brick : {2, 4, 8})
    for (double tol : {0.003, 0.01, 0.05}) {
      AdaptiveGrid t = make_adaptive(fine, {.tolerance = tol, .brick = brick});
      EXPECT_NEAR(t.rms(), rms, 1e-9 * rms);
      EXPECT_LT(t.stored_points(), gd.count()) << "brick " << brick << " tolerance " << tol;
      SHGrid d = t.to_dense();
      double worst = 0;
      for (int z = 0; z < gd.nz; ++z)
        for (int y = 0; y < gd.ny; ++y)
          for (int x = 0; x < gd.nx; ++x) {
            worst = std::max(worst, norm_diff(d.at(x, y, z), fine.at(x, y, z), KC));
            // Through world coordinates the same within rounding (the point's index may be off by 1 ulp).
            auto c = t.coeffs_at(gd.point(x, y, z));
            double e = 0;
            for (int k = 0; k < 4; ++k)
              for (int ch = 0; ch < 3; ++ch) e += std::pow(c.c[size_t(k)][ch] - fine.at(x, y, z)[3 * k + ch], 2);
            EXPECT_LE(std::sqrt(e), tol * rms * (1 + 1e-6) + 1e-5);
          }
      EXPECT_LE(worst, tol * rms * (1 + 1e-6) + 1e-6) << "brick " << brick << " tolerance " << tol;
      // Between the fine points too: within the bound of the fine grid's trilinear lookup.
      std::mt19937 rng(11);
      std::uniform_real_distribution<double> U(0, 1);
      for (int i = 0; i < 2000; ++i) {
        Vec3 p{U(rng), 0.5 * U(rng), U(rng)};
        auto a = t.coeffs_at(p), b = fine.coeffs_at(p);
        double e = 0;
        for (int k = 0; k < 4; ++k)
          for (int ch = 0; ch < 3; ++ch) e += std::pow(a.c[size_t(k)][ch] - b.c[size_t(k)][ch], 2);
        ASSERT_LE(std::sqrt(e), tol * rms * (1 + 1e-6) + 1e-6)
            << "brick " << brick << " tolerance " << tol << " point " << i;
      }
      // The bump's centre is answered at full resolution, a far corner of the smooth part is not.
      EXPECT_EQ(t.level_at({0.3, 0.2, 0.6}), 0) << "brick " << brick << " tolerance " << tol;
      EXPECT_GT(t.level_at({0.95, 0.45, 0.05}), 0) << "brick " << brick << " tolerance " << tol;
    }
}

TEST(Adaptive, FileRoundTripKeepsEveryBrickAndTheFileSizeIsAsReported) {
  SHGrid fine = bump_grid();
  AdaptiveGrid t = make_adaptive(fine, {.tolerance = 0.01, .brick = 4});
  const std::string path = (fs::temp_directory_path() / "iblkit_adaptive_roundtrip.shtree").string();
  write_adaptive(path, t);
  EXPECT_EQ(fs::file_size(path), t.file_bytes());
  EXPECT_TRUE(is_adaptive_file(path));
  AdaptiveGrid r = read_adaptive(path);
  ASSERT_EQ(r.levels(), t.levels());
  EXPECT_EQ(r.brick(), 4);
  EXPECT_EQ(r.bands(), 2);
  EXPECT_EQ(r.tolerance(), 0.01);
  EXPECT_EQ(r.rms(), t.rms());
  for (int l = 0; l < t.levels(); ++l) EXPECT_EQ(r.level(l).bricks.size(), t.level(l).bricks.size()) << "level " << l;
  ASSERT_EQ(r.data().size(), t.data().size());
  EXPECT_EQ(std::memcmp(r.data().data(), t.data().data(), t.data().size() * 4), 0);
  SHGrid a = r.to_dense(), b = read_dense(path);
  EXPECT_EQ(a.data(), b.data());
  EXPECT_EQ(a.data(), t.to_dense().data());
  // A dense file read through read_dense is what read_shgrid reads.
  const std::string dense = (fs::temp_directory_path() / "iblkit_adaptive_roundtrip.shgrid").string();
  write_shgrid(dense, fine);
  EXPECT_FALSE(is_adaptive_file(dense));
  EXPECT_EQ(read_dense(dense).data(), fine.data());
  fs::remove(path);
  fs::remove(dense);
}

// The file's bytes, and the same with line 2 replaced by `header` (padded to the old length).
std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void spit(const std::string& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }
std::string with_header(const std::string& bytes, const std::string& header) {
  size_t l1 = bytes.find('\n'), l2 = bytes.find('\n', l1 + 1);
  std::string h = header;
  h.resize(l2 - l1 - 1, ' ');
  return bytes.substr(0, l1 + 1) + h + bytes.substr(l2);
}
std::string header_of(const std::string& bytes) {
  size_t l1 = bytes.find('\n'), l2 = bytes.find('\n', l1 + 1);
  std::string h = bytes.substr(l1 + 1, l2 - l1 - 1);
  return h.substr(0, h.find_last_not_of(' ') + 1);
}
std::string replace(std::string s, const std::string& from, const std::string& to) {
  size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? s : s.replace(at, from.size(), to);
}

TEST(Adaptive, HostileFilesGiveOneLineErrorsNamingTheFileAndField) {
  AdaptiveGrid t = make_adaptive(bump_grid(), {.tolerance = 0.01, .brick = 4});
  const std::string good = (fs::temp_directory_path() / "iblkit_adaptive_good.shtree").string();
  const std::string bad = (fs::temp_directory_path() / "iblkit_adaptive_bad.shtree").string();
  write_adaptive(good, t);
  const std::string bytes = slurp(good), hdr = header_of(bytes);
  const size_t data_at = bytes.find('\n', bytes.find('\n') + 1) + 1;
  ASSERT_EQ(data_at % 64, 0u);
  auto expect = [&](const std::string& content, std::initializer_list<std::string> frags) {
    spit(bad, content);
    expect_error([&] { read_adaptive(bad); }, frags);
  };
  expect(bytes.substr(0, bytes.size() - 100), {bad, "truncated"});
  expect(bytes.substr(0, data_at + 8), {bad, "truncated"});
  expect("IBLKIT-SHGRID 1\n" + bytes.substr(bytes.find('\n') + 1), {bad, "not an .shtree"});
  expect(with_header(bytes, "{not json"), {bad, "does not parse"});
  expect(with_header(bytes, replace(hdr, "\"dtype\":\"float32\"", "\"dtype\":\"float64\"")), {bad, "\"dtype\""});
  // Counts that lie: more level-0 bricks than the file holds; a top level without its brick.
  const auto& L0 = t.level(0);
  std::string counts = "\"bricks\":[" + std::to_string(L0.bricks.size());
  expect(with_header(bytes, replace(hdr, counts, "\"bricks\":[" + std::to_string(L0.map.size()))),
         {bad, "level 0"});  // truncated, or values read as coordinates
  expect(with_header(bytes, replace(hdr, counts, "\"bricks\":[" + std::to_string(L0.map.size() + 1))),
         {bad, "\"bricks\"", "level 0"});
  expect(with_header(bytes, replace(hdr, counts, "\"bricks\":[-1")), {bad, "\"bricks\""});
  expect(with_header(bytes, replace(hdr, "\"levels\":" + std::to_string(t.levels()), "\"levels\":2")),
         {bad, "\"levels\" = 2"});
  expect(with_header(bytes, replace(hdr, "\"resolution\":[33,17,25]", "\"resolution\":[65536,65536,65536]")),
         {bad, "\"resolution\"", "implausibly large"});
  expect(with_header(bytes, replace(hdr, "\"resolution\":[33,17,25]", "\"resolution\":[1,17,25]")),
         {bad, "\"resolution\""});
  expect(with_header(bytes, replace(hdr, "\"brick\":4", "\"brick\":99")), {bad, "\"brick\" = 99"});
  expect(with_header(bytes, replace(hdr, "\"bands\":2", "\"bands\":0")), {bad, "\"bands\" = 0"});
  expect(with_header(bytes, replace(hdr, "\"min\":[0.0,0.0,0.0]", "\"min\":[-1e308,0.0,0.0]")),
         {bad, "\"min\", \"max\""});
  expect(with_header(bytes, replace(hdr, "\"min\":[0.0,0.0,0.0]", "\"min\":[5.0,0.0,0.0]")),
         {bad, "max must exceed min"});
  expect(with_header(bytes, replace(hdr, "\"tolerance\":0.01", "\"tolerance\":-1")), {bad, "\"tolerance\""});
  // Numbers that are not integers, or too large for one, are refused before any conversion (fuzz_shtree
  // found "bricks" holding 8.9e61, which reached a float-to-integer cast: undefined behaviour).
  expect(with_header(bytes, replace(hdr, counts, "\"bricks\":[8.9e61")), {bad, "\"bricks\"", "not a whole number"});
  expect(with_header(bytes, replace(hdr, "\"bands\":2", "\"bands\":1e30")), {bad, "\"bands\"", "not a whole number"});
  expect(with_header(bytes, replace(hdr, "\"brick\":4", "\"brick\":4.5")), {bad, "\"brick\"", "not a whole number"});
  expect(with_header(bytes, replace(hdr, "\"resolution\":[33,17,25]", "\"resolution\":[33,1e40,25]")),
         {bad, "\"resolution\"", "not a whole number"});
  // The top level's brick at coordinates outside its one-brick grid.
  std::string moved = bytes;
  int32_t five = 5;
  std::memcpy(&moved[data_at], &five, 4);
  expect(moved, {bad, "level " + std::to_string(t.levels() - 1), "outside"});
  // A NaN among the values (the last float of the file).
  std::string nan = bytes;
  float q = std::nanf("");
  std::memcpy(&nan[nan.size() - 4], &q, 4);
  expect(nan, {bad, "not finite"});
  // Two level-0 entries naming the same brick.
  ASSERT_GE(L0.bricks.size(), 2u);
  size_t table0 = bytes.size() - L0.bricks.size() * 12 - size_t(t.data().size() - L0.bricks[0].offset) * 4;
  std::string dup = bytes;
  std::memcpy(&dup[table0 + 12], &dup[table0], 12);
  expect(dup, {bad, "level 0", "listed twice"});
  fs::remove(good);
  fs::remove(bad);
}

TEST(Adaptive, ArgumentsAreChecked) {
  SHGrid fine = bump_grid();
  expect_error([&] { make_adaptive(fine, {.tolerance = -1}); }, "tolerance");
  expect_error([&] { make_adaptive(fine, {.tolerance = std::nan("")}); }, "tolerance");
  expect_error([&] { make_adaptive(fine, {.tolerance = 0.1, .brick = 1}); }, "brick 1");
  SHGrid err = fine;
  err.set_content("cv-error");
  expect_error([&] { make_adaptive(err, {}); }, "cv-error");
  AdaptiveGrid t = make_adaptive(fine, {});
  expect_error([&] { t.coeffs_at({NAN, 0, 0}); }, "not finite");
  expect_error(
      [&] {
        t.add_brick(0, 0, 0, 0);
        t.add_brick(0, 0, 0, 0);
      },
      "given twice");
  AdaptiveGrid empty(fine.grid(), 2, 4);  // levels but no bricks: a lookup has nothing to answer from
  expect_error([&] { empty.coeffs_at({0.5, 0.25, 0.5}); }, "top level has no brick");
  expect_error([&] { AdaptiveGrid(GridDesc{4, 4, 4, {{0, 0, 0}, {1, 0, 1}}}, 2, 4); }, "max must exceed min");
  expect_error([&] { AdaptiveGrid(fine.grid(), 0, 4); }, "bands = 0");
}

}  // namespace
}  // namespace ibl::ilf
