#include "iblkit/io/jpeg_quality.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "iblkit/io/photo.h"

namespace ibl::io {
namespace {

TEST(JpegQuality, TheQualityAJpegWasWrittenWithIsReadBackFromItsTables) {
  // libjpeg's own tables (written through OpenImageIO) at the qualities cameras and editors use.
  const auto dir = std::filesystem::temp_directory_path() / "iblkit_jpeg_quality_test";
  std::filesystem::create_directories(dir);
  Image codes(48, 32, 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 48; ++x)
      for (int c = 0; c < 3; ++c) codes.at(x, y, c) = static_cast<float>((x * 5 + y * 3 + c * 40) % 256) / 255.0f;
  for (int q : {10, 35, 50, 75, 80, 90, 95, 100}) {
    const std::string path = (dir / ("q" + std::to_string(q) + ".jpg")).string();
    write_photo(path, codes, 8, {}, q);
    EXPECT_EQ(estimate_jpeg_quality(path), q) << path;
    EXPECT_EQ(read_photo(path).meta.jpeg_quality, q);
  }
  // Not a JPEG, or no such file: 0.
  write_photo((dir / "a.png").string(), codes, 8, {});
  EXPECT_EQ(estimate_jpeg_quality((dir / "a.png").string()), 0);
  EXPECT_EQ(estimate_jpeg_quality((dir / "missing.jpg").string()), 0);
  std::filesystem::remove_all(dir);
}

TEST(JpegQuality, AnnexKTableScaledIsItsOwnQuality) {
  // Table K.1 itself is quality 50 (scale 100 %); all ones is quality 100.
  const int k1[64] = {16, 11,  10,  16, 24, 40, 51, 61, 12,  12,  14,  19,  26, 58, 60, 55,  14,  13,  16,  24, 40, 57,
                      69, 56,  14,  17, 22, 29, 51, 87, 80,  62,  18,  22,  37, 56, 68, 109, 103, 77,  24,  35, 55, 64,
                      81, 104, 113, 92, 49, 64, 78, 87, 103, 121, 120, 101, 72, 92, 95, 98,  112, 100, 103, 99};
  EXPECT_EQ(jpeg_quality_of_table(k1), 50);
  int ones[64];
  for (int& v : ones) v = 1;
  EXPECT_EQ(jpeg_quality_of_table(ones), 100);
  int zeros[64] = {};
  EXPECT_EQ(jpeg_quality_of_table(zeros), 0);
}

}  // namespace
}  // namespace ibl::io
