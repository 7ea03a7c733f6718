// OpenImageIO's side of io/codecs.h: every format iblkit does not read or write itself, and text.
// Built into the "oiio" plugin (libiblkit_oiio.so) for the iblkit command, linked directly into the
// test binary and the benchmarks; either way it provides itself to io::detail::oiio_codec when
// loaded.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/io/codecs.h"

namespace ibl::io::detail {

namespace {

std::unique_ptr<OIIO::ImageInput> open_input(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string err = OIIO::geterror();
    if (err.find("not exist") != std::string::npos || err.find("Could not open") != std::string::npos)
      fail(ErrorKind::Io, "{}: cannot open ({})", path, err);
    fail(ErrorKind::Format, "{}: not an image format this build reads ({})", path, err);
  }
  return in;
}

Header oiio_read_header(const std::string& path) {
  auto in = open_input(path);
  const OIIO::ImageSpec& spec = in->spec();
  return Header{spec.width, spec.height, spec.nchannels, in->format_name()};
}

Decoded oiio_read(const std::string& path) {
  auto in = open_input(path);
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    fail(ErrorKind::Format, "{}: image has no pixels ({}x{}x{})", path, spec.width, spec.height, spec.nchannels);
  check_decoded_size(path, spec.width, spec.height, spec.nchannels);
  int nc = spec.nchannels;
  Decoded d;
  d.image = Image(spec.width, spec.height, nc);
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, d.image.data())) {
    std::string err = in->geterror();
    fail(ErrorKind::Format, "{}: corrupt or truncated image data ({})", path, err.empty() ? "read failed" : err);
  }
  d.format = in->format_name();
  in->close();
  bool ldr = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  std::string cs = spec.get_string_attribute("oiio:ColorSpace");
  d.srgb = ldr && (cs.empty() || cs == "sRGB" || cs == "srgb_rec709_scene");
  return d;
}

void oiio_write(const std::string& path, const Image& img, bool ldr, bool half) {
  std::string ext = OIIO::Strutil::lower(OIIO::Filesystem::extension(path));
  auto out = OIIO::ImageOutput::create(path);
  if (!out) fail(ErrorKind::Format, "{}: no image writer for extension '{}' ({})", path, ext, OIIO::geterror());
  const bool exr = ext == ".exr";
  OIIO::TypeDesc type = ldr ? OIIO::TypeDesc::UINT8 : (half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
  OIIO::ImageSpec spec(img.width(), img.height(), img.channels(), type);
  if (ldr) spec.attribute("oiio:ColorSpace", "sRGB");
  if (exr) spec.attribute("compression", "zip");
  if (!out->open(path, spec)) fail(ErrorKind::Io, "{}: cannot write ({})", path, out->geterror());
  if (!out->write_image(OIIO::TypeDesc::FLOAT, img.data()))
    fail(ErrorKind::Io, "{}: write failed ({})", path, out->geterror());
  if (!out->close()) fail(ErrorKind::Io, "{}: close failed ({})", path, out->geterror());
}

bool oiio_draw_text(Image& img, int x, int y, const std::string& text, int size, const char* font, Vec3 rgb) {
  OIIO::ImageSpec spec(img.width(), img.height(), img.channels(), OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf buf(spec, img.data());  // wraps our pixels
  float col[4] = {static_cast<float>(rgb.x), static_cast<float>(rgb.y), static_cast<float>(rgb.z), 1.0f};
  return OIIO::ImageBufAlgo::render_text(buf, x, y, text, size, font,
                                         OIIO::cspan<float>(col, img.channels() >= 4 ? 4 : 3));
}

const uint16_t& iso16(double iso) {
  static thread_local uint16_t v;
  v = static_cast<uint16_t>(std::clamp(std::lround(iso), 1L, 65535L));
  return v;
}

void oiio_write_photo(const std::string& path, const Image& img, const PhotoMeta& m) {
  std::string ext = OIIO::Strutil::lower(OIIO::Filesystem::extension(path));
  auto out = OIIO::ImageOutput::create(path);
  if (!out) fail(ErrorKind::Format, "{}: no image writer for extension '{}' ({})", path, ext, OIIO::geterror());
  OIIO::ImageSpec spec(img.width(), img.height(), img.channels(),
                       m.bits == 16 ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8);
  if (m.srgb) spec.attribute("oiio:ColorSpace", "sRGB");
  if (ext == ".jpg" || ext == ".jpeg") {
    spec.attribute("Compression", "jpeg:" + std::to_string(m.quality));
    spec.attribute("CompressionQuality", m.quality);
  }
  if (m.exposure_s > 0) spec.attribute("ExposureTime", static_cast<float>(m.exposure_s));
  if (m.f_number > 0) spec.attribute("FNumber", static_cast<float>(m.f_number));
  if (m.iso > 0) {  // EXIF 2.3 tag 0x8827 (ISOSpeedRatings before 2.3): OpenImageIO's name for it
    spec.attribute("Exif:PhotographicSensitivity", OIIO::TypeDesc::UINT16, &iso16(m.iso));
  }
  // OpenImageIO 2.4's TIFF writer leaves the ISO tag out (it writes ExposureTime and FNumber): the
  // description carries all three in every format.
  spec.attribute("ImageDescription", "iblkit camera: ExposureTime=" + fmt::format("{:.9g}", m.exposure_s) +
                                         " FNumber=" + fmt::format("{:.9g}", m.f_number) +
                                         " ISO=" + fmt::format("{:.9g}", m.iso));
  if (!out->open(path, spec)) fail(ErrorKind::Io, "{}: cannot write ({})", path, out->geterror());
  if (!out->write_image(OIIO::TypeDesc::FLOAT, img.data()))
    fail(ErrorKind::Io, "{}: write failed ({})", path, out->geterror());
  if (!out->close()) fail(ErrorKind::Io, "{}: close failed ({})", path, out->geterror());
}

const OiioCodec kCodec{oiio_read, oiio_read_header, oiio_write, oiio_draw_text, oiio_write_photo};
[[maybe_unused]] const bool kProvided = (oiio_codec.provide(&kCodec), true);

}  // namespace

}  // namespace ibl::io::detail
