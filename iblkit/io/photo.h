// Photographs as the camera wrote them: code values in [0, 1] (no sRGB decoding, unlike
// read_image) with the bit depth and the exposure metadata (Exif ExposureTime, FNumber,
// ISOSpeedRatings, Make, Model, read through OpenImageIO's metadata). For hdr merge (capture/) and
// for the lab's photographs (write_photo: 8-bit JPEG/PNG, 16-bit TIFF/PNG, Exif written where the
// format holds it).
#pragma once
#include <string>

#include "iblkit/core/image.h"

namespace ibl::io {

struct PhotoMeta {
  double exposure_time = 0;  // seconds; 0: not in the file
  double f_number = 0;       // 0: not in the file
  double iso = 0;            // 0: not in the file
  std::string make, model;   // camera
};

struct Photo {
  Image codes;  // 3 channels (grey repeated, alpha dropped), values code / (2^bits − 1)
  int bits = 8;
  PhotoMeta meta;
  std::string format;  // OpenImageIO's name of the format
};

// Throws ibl::Error naming the file (missing, not an image, not 8/16-bit integer data).
Photo read_photo(const std::string& path);

// Writes codes (values in [0, 1], 1 or 3 channels) as `bits`-bit integers (8: .jpg/.png/.tif; 16:
// .tif/.png) with the metadata; `quality` for JPEG (1–100). Through an AtomicFile. PNG gets no Exif
// block, and OpenImageIO 2.4's TIFF writer drops the ISO (exposure time and f-number are written).
void write_photo(const std::string& path, const Image& codes, int bits, const PhotoMeta& meta, int quality = 95);

}  // namespace ibl::io
