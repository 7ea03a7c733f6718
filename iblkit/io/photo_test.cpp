#include "iblkit/io/photo.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"

namespace ibl::io {
namespace {

TEST(Photo, CodesAndExifRoundTrip) {
  const auto dir = std::filesystem::temp_directory_path() / "iblkit_photo_test";
  std::filesystem::create_directories(dir);
  Image codes(32, 16, 3);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x)
      for (int c = 0; c < 3; ++c) codes.at(x, y, c) = static_cast<float>((x * 8 + c * 3) % 256) / 255.0f;
  PhotoMeta meta{1.0 / 64, 5.6, 400, "iblkit", "lab"};  // 1/64: OpenImageIO 2.4 wrote x/0 for powers of 2
  for (const char* name : {"a.tif", "a.png", "a.jpg"}) {
    for (int bits : {8, 16}) {
      const std::string path = (dir / name).string();
      if (bits == 16 && std::string(name) == "a.jpg") {
        EXPECT_THROW(write_photo(path, codes, bits, meta), Error);
        continue;
      }
      write_photo(path, codes, bits, meta, 100);
      const Photo p = read_photo(path);
      EXPECT_EQ(p.bits, bits) << name;
      ASSERT_EQ(p.codes.width(), 32);
      // JPEG at quality 100 is within a few codes; the others exact.
      const double tol = std::string(name) == "a.jpg" ? 6.0 / 255 : 0.5 / (std::exp2(bits) - 1);
      for (size_t i = 0; i < codes.size(); ++i) ASSERT_NEAR(p.codes.data()[i], codes.data()[i], tol) << name;
      if (std::string(name) != "a.png") {  // PNG holds no Exif block here
        EXPECT_NEAR(p.meta.exposure_time, 1.0 / 64, 1e-8) << name;
        EXPECT_NEAR(p.meta.f_number, 5.6, 1e-5) << name;
        // OpenImageIO 2.4's TIFF writer drops the ISO tag (io/photo.h); JPEG keeps it.
        if (std::string(name) == "a.jpg") EXPECT_EQ(p.meta.iso, 400) << name;
        EXPECT_EQ(p.meta.model, "lab") << name;
      }
    }
  }
  EXPECT_THROW(read_photo((dir / "missing.jpg").string()), Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ibl::io
