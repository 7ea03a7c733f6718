#include "iblkit/capture/backplate.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/photo.h"

namespace ibl::capture {
namespace {

namespace fs = std::filesystem;

// A 16-bit TIFF and an 8-bit PNG of code values with Exif, then a "composite" that darkens a block and
// leaves the rest as it was.
struct Fixture {
  fs::path dir = fs::temp_directory_path() / "iblkit_backplate_test";
  Image codes{40, 30, 3};
  io::PhotoMeta meta{1.0 / 60, 2.8, 200, "iblkit", "bench"};
  Fixture() {
    fs::create_directories(dir);
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 40; ++x)
        for (int c = 0; c < 3; ++c) codes.at(x, y, c) = static_cast<float>((x * 6 + y * 5 + c * 60) % 256) / 255.0f;
    for (int x = 30; x < 40; ++x)  // a saturated corner (a window)
      for (int y = 0; y < 5; ++y)
        for (int c = 0; c < 3; ++c) codes.at(x, y, c) = 1.0f;
    meta.attributes.push_back({"Exif:DateTimeOriginal", "string", "2026:12:03 12:00:00"});
  }
  ~Fixture() { fs::remove_all(dir); }
};

TEST(Backplate, UnchangedPixelsKeepTheirCodesBitForBitAndChangedOnesGoBackThroughTheResponse) {
  Fixture f;
  for (int bits : {8, 16}) {
    const std::string in = (f.dir / (bits == 8 ? "in.png" : "in.tif")).string();
    io::write_photo(in, f.codes, bits, f.meta);
    const Backplate b = read_backplate(in);
    ASSERT_TRUE(b.encoded);
    EXPECT_EQ(b.response.kind, "srgb");  // the default for code values
    EXPECT_EQ(b.photo.bits, bits);
    // Linear is the sRGB curve's inverse of the codes.
    EXPECT_NEAR(b.linear.at(3, 4, 1), io::srgb_to_linear(b.photo.codes.at(3, 4, 1)), 1e-6);
    Image comp = b.linear;
    for (int y = 0; y < 10; ++y)  // darken a block that includes saturated pixels
      for (int x = 25; x < 40; ++x)
        for (int c = 0; c < 3; ++c) comp.at(x, y, c) *= 0.5f;
    BackplateReport r;
    const Image out = encode_like(b, comp, 0, &r);
    EXPECT_EQ(r.kept, 40 * 30 - 15 * 10);
    EXPECT_EQ(r.encoded, 15 * 10);
    int64_t saturated = 0, saturated_in_block = 0;  // the corner, and gradient pixels that reach the top code
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 40; ++x) {
        bool s = false;
        for (int c = 0; c < 3; ++c) s = s || b.photo.codes.at(x, y, c) >= 1.0f;
        saturated += s;
        saturated_in_block += s && x >= 25 && y < 10;
      }
    EXPECT_GE(saturated, 10 * 5);
    EXPECT_EQ(r.saturated, saturated);
    EXPECT_EQ(r.saturated_darkened, saturated_in_block);
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 40; ++x)
        for (int c = 0; c < 3; ++c) {
          if (x >= 25 && y < 10) {
            const double want = b.response.apply(comp.at(x, y, c), c);
            EXPECT_NEAR(out.at(x, y, c), want, 0.5 / (bits == 8 ? 255.0 : 65535.0) + 1e-7);
          } else {
            ASSERT_EQ(out.at(x, y, c), b.photo.codes.at(x, y, c)) << x << "," << y;
          }
        }
    // Written back: the same codes where unchanged, and the camera's metadata.
    const std::string back = (f.dir / (bits == 8 ? "out.png" : "out.tif")).string();
    write_like(back, b, out);
    const io::Photo p = io::read_photo(back);
    EXPECT_EQ(p.bits, bits);
    for (int y = 10; y < 30; ++y)
      for (int x = 0; x < 40; ++x)
        for (int c = 0; c < 3; ++c) {
          const double levels = bits == 8 ? 255.0 : 65535.0;
          ASSERT_EQ(std::lround(p.codes.at(x, y, c) * levels), std::lround(b.photo.codes.at(x, y, c) * levels));
        }
    if (bits == 16) {  // PNG carries no Exif block
      EXPECT_EQ(p.meta.make, "iblkit");
      EXPECT_NEAR(p.meta.exposure_time, 1.0 / 60, 1e-6);
      bool date = false;
      for (const auto& a : p.meta.attributes)
        date = date || (a.name == "Exif:DateTimeOriginal" && a.value == "2026:12:03 12:00:00");
      EXPECT_TRUE(date);
    }
  }
}

TEST(Backplate, ALinearResponseAndAFloatFileAndBadInput) {
  Fixture f;
  const std::string in = (f.dir / "in.tif").string();
  io::write_photo(in, f.codes, 16, f.meta);
  const Backplate lin = read_backplate(in, "linear");
  EXPECT_NEAR(lin.linear.at(7, 8, 2), lin.photo.codes.at(7, 8, 2), 1e-6);
  // A float file is linear by default and is not "encoded": encode_like refuses it.
  Image hdr(8, 4, 3, 2.5f);
  const std::string exr = (f.dir / "hdr.exr").string();
  io::write_image(exr, hdr);
  const Backplate h = read_backplate(exr);
  EXPECT_FALSE(h.encoded);
  EXPECT_FLOAT_EQ(h.linear.at(1, 1, 0), 2.5f);
  EXPECT_THROW(encode_like(h, hdr), Error);
  EXPECT_THROW(read_backplate((f.dir / "missing.png").string()), Error);
  EXPECT_THROW(read_backplate(in, "no-such-curve.json"), Error);
  EXPECT_THROW(encode_like(lin, Image(3, 3, 3)), Error);  // not the backplate's size
}

TEST(Backplate, ACurveOfFewerCodesThanThePhotographIsRefused) {
  // A curve recovered from 8-bit codes (256 values) says nothing between them: refused for a 16-bit photograph,
  // taken for an 8-bit one; the analytic curves fit any depth.
  Fixture f;
  const std::string tif = (f.dir / "in16.tif").string(), png = (f.dir / "in8.png").string();
  io::write_photo(tif, f.codes, 16, f.meta);
  io::write_photo(png, f.codes, 8, f.meta);
  Response r = srgb_response(256);
  r.kind = "debevec";
  const std::string curve = (f.dir / "curve8.json").string();
  write_response(curve, r);
  try {
    read_backplate(tif, curve);
    FAIL() << "a 256-code curve taken for a 16-bit photograph";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("in16.tif: a 16-bit photograph, but the curve"), std::string::npos) << m;
    EXPECT_NE(m.find("256 code values (a 8-bit camera's)"), std::string::npos) << m;
  }
  EXPECT_NO_THROW(read_backplate(png, curve));
  EXPECT_NO_THROW(read_backplate(tif, "srgb"));
  EXPECT_NO_THROW(check_fits(srgb_response(256), 16, "x.tif", "srgb"));  // analytic: any depth
}

}  // namespace
}  // namespace ibl::capture
