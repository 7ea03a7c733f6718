// Raw files through LibRaw (Debian libraw-dev): the "raw" plugin (libiblkit_raw.so) for the iblkit
// command, linked directly into the programs that link everything. read_photo (io/photo.h) hands it a
// path that dng.h's is_raw_path names.
#include <libraw/libraw.h>

#include <algorithm>
#include <cstdint>
#include <memory>

#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/io/codecs.h"

namespace ibl::io::detail {

namespace {

// The colour filter array's name: the 2×2 pattern of its channels, or LinearRaw when every site has all.
std::string pattern_of(LibRaw& lr) {
  const auto& id = lr.imgdata.idata;
  if (id.filters == 0) return id.colors >= 3 ? "LinearRaw" : "monochrome";
  std::string s;
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 2; ++c) s += id.cdesc[lr.COLOR(r, c) & 3];
  return s;
}

Photo raw_read_photo(const std::string& path) {
  auto lr = std::make_unique<LibRaw>();
  auto& P = lr->imgdata.params;
  P.output_bps = 16;             // -4: 16-bit linear
  P.gamm[0] = 1, P.gamm[1] = 1;  //     no gamma
  P.no_auto_bright = 1;          // -W: no brightening to the histogram
  P.use_camera_wb = 1;           // -w: the as-shot white balance
  P.use_camera_matrix = 1;       //     the file's colour matrix
  P.output_color = 1;            // -o 1: linear sRGB primaries
  P.highlight = 0;               // -H 0: clip (a clipped site reads 1 in every channel)
  P.user_qual = 3;               // -q 3: AHD demosaicing
  P.adjust_maximum_thr = 0;      //     the white level is the file's, not the data's maximum
  // LibRaw reports data errors (a file cut short) through this callback and carries on with zeros; the
  // reader refuses the file instead of printing LibRaw's line and returning black rows.
  struct DataError {
    bool any = false;
    int offset = -1;
  } data_error;
  lr->set_dataerror_handler(
      [](void* d, const char*, const int offset) {
        auto* e = static_cast<DataError*>(d);
        e->any = true;
        e->offset = offset;
      },
      &data_error);
  // The focal plane's resolution (Exif 0xA20E, 0xA20F, 0xA210), which LibRaw parses past without keeping: with the
  // focal length it gives the field of view exactly (capture::lens_from_exif).
  struct FocalPlane {
    double xres = 0, yres = 0;
    int unit = 0;
  } plane;
  lr->set_exifparser_handler(
      [](void* ctx, int tag, int type, int len, unsigned int ord, void* ifp, INT64) {
        auto* fp = static_cast<FocalPlane*>(ctx);
        auto* in = static_cast<LibRaw_abstract_datastream*>(ifp);
        const int t = tag & 0xffff;
        if (len != 1 || (t != 0xa20e && t != 0xa20f && t != 0xa210)) return;
        auto u32 = [&](const uint8_t* b) {
          return ord == 0x4949 ? uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24
                               : uint32_t(b[3]) | uint32_t(b[2]) << 8 | uint32_t(b[1]) << 16 | uint32_t(b[0]) << 24;
        };
        uint8_t b[8] = {};
        if (t == 0xa210 && type == 3 && in->read(b, 1, 2) == 2)
          fp->unit = ord == 0x4949 ? b[0] | b[1] << 8 : b[1] | b[0] << 8;
        else if (type == 5 && in->read(b, 1, 8) == 8 && u32(b + 4) != 0)
          (t == 0xa20e ? fp->xres : fp->yres) = double(u32(b)) / u32(b + 4);
      },
      &plane);
  int rc = lr->open_file(path.c_str());
  if (rc != LIBRAW_SUCCESS)
    fail(ErrorKind::Format, "{}: not a raw file LibRaw can read ({}): convert it to DNG, or pass a JPEG/TIFF", path,
         libraw_strerror(rc));
  const auto& sz = lr->imgdata.sizes;
  if (sz.width == 0 || sz.height == 0) fail(ErrorKind::Format, "{}: raw file has no image", path);
  check_decoded_size(path, sz.raw_width, sz.raw_height, 4);
  if ((rc = lr->unpack()) != LIBRAW_SUCCESS)
    fail(ErrorKind::Format, "{}: corrupt or truncated raw data ({})", path, libraw_strerror(rc));
  if (data_error.any)
    fail(ErrorKind::Format, "{}: corrupt or truncated raw data (LibRaw: {} at byte {})", path,
         data_error.offset < 0 ? "unexpected end of file" : "data error", data_error.offset);
  const auto& col = lr->imgdata.color;
  Photo p;
  p.format = "raw";
  p.bits = 16;
  p.linear = true;
  unsigned cb = 0;
  for (int c = 0; c < 4; ++c) cb = std::max(cb, col.cblack[c]);
  if (col.cblack[4] * col.cblack[5] > 0)
    for (unsigned i = 0; i < col.cblack[4] * col.cblack[5] && i < LIBRAW_CBLACK_SIZE - 6; ++i)
      cb = std::max(cb, col.cblack[6 + i]);
  p.raw.black = col.black + cb;
  p.raw.white = col.maximum;
  p.raw.pattern = pattern_of(*lr);
  if ((rc = lr->dcraw_process()) != LIBRAW_SUCCESS)
    fail(ErrorKind::Format, "{}: LibRaw could not process the raw data ({})", path, libraw_strerror(rc));
  const float* mul = lr->imgdata.color.pre_mul;
  const double lo = std::min({mul[0], mul[1], mul[2]});
  for (int c = 0; c < 3; ++c) p.raw.multipliers[c] = lo > 0 ? mul[c] / lo : 1.0;
  std::unique_ptr<libraw_processed_image_t, void (*)(libraw_processed_image_t*)> img(
      lr->dcraw_make_mem_image(&rc), [](libraw_processed_image_t* i) { LibRaw::dcraw_clear_mem(i); });
  if (!img || rc != LIBRAW_SUCCESS)
    fail(ErrorKind::Format, "{}: LibRaw could not render the image ({})", path, libraw_strerror(rc));
  if (img->type != LIBRAW_IMAGE_BITMAP || img->bits != 16 || (img->colors != 3 && img->colors != 1))
    fail(ErrorKind::Format, "{}: LibRaw gave {} channels of {} bits, not 16-bit RGB", path, img->colors, img->bits);
  p.codes = Image(img->width, img->height, 3);
  const auto* px = reinterpret_cast<const uint16_t*>(img->data);
  const int nc = img->colors;
  for (size_t i = 0; i < p.codes.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c)
      p.codes.data()[3 * i + c] = static_cast<float>(px[i * nc + (nc == 3 ? c : 0)] / 65535.0);
  const auto& o = lr->imgdata.other;
  p.meta.exposure_time = o.shutter > 0 ? o.shutter : 0;
  p.meta.f_number = o.aperture > 0 ? o.aperture : 0;
  p.meta.iso = o.iso_speed > 0 ? o.iso_speed : 0;
  // The lens as LibRaw reads it (Exif FocalLength and FocalLengthIn35mmFilm), in OpenImageIO's names, for
  // capture::lens_from_exif.
  if (o.focal_len > 0) p.meta.attributes.push_back({"Exif:FocalLength", "float", fmt::format("{:.9g}", o.focal_len)});
  if (plane.xres > 0)
    p.meta.attributes.push_back({"Exif:FocalPlaneXResolution", "float", fmt::format("{:.9g}", plane.xres)});
  if (plane.yres > 0)
    p.meta.attributes.push_back({"Exif:FocalPlaneYResolution", "float", fmt::format("{:.9g}", plane.yres)});
  if (plane.unit > 0)
    p.meta.attributes.push_back({"Exif:FocalPlaneResolutionUnit", "int", fmt::format("{}", plane.unit)});
  if (lr->imgdata.lens.FocalLengthIn35mmFormat > 0)
    p.meta.attributes.push_back({"Exif:FocalLengthIn35mmFilm", "int",
                                 fmt::format("{}", static_cast<int>(lr->imgdata.lens.FocalLengthIn35mmFormat))});
  p.meta.make = lr->imgdata.idata.make;
  p.meta.model = lr->imgdata.idata.model;
  return p;
}

const RawCodec kCodec{raw_read_photo};
[[maybe_unused]] const bool kProvided = (raw_codec.provide(&kCodec), true);

}  // namespace

}  // namespace ibl::io::detail
