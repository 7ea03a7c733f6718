// OpenImageIO's side of io/codecs.h: every format iblkit does not read or write itself, and text.
// Built into the "oiio" plugin (libiblkit_oiio.so) for the iblkit command, linked directly into the
// test binary and the benchmarks; either way it provides itself to io::detail::oiio_codec when
// loaded.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cmath>

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

Photo oiio_read_photo(const std::string& path) {
  auto in = open_input(path);
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    fail(ErrorKind::Format, "{}: image has no pixels ({}x{}x{})", path, spec.width, spec.height, spec.nchannels);
  const auto base = spec.format.basetype;
  if (base != OIIO::TypeDesc::UINT8 && base != OIIO::TypeDesc::UINT16)
    fail(ErrorKind::Format,
         "{}: holds {} pixels, not the 8- or 16-bit code values of a photograph (for an HDR image use it as a probe)",
         path, spec.format.c_str());
  check_decoded_size(path, spec.width, spec.height, spec.nchannels);
  Image raw(spec.width, spec.height, spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, raw.data())) {
    std::string err = in->geterror();
    fail(ErrorKind::Format, "{}: corrupt or truncated image data ({})", path, err.empty() ? "read failed" : err);
  }
  Photo p;
  p.bits = base == OIIO::TypeDesc::UINT8 ? 8 : 16;
  p.format = in->format_name();
  p.codes = Image(spec.width, spec.height, 3);
  const int nc = spec.nchannels;
  for (size_t i = 0; i < raw.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c) p.codes.data()[3 * i + c] = raw.data()[i * nc + (nc >= 3 ? c : 0)];
  p.meta.exposure_time = spec.get_float_attribute("ExposureTime", 0.0f);
  p.meta.f_number = spec.get_float_attribute("FNumber", 0.0f);
  // Exif 2.3 renamed ISOSpeedRatings (tag 0x8827) PhotographicSensitivity; OpenImageIO 2.4 reads it so.
  for (const char* name : {"Exif:ISOSpeedRatings", "Exif:PhotographicSensitivity"})
    if (p.meta.iso <= 0) p.meta.iso = spec.get_int_attribute(name, 0);
  p.meta.make = spec.get_string_attribute("Make");
  p.meta.model = spec.get_string_attribute("Model");
  for (const OIIO::ParamValue& a : spec.extra_attribs) {
    const std::string name = a.name().string();
    if (name.rfind("oiio:", 0) == 0 || name.rfind("jpeg:", 0) == 0 || name == "Compression" ||
        name == "CompressionQuality" || name == "ExposureTime" || name == "FNumber" || name == "Make" ||
        name == "Model" || name == "Exif:ISOSpeedRatings" || name == "Exif:PhotographicSensitivity")
      continue;
    if (a.type().basetype == OIIO::TypeDesc::UNKNOWN || a.type().basetype == OIIO::TypeDesc::PTR) continue;
    p.meta.attributes.push_back({name, a.type().c_str(), a.get_string(1 << 20)});
  }
  in->close();
  return p;
}

void oiio_write_photo(const std::string& path, const Image& codes, int bits, const PhotoMeta& meta, int quality) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) fail(ErrorKind::Format, "{}: no image writer for this extension ({})", path, OIIO::geterror());
  OIIO::ImageSpec spec(codes.width(), codes.height(), codes.channels(),
                       bits == 16 ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8);
  for (const PhotoAttribute& a : meta.attributes) spec.attribute(a.name, OIIO::TypeDesc(a.type), a.value);
  // OpenImageIO 2.4 turns a float that is an exact power of two below 1 (1/4, 1/64 s) into the Exif
  // rational x/0 (read back as inf); one part in 10^7 more gives it 1/4, 1/64 exactly.
  auto rational_safe = [](double v) {
    int e;
    return static_cast<float>(std::frexp(v, &e) == 0.5 && v < 1 ? v * (1 + 1e-7) : v);
  };
  if (meta.exposure_time > 0) spec.attribute("ExposureTime", rational_safe(meta.exposure_time));
  if (meta.f_number > 0) spec.attribute("FNumber", rational_safe(meta.f_number));
  if (meta.iso > 0) spec.attribute("Exif:ISOSpeedRatings", static_cast<int>(std::lround(meta.iso)));
  if (!meta.make.empty()) spec.attribute("Make", meta.make);
  if (!meta.model.empty()) spec.attribute("Model", meta.model);
  if (std::string(out->format_name()) == "jpeg") {
    spec.attribute("Compression", fmt::format("jpeg:{}", quality));
    spec.attribute("CompressionQuality", quality);
  } else if (std::string(out->format_name()) == "tiff") {
    spec.attribute("Compression", "zip");  // lossless
  }
  if (!out->open(path, spec)) fail(ErrorKind::Io, "{}: cannot write ({})", path, out->geterror());
  // Rounded here: OpenImageIO's float -> integer conversion is not round-to-nearest everywhere.
  const double levels = bits == 16 ? 65535.0 : 255.0;
  bool ok;
  if (bits == 16) {
    std::vector<uint16_t> q(codes.size());
    for (size_t i = 0; i < q.size(); ++i) q[i] = static_cast<uint16_t>(std::lround(codes.data()[i] * levels));
    ok = out->write_image(OIIO::TypeDesc::UINT16, q.data());
  } else {
    std::vector<uint8_t> q(codes.size());
    for (size_t i = 0; i < q.size(); ++i) q[i] = static_cast<uint8_t>(std::lround(codes.data()[i] * levels));
    ok = out->write_image(OIIO::TypeDesc::UINT8, q.data());
  }
  if (!ok) fail(ErrorKind::Io, "{}: write failed ({})", path, out->geterror());
  if (!out->close()) fail(ErrorKind::Io, "{}: close failed ({})", path, out->geterror());
}

const OiioCodec kCodec{oiio_read, oiio_read_header, oiio_write, oiio_draw_text, oiio_read_photo, oiio_write_photo};
[[maybe_unused]] const bool kProvided = (oiio_codec.provide(&kCodec), true);

}  // namespace

}  // namespace ibl::io::detail
