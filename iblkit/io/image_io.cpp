#include "iblkit/io/image_io.h"
#include "iblkit/core/input_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <vector>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/io/codecs.h"

namespace ibl::io {

namespace fs = std::filesystem;

float srgb_to_linear(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }
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
    if (std::isfinite(d[i]) && std::abs(d[i]) <= kMaxPixel) {
      mean_abs += std::abs(d[i]);
      ++finite;
    }
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
      fail(ErrorKind::Value, "{}: pixel ({}, {}) channel {} is {} ({}); sanitize replaces such values by 0", what, x, y,
           static_cast<int>(i % nc), kind, v);
    }
    d[i] = 0.0f;
    ++bad;
  }
  return bad;
}

namespace detail {

constinit plugin::Provided<OiioCodec> oiio_codec{"oiio", "OpenImageIO codec"};
constinit plugin::Provided<RawCodec> raw_codec{"raw", "LibRaw raw decoder"};

FileKind sniff(const std::string& path) {
  unsigned char b[4] = {};
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return FileKind::Other;  // OpenImageIO's open says why
  size_t n = std::fread(b, 1, 4, f);
  std::fclose(f);
  if (n == 4 && b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01) return FileKind::OpenExr;
  if (n >= 2 && b[0] == '#' && b[1] == '?') return FileKind::Rgbe;
  if (n >= 3 && b[0] == 'P' && (b[1] == 'F' || b[1] == 'f') && std::isspace(b[2])) return FileKind::Pfm;
  return FileKind::Other;
}

std::optional<Decoded> read_own(const std::string& path) {
  switch (sniff(path)) {
    case FileKind::OpenExr:
      return read_exr(path);
    case FileKind::Rgbe:
      return read_rgbe(path);
    case FileKind::Pfm:
      return read_pfm(path);
    case FileKind::Other:
      break;
  }
  return std::nullopt;
}

Header read_header(const std::string& path) {
  std::optional<Header> h;
  switch (sniff(path)) {
    case FileKind::OpenExr:
      h = read_exr_header(path);
      break;
    case FileKind::Rgbe:
      h = read_rgbe_header(path);
      break;
    case FileKind::Pfm:
      h = read_pfm_header(path);
      break;
    case FileKind::Other:
      break;
  }
  return h ? *h : oiio_codec.get().read_header(path);
}

}  // namespace detail

Image read_image(const std::string& path, const ReadDesc& desc, ReadReport* report) {
  require_input_file(path, "an image");  // no FIFO, device or folder reaches a codec
  std::optional<detail::Decoded> d = detail::read_own(path);
  if (!d) d = detail::oiio_codec.get().read(path);
  Image& img = d->image;
  int nc = img.channels();
  if (d->srgb) {
    int color_channels = std::min(nc, 3);
    for (size_t i = 0; i < img.pixel_count(); ++i)
      for (int c = 0; c < color_channels; ++c) img.data()[i * nc + c] = srgb_to_linear(img.data()[i * nc + c]);
  }
  if (desc.max_channels > 0 && nc > desc.max_channels) img = img.with_channels(desc.max_channels);
  int fixed = check_pixels(img, path, desc.sanitize);
  if (report) {
    report->sanitized = fixed;
    report->srgb_decoded = d->srgb;
    report->format = d->format;
  }
  return std::move(img);
}

namespace {
// Portable float map: Debian's OpenImageIO 2.4 reads PFM but has no writer for it. Little-endian
// (scale −1), rows bottom to top, 1 or 3 channels.
// Writes to `file` (a temporary name); errors name `path`.
void write_pfm(const std::string& file, const std::string& path, const Image& img) {
  int nc = img.channels() >= 3 ? 3 : 1;
  std::FILE* f = std::fopen(file.c_str(), "wb");
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

// Our own writers where they write what OpenImageIO would; OpenImageIO (a plugin) for the rest (PNG
// with alpha among them: OpenImageIO divides colour by alpha on writing it).
void write_encoded(const std::string& file, const std::string& ext, const Image& src, bool ldr, bool half, bool data) {
  const int nc = src.channels();
  if (ext == ".exr" && nc <= 4) return detail::write_exr(file, src, half);
  if (ext == ".hdr" && nc == 3) return detail::write_rgbe(file, src);
  if (ext == ".png" && (nc == 1 || nc == 3 || (data && nc <= 4))) return detail::write_png(file, src, !data);
  if (data)
    fail(ErrorKind::Value, "{}: a data image is written as .png with 1 to 4 channels (got {} channels)", file, nc);
  detail::oiio_codec.get().write(file, src, ldr, half && ext == ".exr");
}
}  // namespace

void write_image(const std::string& path, const Image& img, const WriteDesc& desc) {
  if (img.empty()) fail(ErrorKind::Value, "{}: refusing to write an empty image", path);
  std::string ext = fs::path(path).extension().string();
  for (auto& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  bool ldr = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
  int nc = img.channels();
  if (ext == ".hdr" || ext == ".jpg" || ext == ".jpeg") nc = std::min(nc, 3);
  Image src = nc == img.channels() ? img : img.with_channels(nc);
  if (ldr && !desc.data) {
    int color = std::min(nc, 3);
    for (size_t i = 0; i < src.pixel_count(); ++i)
      for (int c = 0; c < nc; ++c) {
        float& v = src.data()[i * nc + c];
        v = c < color ? linear_to_srgb(v) : std::clamp(v, 0.0f, 1.0f);
      }
  }
  // Every writer writes to a temporary name beside `path` (keeping the extension, which picks the
  // format) and the file is renamed into place only when complete; messages name `path`.
  AtomicFile file(path);
  try {
    if (ext == ".pfm")
      write_pfm(file.temp_path(), path, img);
    else
      write_encoded(file.temp_path(), ext, src, ldr, desc.half, desc.data);
  } catch (const Error& e) {
    throw file.naming_path(e);
  }
  file.commit();
}

}  // namespace ibl::io
