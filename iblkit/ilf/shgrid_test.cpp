// SHGrid: trilinear lookup, the furnace responses, .shgrid round trips and header errors; the block
// matrix product against a naive sum.
#include <gtest/gtest.h>
#ifdef IBLKIT_HAVE_OPENVDB
#include <openvdb/openvdb.h>
#endif

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "iblkit/core/error.h"
#include "iblkit/ilf/build.h"
#include "iblkit/ilf/shgrid.h"

namespace ibl::ilf {
namespace {
namespace fs = std::filesystem;

GridDesc small_grid() { return {4, 3, 5, {{-1, 0, 2}, {1, 0.5, 4}}}; }

TEST(SHGrid, TrilinearIsExactOnLinearFields) {
  SHGrid g(small_grid(), 2);
  auto f = [](Vec3 p, int k, int c) { return 0.5 + 0.3 * p.x - 0.7 * p.y + 0.2 * p.z + 0.1 * k + 0.05 * c; };
  for (int z = 0; z < 5; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x)
        for (int k = 0; k < 4; ++k)
          for (int c = 0; c < 3; ++c) g.at(x, y, z)[3 * k + c] = float(f(g.grid().point(x, y, z), k, c));
  constexpr double kFloatTol = 1e-5;  // float storage of values ≈ 1
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0, 1);
  for (int t = 0; t < 50; ++t) {
    Vec3 p{-1 + 2 * U(rng), 0.5 * U(rng), 2 + 2 * U(rng)};
    auto c = g.coeffs_at(p);
    for (int k = 0; k < 4; ++k)
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(c.c[k][ch], f(p, k, ch), kFloatTol);
  }
  // Outside the volume: clamped to the boundary.
  auto c = g.coeffs_at({5, 0.25, 3});
  EXPECT_NEAR(c.c[0][0], f({1, 0.25, 3}, 0, 0), kFloatTol);
}

// White furnace: L = 1 everywhere is c00 = √(4π); irradiance π, radiance 1, normalised Phong lobe 1.
TEST(SHGrid, FurnaceResponses) {
  SHGrid g(small_grid(), 5);
  for (int64_t i = 0; i < g.grid().count(); ++i)
    for (int c = 0; c < 3; ++c) g.data()[size_t(i) * 25 * 3 + c] = float(std::sqrt(4 * kPi));
  constexpr double kTol = 1e-5;  // float coefficients
  Vec3 p{0.1, 0.2, 3.0};
  EXPECT_NEAR(g.irradiance(p, {0, 1, 0}).x, kPi, kTol * kPi);
  EXPECT_NEAR(g.radiance(p, {0.3, -0.4, 0.5}).y, 1.0, kTol);
  EXPECT_NEAR(g.glossy(p, {0, 0, 1}, 6.0).z, 1.0, kTol);
  EXPECT_THROW(g.glossy(p, {0, 0, 1}, -1.0), Error);
}

// A single directional-ish lobe: radiance c·Y_10 (∝ z) has irradiance (2π/3)·c·Y_10(n) (Â_1 = 2π/3).
TEST(SHGrid, IrradianceOfLinearLobe) {
  SHGrid g(small_grid(), 3);
  for (int64_t i = 0; i < g.grid().count(); ++i) g.data()[size_t(i) * 9 * 3 + 3 * 2] = 1.0f;  // k = index(1,0)
  constexpr double kTol = 1e-5;
  double y10 = std::sqrt(3 / (4 * kPi));
  EXPECT_NEAR(g.irradiance({0, 0.2, 3}, {0, 0, 1}).x, 2 * kPi / 3 * y10, kTol);
  EXPECT_NEAR(g.irradiance({0, 0.2, 3}, {0, 0, -1}).x, -2 * kPi / 3 * y10, kTol);
}

TEST(SHGrid, FileRoundTripAndLayout) {
  SHGrid g(small_grid(), 3);
  for (size_t i = 0; i < g.data().size(); ++i) g.data()[i] = float(i) * 0.25f - 7.0f;
  auto path = (fs::temp_directory_path() / fmt::format("iblkit_shgrid_{}.shgrid", ::getpid())).string();
  write_shgrid(path, g);
  std::ifstream in(path, std::ios::binary);
  std::string l1, l2;
  std::getline(in, l1);
  std::getline(in, l2);
  EXPECT_EQ(l1, "IBLKIT-SHGRID 1");
  size_t off = l1.size() + 1 + l2.size() + 1;
  EXPECT_EQ(off % 64, 0u);
  EXPECT_EQ(fs::file_size(path), off + g.data().size() * 4);
  // Value at (x=2, y=1, z=3), coefficient 4, channel 1 sits at (((z·ny + y)·nx + x)·K + k)·3 + c.
  size_t idx = ((size_t(3 * 3 + 1) * 4 + 2) * 9 + 4) * 3 + 1;
  in.seekg(std::streamoff(off + idx * 4));
  float v;
  in.read(reinterpret_cast<char*>(&v), 4);
  EXPECT_EQ(v, g.at(2, 1, 3)[4 * 3 + 1]);
  SHGrid r = read_shgrid(path);
  EXPECT_EQ(r.bands(), 3);
  EXPECT_EQ(r.grid().nx, 4);
  EXPECT_EQ(r.grid().nz, 5);
  EXPECT_EQ(r.grid().volume.max.z, 4.0);
  EXPECT_EQ(r.data(), g.data());
  // Truncated and wrong-magic files are clear errors.
  fs::resize_file(path, fs::file_size(path) - 8);
  try {
    read_shgrid(path);
    FAIL() << "no error for a truncated file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  {
    std::ofstream o(path);
    o << "P6\n";
  }
  EXPECT_THROW(read_shgrid(path), Error);
  fs::remove(path);
}

TEST(SHGrid, VdbExportOrClearError) {
  SHGrid g(small_grid(), 2);
  auto path = (fs::temp_directory_path() / fmt::format("iblkit_shgrid_{}.vdb", ::getpid())).string();
  if (have_vdb()) {
    for (size_t i = 0; i < g.data().size(); ++i) g.data()[i] = 0.25f * static_cast<float>(i % 17) - 1.0f;
    write_vdb(path, g);
    EXPECT_GT(fs::file_size(path), 0u);
#ifdef IBLKIT_HAVE_OPENVDB
    // Read it back: grid "sh_l1_m-1" (k = 1) at index (2, 1, 3) holds that point's RGB.
    openvdb::initialize();
    openvdb::io::File file(path);
    file.open();
    auto base = file.readGrid("sh_l1_m-1");
    file.close();
    auto grid = openvdb::gridPtrCast<openvdb::Vec3fGrid>(base);
    ASSERT_TRUE(grid);
    openvdb::Vec3f v = grid->getConstAccessor().getValue(openvdb::Coord(2, 1, 3));
    const float* want = g.at(2, 1, 3) + 3 * 1;
    EXPECT_EQ(v.x(), want[0]);
    EXPECT_EQ(v.y(), want[1]);
    EXPECT_EQ(v.z(), want[2]);
    // The index-to-world transform puts grid point (2, 1, 3) where the grid says it is.
    openvdb::Vec3d w = grid->transform().indexToWorld(openvdb::Vec3d(2, 1, 3));
    Vec3 p = g.grid().point(2, 1, 3);
    EXPECT_NEAR(w.x(), p.x, 1e-9);
    EXPECT_NEAR(w.y(), p.y, 1e-9);
    EXPECT_NEAR(w.z(), p.z, 1e-9);
#endif
    fs::remove(path);
  } else {
    try {
      write_vdb(path, g);
      FAIL() << "no error without OpenVDB";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Unsupported);
      EXPECT_NE(std::string(e.what()).find("no OpenVDB"), std::string::npos);
    }
  }
}

TEST(IlfAccumulate, BlockProductMatchesNaiveSum) {
  int64_t rows = 5000;
  int D = 7, K = 9;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> U(-1, 1);
  std::vector<float> R(size_t(rows) * D), B(size_t(D) * K);
  std::vector<double> C(size_t(rows) * K, 0.5);
  for (auto& v : R) v = U(rng);
  for (auto& v : B) v = U(rng);
  double flops = accumulate_block(R.data(), rows, D, B.data(), K, C.data());
  EXPECT_EQ(flops, 2.0 * rows * D * K);
  constexpr double kTol = 1e-5;  // float sums of 7 products of magnitude ≤ 1
  for (int64_t r = 0; r < rows; r += 97)
    for (int k = 0; k < K; ++k) {
      double s = 0.5;
      for (int j = 0; j < D; ++j) s += double(R[size_t(j) * rows + r]) * B[size_t(k) * D + j];
      EXPECT_NEAR(C[size_t(k) * rows + r], s, kTol);
    }
}

// Hostile input: the lookup is defined for any input, and a header cannot make the reader allocate what
// the file does not hold or accept a volume beyond the supported range.
TEST(SHGrid, LookupOfANonFinitePointIsAnErrorAndFarPointsClamp) {
  SHGrid g(small_grid(), 2);
  g.at(3, 2, 4)[0] = 7.0f;
  EXPECT_THROW(g.coeffs_at({std::nan(""), 0.2, 3}), Error);
  EXPECT_THROW(g.irradiance({0, std::nan(""), 3}, {0, 1, 0}), Error);
  EXPECT_THROW(g.coeffs_at({0, 0.2, INFINITY}), Error);
  EXPECT_FLOAT_EQ(float(g.coeffs_at({1e300, 1e300, 1e300}).c[0].x), 7.0f);  // clamped to the far corner
  EXPECT_EQ(g.coeffs_at({-1e300, -1e300, -1e300}).c[0].x, 0.0);
}

void write_header(const std::string& path, const std::string& json_header, size_t data_bytes) {
  std::string h = "IBLKIT-SHGRID 1\n" + json_header;
  size_t total = ((h.size() + 1 + 63) / 64) * 64;
  h.append(total - h.size() - 1, ' ');
  h.push_back('\n');
  std::ofstream o(path, std::ios::binary);
  o << h << std::string(data_bytes, '\0');
}

TEST(SHGrid, HeaderSizesAndVolumesAreCheckedBeforeAllocating) {
  const std::string path = (fs::temp_directory_path() / "iblkit_shgrid_header_test.shgrid").string();
  const std::string tail = R"(, "dtype": "float32", "layout": "z,y,x,coefficient,channel"})";
  auto message = [&] {
    try {
      read_shgrid(path);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // 200³ points of 5 bands declared (2.4 GB), 100 bytes present: refused from the file's length.
  write_header(path, R"({"bands": 5, "resolution": [200, 200, 200], "min": [0, 0, 0], "max": [1, 1, 1])" + tail, 100);
  EXPECT_NE(
      message().find(
          "truncated: the header declares 200x200x200 points of 5 bands (2400000000 data bytes), the file holds 100"),
      std::string::npos)
      << message();
  // min/max ±1e308: the volume's size overflows; refused.
  write_header(
      path,
      R"({"bands": 1, "resolution": [2, 2, 2], "min": [-1e308, -1e308, -1e308], "max": [1e308, 1e308, 1e308])" + tail,
      8 * 3 * 4);
  EXPECT_NE(message().find("\"min\", \"max\""), std::string::npos) << message();
  write_header(path, R"({"bands": 0, "resolution": [2, 2, 2], "min": [0, 0, 0], "max": [1, 1, 1])" + tail, 0);
  EXPECT_NE(message().find("\"bands\" = 0"), std::string::npos) << message();
  write_header(path, R"({"bands": 1, "resolution": [1, 2, 2], "min": [0, 0, 0], "max": [1, 1, 1])" + tail, 0);
  EXPECT_NE(message().find("\"resolution\" 1x2x2"), std::string::npos) << message();
  fs::remove(path);
}

}  // namespace
}  // namespace ibl::ilf
