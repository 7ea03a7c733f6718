#include "iblkit/io/image_io.h"

#include <cmath>
#include <filesystem>
#include <cstdio>
#include <memory>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "iblkit/core/error.h"

namespace ibl::io {

namespace fs = std::filesystem;

float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}
float linear_to_srgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

int check_pixels(Image& img, const std::string& what, bool sanitize) {
  float* d = img.data();
  int nc = img.channels();
  // Negative values within kNoise × the mean |value| are processing noise (Blender's CC0 probes
  // hold down to −3.4% of their mean, from filtering during their making); they become 0 silently.
  // Anything more negative is bad data.
  constexpr double kNoise = 0.05;
  // Values above 1e20 (the sun is about 1e9 W/(sr·m²)) are not radiance: their sums overflow float.
  constexpr float kMaxPixel = 1e20f;
  double mean_abs = 0;
  size_t finite = 0;
  for (size_t i = 0; i < img.size(); ++i)
    if (std::isfinite(d[i]) && std::abs(d[i]) <= kMaxPixel) { mean_abs += std::abs(d[i]); ++finite; }
  float noise = static_cast<float>(finite ? kNoise * mean_abs / finite : 0.0);
  int bad = 0;
  for (size_t i = 0; i < img.size(); ++i) {
    float v = d[i];
    if (std::isfinite(v) && v >= 0.0f && v <= kMaxPixel) continue;
    if (std::isfinite(v) && v < 0.0f && v >= -noise) {
      d[i] = 0.0f;
      continue;
    }
    if (!sanitize) {
      size_t p = i / nc;
      int x = static_cast<int>(p % img.width()), y = static_cast<int>(p / img.width());
      const char* kind = std::isnan(v) ? "NaN" : (std::isinf(v) ? "Inf" : (v > kMaxPixel ? "above 1e20" : "negative"));
      fail(ErrorKind::Value, "{}: pixel ({}, {}) channel {} is {} ({}); sanitize replaces such values by 0",
           what, x, y, static_cast<int>(i % nc), kind, v);
    }
    d[i] = 0.0f;
    ++bad;
  }
  return bad;
}

Image read_image(const std::string& path, const ReadDesc& desc, ReadReport* report) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(ErrorKind::Io, "{}: no such file", path);
  if (fs::is_directory(path, ec)) fail(ErrorKind::Io, "{}: is a folder, not an image", path);
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string err = OIIO::geterror();
    if (err.find("not exist") != std::string::npos || err.find("Could not open") != std::string::npos)
      fail(ErrorKind::Io, "{}: cannot open ({})", path, err);
    fail(ErrorKind::Format, "{}: not an image format this build reads ({})", path, err);
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    fail(ErrorKind::Format, "{}: image has no pixels ({}x{}x{})", path, spec.width, spec.height, spec.nchannels);
  if (static_cast<int64_t>(spec.width) * spec.height > (int64_t(1) << 30))
    fail(ErrorKind::Value, "{}: image {}x{} is too large", path, spec.width, spec.height);
  int nc = spec.nchannels;
  Image img(spec.width, spec.height, nc);
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, img.data())) {
    std::string err = in->geterror();
    fail(ErrorKind::Format, "{}: corrupt or truncated image data ({})", path, err.empty() ? "read failed" : err);
  }
  std::string fmt_name = in->format_name();
  in->close();
  bool ldr = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  std::string cs = spec.get_string_attribute("oiio:ColorSpace");
  bool srgb = ldr && (cs.empty() || cs == "sRGB" || cs == "srgb_rec709_scene");
  if (srgb) {
    int color_channels = std::min(nc, 3);
    for (size_t i = 0; i < img.pixel_count(); ++i)
      for (int c = 0; c < color_channels; ++c) img.data()[i * nc + c] = srgb_to_linear(img.data()[i * nc + c]);
  }
  if (desc.max_channels > 0 && nc > desc.max_channels) img = img.with_channels(desc.max_channels);
  int fixed = check_pixels(img, path, desc.sanitize);
  if (report) {
    report->sanitized = fixed;
    report->srgb_decoded = srgb;
    report->format = fmt_name;
  }
  return img;
}

namespace {
// Portable float map: Debian's OpenImageIO 2.4 reads PFM but has no writer for it. Little-endian
// (scale −1), rows bottom to top, 1 or 3 channels.
void write_pfm(const std::string& path, const Image& img) {
  int nc = img.channels() >= 3 ? 3 : 1;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) fail(ErrorKind::Io, "{}: cannot write", path);
  std::fprintf(f, "%s\n%d %d\n-1.0\n", nc == 3 ? "PF" : "Pf", img.width(), img.height());
  std::vector<float> row(static_cast<size_t>(img.width()) * nc);
  bool ok = true;
  for (int y = img.height() - 1; y >= 0; --y) {
    for (int x = 0; x < img.width(); ++x)
      for (int c = 0; c < nc; ++c) row[static_cast<size_t>(x) * nc + c] = img.at(x, y, c);
    ok = ok && std::fwrite(row.data(), sizeof(float), row.size(), f) == row.size();
  }
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) fail(ErrorKind::Io, "{}: write failed", path);
}
}  // namespace

void write_image(const std::string& path, const Image& img, const WriteDesc& desc) {
  if (img.empty()) fail(ErrorKind::Value, "{}: refusing to write an empty image", path);
  std::string ext = fs::path(path).extension().string();
  for (auto& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (ext == ".pfm") return write_pfm(path, img);
  auto out = OIIO::ImageOutput::create(path);
  if (!out) fail(ErrorKind::Format, "{}: no image writer for extension '{}' ({})", path, ext, OIIO::geterror());
  bool ldr = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
  int nc = img.channels();
  if (ext == ".hdr" || ext == ".jpg" || ext == ".jpeg") nc = std::min(nc, 3);
  OIIO::TypeDesc type = ldr ? OIIO::TypeDesc::UINT8 : (desc.half && ext == ".exr" ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
  OIIO::ImageSpec spec(img.width(), img.height(), nc, type);
  if (ldr) spec.attribute("oiio:ColorSpace", "sRGB");
  if (ext == ".exr") spec.attribute("compression", "zip");
  Image src = nc == img.channels() ? img : img.with_channels(nc);
  if (ldr) {
    int color = std::min(nc, 3);
    for (size_t i = 0; i < src.pixel_count(); ++i)
      for (int c = 0; c < nc; ++c) {
        float& v = src.data()[i * nc + c];
        v = c < color ? linear_to_srgb(v) : std::clamp(v, 0.0f, 1.0f);
      }
  }
  if (!out->open(path, spec)) fail(ErrorKind::Io, "{}: cannot write ({})", path, out->geterror());
  if (!out->write_image(OIIO::TypeDesc::FLOAT, src.data())) fail(ErrorKind::Io, "{}: write failed ({})", path, out->geterror());
  if (!out->close()) fail(ErrorKind::Io, "{}: close failed ({})", path, out->geterror());
}

}  // namespace ibl::io
