#include "iblkit/io/image_io.h"
#include "iblkit/core/testing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <utility>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfTileDescription.h>
#include <OpenEXR/ImfTiledOutputFile.h>
#include <vector>
#include "iblkit/core/error.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/tonemap.h"

using ibl::test_util::expect_error;

namespace ibl::io {
namespace {

namespace fs = std::filesystem;

fs::path tmpdir() {
  fs::path d = fs::temp_directory_path() / ("iblkit_io_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

Image gradient(int w, int h, int c) {
  Image img(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) img.at(x, y, k) = 0.01f * x + 0.1f * y + 3.0f * k + 0.5f;
  return img;
}

TEST(ImageIo, FloatFormatsRoundTripExactly) {
  Image img = gradient(13, 7, 3);
  for (const char* ext : {".exr", ".pfm", ".tif"}) {
    std::string p = (tmpdir() / (std::string("rt") + ext)).string();
    write_image(p, img);
    Image back = read_image(p);
    ASSERT_EQ(back.width(), 13);
    ASSERT_EQ(back.height(), 7);
    ASSERT_EQ(back.channels(), 3);
    for (size_t i = 0; i < img.size(); ++i) ASSERT_EQ(back.data()[i], img.data()[i]) << ext << " " << i;
  }
}

TEST(ImageIo, RgbeAndHalfKeepRelativePrecision) {
  constexpr double kRgbeRelTol = 1.0 / 128;   // 8-bit mantissa shared exponent: ≤ 2^-8 of the largest channel
  constexpr double kHalfRelTol = 1.0 / 1024;  // 10-bit mantissa
  Image img = gradient(16, 8, 3);
  std::string hdr = (tmpdir() / "rt.hdr").string(), exr = (tmpdir() / "half.exr").string();
  write_image(hdr, img);
  write_image(exr, img, {true});
  Image a = read_image(hdr), b = read_image(exr);
  for (size_t i = 0; i < img.size(); ++i) {
    EXPECT_NEAR(a.data()[i], img.data()[i], kRgbeRelTol * img.data()[(i / 3) * 3 + 2]);
    EXPECT_NEAR(b.data()[i], img.data()[i], kHalfRelTol * img.data()[i]);
  }
}

TEST(ImageIo, PngIsSrgbEncodedAndDecoded) {
  constexpr double kQuantTol = 1.0 / 255 * 2.5;  // one 8-bit step in sRGB, slope ≤ 2.4 near 1 in linear
  Image img(4, 1, 3);
  float vals[4] = {0.0f, 0.05f, 0.214f, 1.0f};  // 0.214 linear ≈ 0.5 sRGB
  for (int x = 0; x < 4; ++x) img.set_rgb(x, 0, {vals[x], vals[x], vals[x]});
  std::string p = (tmpdir() / "srgb.png").string();
  write_image(p, img);
  ReadReport rep;
  Image back = read_image(p, {}, &rep);
  EXPECT_TRUE(rep.srgb_decoded);
  for (int x = 0; x < 4; ++x) EXPECT_NEAR(back.at(x, 0, 0), vals[x], kQuantTol);
  EXPECT_NEAR(linear_to_srgb(0.214f), 0.5f, 2e-3);
  EXPECT_NEAR(srgb_to_linear(linear_to_srgb(0.37f)), 0.37f, 1e-6);
}

TEST(ImageIo, MissingFileNamesTheFile) {
  expect_error([] { read_image("/nonexistent/probe.exr"); }, ErrorKind::Io, {"/nonexistent/probe.exr", "no such file"});
  expect_error([] { read_image(tmpdir().string()); }, ErrorKind::Io, {"folder"});
}

TEST(ImageIo, UnknownFormatIsAFormatError) {
  std::string p = (tmpdir() / "notes.txt").string();
  std::ofstream(p) << "this is not an image\n";
  expect_error([&] { read_image(p); }, ErrorKind::Format, {p});
}

TEST(ImageIo, TruncatedFileIsAFormatError) {
  Image img = gradient(64, 64, 3);
  std::string good = (tmpdir() / "full.hdr").string(), cut = (tmpdir() / "cut.hdr").string();
  write_image(good, img);
  auto size = fs::file_size(good);
  std::ifstream in(good, std::ios::binary);
  std::string bytes(size / 2, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  expect_error([&] { read_image(cut); }, ErrorKind::Format, {cut});
  // And a corrupt header.
  std::string junk = (tmpdir() / "junk.exr").string();
  std::ofstream(junk, std::ios::binary) << "\x76\x2f\x31\x01garbage-after-the-magic-number";
  expect_error([&] { read_image(junk); }, ErrorKind::Format, {junk});
}

// Writes a small EXR at `name` and overwrites int32 (little-endian) values in it: each pair is the offset after
// the first occurrence of `key` and the value. Returns the path; fails the test where `key` is missing.
std::string patched_exr(const std::string& name, int size, const std::string& key,
                        std::initializer_list<std::pair<size_t, int32_t>> values) {
  std::string p = (tmpdir() / name).string();
  write_image(p, gradient(size, size, 3));
  std::ifstream in(p, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const size_t at = bytes.find(key);
  EXPECT_NE(at, std::string::npos) << key;
  if (at == std::string::npos) return p;
  for (auto [offset, v] : values) bytes.replace(at + key.size() + offset, 4, reinterpret_cast<const char*>(&v), 4);
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return p;
}

TEST(ImageIo, AHeaderDeclaringMorePixelsThanItsFileCanHoldIsRefusedBeforeAllocating) {
  // A 64×64 EXR whose data window is rewritten to 16384×16384 (4 GB of float RGB): refused from the header and
  // the file's size (io/codecs.h, check_decoded_size), not after OpenEXR allocated the frame buffer. After the key:
  // the attribute's size, then xMin, yMin, xMax, yMax (int32).
  std::string p =
      patched_exr("declares-16k.exr", 64, std::string("dataWindow\0box2i\0", 17), {{12, 16383}, {16, 16383}});
  expect_error([&] { read_image(p); }, ErrorKind::Format, {p, "16384x16384", "cannot hold"});
}

TEST(ImageIo, AnExrAttributeLongerThanItsFileIsRefusedBeforeOpenExrAllocatesIt) {
  // A good EXR whose "compression" attribute (1 byte) is rewritten to declare 1 GB (what fuzz_image found with a
  // string attribute: OpenEXR allocated it before reading): refused by the header walk, the file named.
  std::string p = patched_exr("attr-1gb.exr", 16, std::string("compression\0compression\0", 24), {{0, 1 << 30}});
  expect_error([&] { read_image(p); }, ErrorKind::Format, {p, "'compression'", "1073741824 bytes"});
  // The file fuzz_image found, kept in fuzz/crashes/image, is replayed by make test (fuzz_replay_image).
}

TEST(ImageIo, AWideExrWindowIsRefusedBeforeOpenExrAllocatesItsLineBuffer) {
  // What fuzz_image found (fuzz/crashes/image/slow-22s-400MB-exr-1.3KB-file.exr): a small file whose data window
  // is 8388624 x 8. OpenEXR's InputFile allocated a 400 MB line buffer when it opened the file, before the size
  // check after it; the header walk refuses it first, for the header alone (read_image_spec) as for the pixels.
  std::string p = patched_exr("wide.exr", 16, std::string("dataWindow\0box2i\0", 17), {{12, 8388623}, {16, 7}});
  expect_error([&] { read_image_spec(p); }, ErrorKind::Format, {p, "8388624x8", "cannot hold"});
  expect_error([&] { read_image(p); }, ErrorKind::Format, {p, "8388624x8", "cannot hold"});
}

TEST(ImageIo, ExrTilesLargerThanTheFileCanHoldAreRefused) {
  // A 16 x 16 tiled EXR (OpenEXR's own writer) whose tile size is rewritten to 65536 x 65536: OpenEXR clips a
  // tile to the window but allocates its buffer whole, so the header walk refuses it.
  std::string p = (tmpdir() / "tiled.exr").string();
  {
    Imf::Header h(16, 16);
    h.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    h.setTileDescription(Imf::TileDescription(16, 16, Imf::ONE_LEVEL));
    std::vector<float> px(256, 0.5f);
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px.data()), sizeof(float), 16 * sizeof(float)));
    Imf::TiledOutputFile out(p.c_str(), h);
    out.setFrameBuffer(fb);
    out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
  }
  EXPECT_NEAR(read_image(p).at(3, 4, 0), 0.5f, 1e-6f);  // read as it was written
  std::ifstream in(p, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const std::string key("tiles\0tiledesc\0", 15);
  const size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const uint32_t big = 65536;
  for (size_t off : {4, 8}) bytes.replace(at + key.size() + off, 4, reinterpret_cast<const char*>(&big), 4);
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  expect_error([&] { read_image(p); }, ErrorKind::Format, {p, "65536x65536 tiles", "cannot hold"});
}

TEST(ImageIo, BadPixelsAreRejectedWithTheirPositionOrSanitized) {
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -5.0f}) {
    Image img = gradient(8, 8, 3);
    img.at(5, 2, 1) = bad;
    std::string p = (tmpdir() / "bad.exr").string();
    write_image(p, img);
    expect_error([&] { read_image(p); }, ErrorKind::Value, {p, "(5, 2)", "channel 1", "sanitize replaces"});
    ReadReport rep;
    Image fixed = read_image(p, {true, 0}, &rep);
    EXPECT_EQ(rep.sanitized, 1);
    EXPECT_EQ(fixed.at(5, 2, 1), 0.0f);
  }
}

TEST(ImageIo, ProcessingNoiseNegativesBecomeZero) {
  Image img = gradient(8, 8, 3);
  img.at(1, 1, 0) = -1e-3f;  // far within 5% of the mean
  int n = check_pixels(img, "noise", false);
  EXPECT_EQ(n, 0);
  EXPECT_EQ(img.at(1, 1, 0), 0.0f);
}

TEST(ImageIo, BlenderProbesReadAsLatLong) {
  const std::string dir = "/usr/share/blender/datafiles/studiolights/world/";
  if (!fs::exists(dir + "forest.exr")) GTEST_SKIP() << "blender-data not installed";
  auto env = read_envmap(dir + "forest.exr");
  EXPECT_EQ(env.mapping.kind(), sphere::MappingKind::LatLong);
  EXPECT_EQ(env.image.width(), 1024);
  EXPECT_EQ(env.image.height(), 512);
  auto p = env.integral();
  EXPECT_GT(p[0], 0.0);
}

TEST(EnvMapIo, WrongChannelCountIsRejected) {
  Image two(16, 8, 2, 1.0f);
  std::string p = (tmpdir() / "two.exr").string();
  write_image(p, two);
  expect_error([&] { read_envmap(p); }, ErrorKind::Value, {p, "2 channels"});
}

TEST(EnvMapIo, CubeFaceFolderRoundTrip) {
  Image cross = gradient(64, 48, 3);
  sphere::EnvMap env(cross, sphere::Mapping(sphere::MappingKind::CubeHCross, 64, 48));
  std::string dir = (tmpdir() / "faces").string();
  write_cube_faces(dir, env, ".exr");
  auto back = read_envmap(dir);
  ASSERT_EQ(back.mapping.kind(), sphere::MappingKind::CubeHCross);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      if (env.mapping.solid_angle(x, y) > 0) {
        ASSERT_EQ(back.image.at(x, y, 0), cross.at(x, y, 0)) << x << "," << y;
      }
    }
  fs::remove(fs::path(dir) / "pz.exr");
  expect_error([&] { read_envmap(dir); }, ErrorKind::Io, {"pz"});
}

TEST(ToneMap, AutoExposurePutsMedianOnKey) {
  Image img(10, 1, 3);
  for (int x = 0; x < 10; ++x) img.set_rgb(x, 0, Vec3{1, 1, 1} * (x + 1.0));
  double s = auto_exposure_scale(img, 0.18);
  EXPECT_NEAR(s * 6.0, 0.18, 1e-6);  // median of 1..10 by nth_element at index 5 is 6
  Image out = tonemap(img, {});
  for (int x = 1; x < 10; ++x) EXPECT_GE(out.at(x, 0, 0), out.at(x - 1, 0, 0));  // monotone
  EXPECT_LE(out.at(9, 0, 0), 1.0f);
}

}  // namespace
}  // namespace ibl::io
