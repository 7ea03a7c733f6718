#include "iblkit/capture/backplate.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "iblkit/core/error.h"
#include "iblkit/io/dng.h"
#include "iblkit/io/image_io.h"

namespace ibl::capture {

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

double levels_of(int bits) { return bits == 16 ? 65535.0 : 255.0; }

}  // namespace

bool is_photo_extension(const std::string& path) {
  const std::string e = lower_extension(path);
  return e == ".jpg" || e == ".jpeg" || e == ".png" || e == ".tif" || e == ".tiff";
}

namespace {

// `pick(encoded)`: the response for an integer file (true) or a float one (false).
template <typename Pick>
Backplate read_with(const std::string& path, const Pick& pick) {
  Backplate b;
  b.path = path;
  if (io::is_raw_path(path)) {  // linear already (LibRaw): no curve
    b.photo = io::read_photo(path);
    b.encoded = true;
    b.response = pick(true);
    if (b.response.kind != "linear")
      fail(ErrorKind::Value, "{}: a raw file is linear (LibRaw decodes it): no response curve ({}) applies to it", path,
           b.response.kind);
    b.linear = b.photo.codes;
    return b;
  }
  if (is_photo_extension(path)) {
    try {
      b.photo = io::read_photo(path);
      b.encoded = true;
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::Format) throw;  // a float TIFF: read below as linear; a broken file fails there
    }
  }
  if (!b.encoded) {
    b.response = pick(false);
    b.linear = io::read_image(path, {.max_channels = 3});
    if (b.linear.channels() < 3) b.linear = b.linear.with_channels(3);
    if (b.response.kind != "linear")  // a float file through a curve: its values are code values
      for (size_t i = 0; i < b.linear.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
          float& v = b.linear.data()[3 * i + c];
          v = static_cast<float>(b.response.invert(std::clamp(static_cast<double>(v), 0.0, 1.0), c));
        }
    return b;
  }
  b.response = pick(true);
  const Image& codes = b.photo.codes;
  b.linear = Image(codes.width(), codes.height(), 3);
  for (size_t i = 0; i < codes.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c)
      b.linear.data()[3 * i + c] = static_cast<float>(b.response.invert(codes.data()[3 * i + c], c));
  return b;
}

}  // namespace

Backplate read_backplate(const std::string& path, const std::string& response) {
  const bool raw = io::is_raw_path(path);
  Backplate b = read_with(path, [&](bool encoded) {
    return response_by_name(response.empty() ? (encoded && !raw ? "srgb" : "linear") : response);
  });
  if (b.encoded && !response.empty()) check_fits(b.response, b.photo.bits, path, response);
  return b;
}

Backplate read_backplate(const std::string& path, const Response& response) {
  return read_with(path, [&](bool) { return response; });
}

Image encode_like(const Backplate& b, const Image& composite, int bits, BackplateReport* report) {
  if (!b.encoded) fail(ErrorKind::Value, "{}: not a photograph of code values; nothing to encode like", b.path);
  if (composite.width() != b.linear.width() || composite.height() != b.linear.height() || composite.channels() < 3)
    fail(ErrorKind::Value, "the composite ({}x{}) is not the backplate's size ({}x{})", composite.width(),
         composite.height(), b.linear.width(), b.linear.height());
  if (bits == 0) bits = b.photo.bits;
  if (bits != 8 && bits != 16) fail(ErrorKind::Value, "bit depth {}: 8 or 16", bits);
  const bool same_depth = bits == b.photo.bits;
  // A raw backplate's codes are linear: written at 16 bits they stay so (the unchanged pixels bit for bit), at 8
  // bits through sRGB (a developed photograph; 8 linear bits would band the shadows).
  const Response srgb = srgb_response();
  const Response& curve = b.photo.linear && bits == 8 ? srgb : b.response;
  const double levels = levels_of(bits), in_levels = levels_of(b.photo.bits);
  BackplateReport r;
  Image out(composite.width(), composite.height(), 3);
  const Image& codes = b.photo.codes;
  for (int y = 0; y < composite.height(); ++y)
    for (int x = 0; x < composite.width(); ++x) {
      const float* lin = b.linear.pixel(x, y);
      const float* comp = composite.pixel(x, y);
      const float* in = codes.pixel(x, y);
      float* o = out.pixel(x, y);
      const bool same = comp[0] == lin[0] && comp[1] == lin[1] && comp[2] == lin[2];
      bool saturated = false, darker = false;
      for (int c = 0; c < 3; ++c) {
        saturated = saturated || std::lround(in[c] * in_levels) >= static_cast<long>(in_levels);
        darker = darker || comp[c] < lin[c];
      }
      r.saturated += saturated;
      if (same && same_depth) {
        for (int c = 0; c < 3; ++c) o[c] = in[c];
        ++r.kept;
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const double z = curve.apply(std::max(0.0, static_cast<double>(comp[c])), c);
        o[c] = static_cast<float>(std::lround(std::clamp(z, 0.0, 1.0) * levels) / levels);
      }
      ++r.encoded;
      if (saturated && !same) {
        ++r.saturated_changed;
        r.saturated_darkened += darker;
      }
    }
  if (report) *report = r;
  return out;
}

void write_like(const std::string& path, const Backplate& b, const Image& codes, int bits, int quality) {
  if (!b.encoded) fail(ErrorKind::Value, "{}: not a photograph of code values", b.path);
  if (io::is_raw_path(path))
    fail(ErrorKind::Value,
         "{}: iblkit writes no raw files: write the composite as .tif (16-bit, linear like the raw), .jpg (sRGB) or "
         ".exr",
         path);
  if (bits == 0) bits = b.photo.bits;
  if (quality == 0) quality = b.photo.meta.jpeg_quality > 0 ? b.photo.meta.jpeg_quality : 95;
  io::write_photo(path, codes, bits, b.photo.meta, quality);
}

}  // namespace ibl::capture
