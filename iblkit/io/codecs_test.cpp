// iblkit's own image codecs against OpenImageIO's, file by file: the same pixels to the bit, the same
// channel order, format name and sRGB flag, so that the iblkit command (which loads OpenImageIO only
// for other formats) reads and writes exactly what it read and wrote through OpenImageIO.
#include "iblkit/io/codecs.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"

namespace ibl::io::detail {
namespace {

namespace fs = std::filesystem;

fs::path tmpdir() {
  fs::path d = fs::temp_directory_path() / ("iblkit_codecs_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

const OiioCodec& oiio() { return oiio_codec.get(); }

void expect_same(const Decoded& a, const Decoded& b, const std::string& what) {
  ASSERT_EQ(a.image.width(), b.image.width()) << what;
  ASSERT_EQ(a.image.height(), b.image.height()) << what;
  ASSERT_EQ(a.image.channels(), b.image.channels()) << what;
  EXPECT_EQ(a.format, b.format) << what;
  EXPECT_EQ(a.srgb, b.srgb) << what;
  size_t diff = 0, first = 0;
  for (size_t i = 0; i < a.image.size(); ++i)
    if (std::memcmp(a.image.data() + i, b.image.data() + i, sizeof(float)) != 0 && diff++ == 0) first = i;
  EXPECT_EQ(diff, 0u) << what << ": first difference at value " << first << ": " << a.image.data()[first] << " vs "
                      << b.image.data()[first];
}

// Our reader against OpenImageIO's on one file; false when ours leaves the file to OpenImageIO.
bool compare_reads(const std::string& path) {
  EXPECT_NE(sniff(path), FileKind::Other) << path;
  std::optional<Decoded> ours = read_own(path);
  if (!ours) return false;
  expect_same(*ours, oiio().read(path), path);
  Header h = read_header(path), hr = oiio().read_header(path);
  EXPECT_EQ(h.width, hr.width) << path;
  EXPECT_EQ(h.height, hr.height) << path;
  EXPECT_EQ(h.channels, hr.channels) << path;
  EXPECT_EQ(h.format, hr.format) << path;
  return true;
}

std::vector<std::string> real_files() {
  std::vector<std::string> files;
  const fs::path blender = "/usr/share/blender/datafiles/studiolights/world";
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(blender, ec))
    if (e.path().extension() == ".exr") files.push_back(e.path().string());
  const char* shared = std::getenv("IBLKIT_SHARED");
  if (shared && fs::exists(fs::path(shared) / "probes"))
    for (const auto& e : fs::recursive_directory_iterator(fs::path(shared) / "probes")) {
      auto ext = e.path().extension();
      if (ext == ".exr" || ext == ".hdr" || ext == ".pfm") files.push_back(e.path().string());
    }
  return files;
}

TEST(Codecs, RealProbesReadAsOpenImageIOReadsThem) {
  auto files = real_files();
  if (files.empty()) GTEST_SKIP() << "neither blender-data nor ../shared/probes present";
  int ours = 0;
  for (const auto& f : files) ours += compare_reads(f);
  EXPECT_EQ(ours, static_cast<int>(files.size())) << "every real probe is read by our own codecs";
}

// Positive values over many exponents, some zeros, some tiny.
Image test_image(int w, int h, int c, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> mant(0.0f, 1.0f);
  std::uniform_int_distribution<int> ex(-20, 20);
  Image img(w, h, c);
  for (size_t i = 0; i < img.size(); ++i) {
    int kind = static_cast<int>(i % 17);
    img.data()[i] = kind == 0 ? 0.0f : kind == 1 ? 1e-35f : std::ldexp(mant(rng), ex(rng));
  }
  return img;
}

TEST(Codecs, ExrWrittenByEitherReadsTheSame) {
  for (int nc = 1; nc <= 4; ++nc)
    for (bool half : {false, true}) {
      Image img = test_image(37, 11, nc, 7 + nc);
      img.data()[3] = 1e6f;  // beyond half's range
      std::string a = (tmpdir() / fmt::format("oiio_{}_{}.exr", nc, half)).string();
      std::string b = (tmpdir() / fmt::format("ours_{}_{}.exr", nc, half)).string();
      oiio().write(a, img, false, half);
      write_exr(b, img, half);
      ASSERT_TRUE(compare_reads(a));
      ASSERT_TRUE(compare_reads(b));
      auto da = read_exr(a), db = read_exr(b);
      expect_same(*da, *db, fmt::format("{} channels, half {}", nc, half));
      // The same channel names and pixel types in both files.
      Imf::InputFile fa(a.c_str()), fb(b.c_str());
      std::vector<std::pair<std::string, int>> ca, cb;
      for (auto c = fa.header().channels().begin(); c != fa.header().channels().end(); ++c)
        ca.push_back({c.name(), c.channel().type});
      for (auto c = fb.header().channels().begin(); c != fb.header().channels().end(); ++c)
        cb.push_back({c.name(), c.channel().type});
      EXPECT_EQ(ca, cb);
      EXPECT_EQ(fb.header().compression(), Imf::ZIP_COMPRESSION);
    }
}

// An EXR with the given channel names (float), value = channel index + 1 everywhere; data window
// offset from the origin.
std::string exr_with_channels(const std::string& name, const std::vector<std::string>& channels) {
  std::string path = (tmpdir() / name).string();
  Imath::Box2i win({3, 5}, {3 + 8, 5 + 4});
  Imf::Header h(Imath::Box2i({0, 0}, {20, 20}), win);
  std::vector<float> data(9 * 5 * channels.size());
  for (size_t i = 0; i < data.size(); ++i)
    data[i] = static_cast<float>(i % channels.size() + 1) + 0.001f * (i / channels.size());
  Imf::FrameBuffer fb;
  size_t xs = sizeof(float) * channels.size(), ys = xs * 9;
  char* base = reinterpret_cast<char*>(data.data()) - 3 * xs - 5 * ys;
  for (size_t c = 0; c < channels.size(); ++c) {
    h.channels().insert(channels[c], Imf::Channel(Imf::FLOAT));
    fb.insert(channels[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
  }
  Imf::OutputFile out(path.c_str(), h);
  out.setFrameBuffer(fb);
  out.writePixels(5);
  return path;
}

TEST(Codecs, ExrChannelOrderAndDataWindowFollowOpenImageIO) {
  EXPECT_TRUE(compare_reads(exr_with_channels("abgr.exr", {"A", "B", "G", "R"})));
  EXPECT_TRUE(compare_reads(exr_with_channels("ya.exr", {"A", "Y"})));
  EXPECT_TRUE(compare_reads(exr_with_channels("rgby.exr", {"Y", "B", "R", "G"})));
  // Layers and other names: left to OpenImageIO, and read_image still reads them.
  for (auto chans : std::vector<std::vector<std::string>>{
           {"diffuse.R", "diffuse.G", "diffuse.B"}, {"Z"}, {"R", "G", "B", "depth"}}) {
    std::string p = exr_with_channels("other.exr", chans);
    EXPECT_FALSE(read_exr(p).has_value()) << chans[0];
    Image img = read_image(p);
    EXPECT_EQ(img.channels(), static_cast<int>(chans.size()));
    expect_same(oiio().read(p), oiio().read(p), p);
  }
}

TEST(Codecs, RgbeWrittenByEitherReadsTheSame) {
  for (int w : {37, 5}) {  // run-length encoded scanlines, and flat ones (narrower than 8)
    Image img = test_image(w, 9, 3, 3);
    for (int x = 0; x < w; ++x) img.set_rgb(x, 4, {2.5, 0.5, 1.25});  // long runs
    std::string a = (tmpdir() / fmt::format("oiio_{}.hdr", w)).string(),
                b = (tmpdir() / fmt::format("ours_{}.hdr", w)).string();
    oiio().write(a, img, false, false);
    write_rgbe(b, img);
    ASSERT_TRUE(compare_reads(a));
    ASSERT_TRUE(compare_reads(b));
    expect_same(*read_rgbe(a), *read_rgbe(b), fmt::format("width {}", w));
  }
}

// Rows of a multiple of 16 values, where OpenImageIO rounds every value the same way (codec_png.cpp).
TEST(Codecs, PngWrittenByEitherReadsTheSame) {
  for (int nc : {1, 3}) {
    Image img(256, 9, nc);
    std::mt19937 rng(5);
    for (int x = 0; x < 256; ++x)
      for (int y = 0; y < 9; ++y)
        for (int c = 0; c < nc; ++c) {
          // Every level, and half steps give or take a few ulps (where rounding rules differ).
          float v = y < 3 ? (x + 0.5f * y + 0.25f * c) / 255.0f : (x + 0.5f) / 255.0f;
          for (int k = static_cast<int>(rng() % 9) - 4; k != 0; k += k > 0 ? -1 : 1)
            v = std::nextafter(v, k > 0 ? 2.0f : -1.0f);
          img.at(x, y, c) = std::clamp(v, 0.0f, 1.0f);
        }
    std::string a = (tmpdir() / fmt::format("oiio_{}.png", nc)).string(),
                b = (tmpdir() / fmt::format("ours_{}.png", nc)).string();
    oiio().write(a, img, true, false);
    write_png(b, img);
    expect_same(oiio().read(a), oiio().read(b), fmt::format("{} channels", nc));
    EXPECT_TRUE(oiio().read(b).srgb);
  }
}

TEST(Codecs, PfmOfEitherByteOrderReadsTheSame) {
  Image img = test_image(6, 4, 3, 11);
  std::string le = (tmpdir() / "le.pfm").string(), be = (tmpdir() / "be.pfm").string(),
              grey = (tmpdir() / "grey.pfm").string();
  write_image(le, img);
  write_image(grey, test_image(6, 4, 1, 12));
  {
    std::ofstream out(be, std::ios::binary);
    out << "PF\n6 4\n1.0\n";
    for (int y = 3; y >= 0; --y)
      for (int x = 0; x < 6; ++x)
        for (int c = 0; c < 3; ++c) {
          uint32_t u;
          float v = img.at(x, y, c);
          std::memcpy(&u, &v, 4);
          u = __builtin_bswap32(u);
          out.write(reinterpret_cast<const char*>(&u), 4);
        }
  }
  EXPECT_TRUE(compare_reads(le));
  EXPECT_TRUE(compare_reads(be));
  EXPECT_TRUE(compare_reads(grey));
  expect_same(read_pfm(le), read_pfm(be), "byte orders");
}

TEST(Codecs, BrokenFilesAreFormatErrorsNamingTheFile) {
  Image img = test_image(64, 16, 3, 5);
  for (const char* ext : {".exr", ".hdr", ".pfm"}) {
    std::string good = (tmpdir() / (std::string("good") + ext)).string(),
                cut = (tmpdir() / (std::string("cut") + ext)).string();
    write_image(good, img);
    std::ifstream in(good, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() * 2 / 3);
    try {
      read_image(cut);
      ADD_FAILURE() << ext << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Format) << e.what();
      EXPECT_NE(std::string(e.what()).find(cut), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace ibl::io::detail
