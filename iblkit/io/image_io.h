// Reading and writing images: .exr, .hdr (RGBE), .pfm, .tif, .png/.jpg (8-bit sRGB, decoded to
// linear on read and encoded on write), and whatever else OpenImageIO reads. EXR, RGBE, PFM and PNG
// output go through iblkit's own codecs, everything else through OpenImageIO, loaded only then
// (io/codecs.h); the pixels are the same either way. Every failure throws ibl::Error naming the file.
#pragma once
#include <string>

#include "iblkit/core/image.h"

namespace ibl::io {

struct ReadDesc {
  // Replace NaN/Inf by 0 and negative values by 0 instead of rejecting the image.
  bool sanitize = false;
  // Keep at most this many channels (e.g. 3 drops alpha); 0 keeps all.
  int max_channels = 0;
};

struct ReadReport {
  int sanitized = 0;          // values replaced because of `sanitize`
  bool srgb_decoded = false;  // 8-bit sRGB input decoded to linear
  std::string format;         // OpenImageIO's name of the format ("openexr", "hdr", "pnm", …)
};

Image read_image(const std::string& path, const ReadDesc& desc = {}, ReadReport* report = nullptr);

struct ImageSpec {
  int width = 0, height = 0, channels = 0;
};
// The size and channel count from the file's header, the pixels left undecoded (image_spec.cpp);
// the errors of read_image for a missing, unreadable or non-image file. The pixels may still be
// bad: read_image is what checks them.
ImageSpec read_image_spec(const std::string& path);

// Checks for NaN/Inf/negative values; throws ibl::Error with the first bad pixel's position,
// or with `sanitize` replaces them by 0 and returns how many were replaced. Negative values
// within 5% of the mean |value| are compression noise and become 0 without complaint.
int check_pixels(Image& img, const std::string& what, bool sanitize);

struct WriteDesc {
  bool half = false;  // .exr: 16-bit half floats instead of 32-bit
  bool data = false;  // .png: values in [0,1] stored as they are (a data texture such as a BRDF table,
                      // RGBD), without the sRGB curve or the sRGB chunk; 1 to 4 channels, alpha
                      // unassociated (not multiplied into the colour)
};

// Writes img; the format follows the extension. .png/.jpg get sRGB-encoded 8 bits, clamped to [0,1]
// (use io/tonemap.h first for HDR content). Creates no folders.
void write_image(const std::string& path, const Image& img, const WriteDesc& desc = {});

// sRGB transfer function (IEC 61966-2-1).
float srgb_to_linear(float v);
float linear_to_srgb(float v);

}  // namespace ibl::io
