// A backplate as the camera wrote it — 8-bit JPEG/PNG, 16-bit TIFF/PNG, a raw file (linear: no curve; written
// back as a 16-bit linear TIFF or an 8-bit sRGB JPEG/PNG, iblkit writes no raw files) — taken into linear light for the
// composite and written back the way it came: through the same response curve, in the same bit depth,
// with the same metadata (docs/capture.md, "Backplates").
//
// In: each code value z of channel c becomes the relative exposure response.invert(z, c) (1 = the
// sensor's saturation). Out: every pixel the composite left exactly as it was (the object touched it
// neither by itself nor by its shadow or light: its linear value is bit for bit the backplate's) keeps
// its original code; every other pixel is response.apply(x, c) rounded to the bit depth. So a lossless
// output of the input's depth is bit-identical to the input outside what the object changed.
//
// Saturated pixels (a code at the top of the range in some channel: the sun, a window) hold at least the
// light they show, not that light. The rule: they are composited like any other pixel from their decoded
// value — a lower bound, so a shadow over them comes out too bright where the scene was brighter — and
// the pixels where that happens are counted and reported, so that a user knows the shadow there is a
// bound.
#pragma once
#include <cstdint>
#include <string>

#include "iblkit/capture/response.h"
#include "iblkit/core/image.h"
#include "iblkit/io/photo.h"

namespace ibl::capture {

struct Backplate {
  std::string path;
  bool encoded = false;  // integer code values (8/16-bit) with `response`; false: a float (HDR) file, linear
  io::Photo photo;       // the codes, bit depth and metadata (codes empty when not encoded)
  Response response;     // how the codes were linearised (linear for a float file)
  Image linear;          // RGB, what composite() takes
};

// response: "" picks the default — "srgb" for integer files, "linear" for float and raw ones — else "srgb",
// "linear", "camera" or an iblkit.response/1 file. Throws ibl::Error naming the file.
Backplate read_backplate(const std::string& path, const std::string& response = "");
// The same through a curve in memory (one recovered from a bracket of the same camera).
Backplate read_backplate(const std::string& path, const Response& response);

struct BackplateReport {
  int64_t kept = 0;                // pixels whose original codes were kept (unchanged by the composite)
  int64_t encoded = 0;             // pixels encoded from the composite
  int64_t saturated = 0;           // pixels of the backplate saturated in some channel
  int64_t saturated_changed = 0;   // … of those, changed by the composite
  int64_t saturated_darkened = 0;  // … of those, darkened (under the object's shadow)
};

// The composite (RGB linear, the backplate's size) as code values of the backplate's bit depth `bits`
// (its own when 0). Pixels are kept only when the depth is the input's.
Image encode_like(const Backplate& b, const Image& composite, int bits = 0, BackplateReport* report = nullptr);

// Writes codes (encode_like's) to `path` (.jpg 8-bit, .png/.tif 8 or 16) with the backplate's metadata;
// quality for JPEG: 0 takes the input's (estimated from its tables), else 95.
void write_like(const std::string& path, const Backplate& b, const Image& codes, int bits = 0, int quality = 0);

// Is `path`'s extension one that write_like writes (.jpg, .jpeg, .png, .tif, .tiff)?
bool is_photo_extension(const std::string& path);

}  // namespace ibl::capture
