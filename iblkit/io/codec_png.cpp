// PNG output through libpng: the pictures every command writes, without loading OpenImageIO.
// 8 bits per channel, grey or RGB (image_io leaves images with alpha to OpenImageIO, which
// un-premultiplies them), each value v in [0, 1] stored as round(255·v) computed in float, as
// OpenImageIO's vectorised conversion stores it (its scalar remainder, used for the last values of a
// row when the row's value count is not a multiple of 16, computes ⌊255·v + ½⌋ instead, which differs
// only within an ulp of a half step); with the sRGB, gAMA and cHRM chunks OpenImageIO writes for an
// sRGB image, so that its reader, and every viewer, takes the values as sRGB-encoded.
#include <png.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

#include "iblkit/core/error.h"
#include "iblkit/io/codecs.h"

namespace ibl::io::detail {

namespace {
void on_png_error(png_structp png, png_const_charp msg) {
  auto* why = static_cast<std::string*>(png_get_error_ptr(png));
  *why = msg;
  std::longjmp(png_jmpbuf(png), 1);
}
void on_png_warning(png_structp, png_const_charp) {}

// The libpng calls; false (and `why`) on a libpng error. Nothing local changes after setjmp.
bool encode(std::FILE* f, int w, int h, int color_type, png_bytep* rows, bool srgb, std::string* why) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, why, on_png_error, on_png_warning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), 8, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (srgb) png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_ABSOLUTE);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}
}  // namespace

void write_png(const std::string& path, const Image& img, bool srgb) {
  const int w = img.width(), h = img.height(), nc = img.channels();
  if (nc < 1 || nc > 4) fail(ErrorKind::Internal, "{}: write_png takes 1 to 4 channels (got {})", path, nc);
  // Converted up front: nothing below may throw while libpng holds the jump buffer.
  std::vector<unsigned char> bytes(img.size());
  for (size_t i = 0; i < img.size(); ++i) {
    float v = std::clamp(img.data()[i], 0.0f, 1.0f);
    bytes[i] = static_cast<unsigned char>(std::round(v * 255.0f));
  }
  std::vector<png_bytep> rows(static_cast<size_t>(h));
  for (int y = 0; y < h; ++y) rows[static_cast<size_t>(y)] = bytes.data() + static_cast<size_t>(y) * w * nc;

  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) fail(ErrorKind::Io, "{}: cannot write ({})", path, std::strerror(errno));
  std::string why;
  static constexpr int kColorType[4] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                        PNG_COLOR_TYPE_RGB_ALPHA};
  bool ok = encode(f, w, h, kColorType[nc - 1], rows.data(), srgb, &why);
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) fail(ErrorKind::Io, "{}: write failed ({})", path, why.empty() ? "libpng" : why);
}

}  // namespace ibl::io::detail
