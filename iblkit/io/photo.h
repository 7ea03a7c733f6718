// Photographs as the camera wrote them: code values in [0, 1] (no sRGB decoding, unlike
// read_image) with the bit depth and the exposure metadata (Exif ExposureTime, FNumber,
// ISOSpeedRatings, Make, Model, read through OpenImageIO's metadata). For hdr merge (capture/) and
// for the lab's photographs (write_photo: 8-bit JPEG/PNG, 16-bit TIFF/PNG, Exif written where the
// format holds it).
#pragma once
#include <array>
#include <string>
#include <vector>

#include "iblkit/core/image.h"

namespace ibl::io {

// One metadata field as OpenImageIO names it ("Exif:DateTimeOriginal", "Orientation", "XResolution"), its
// type ("string", "float", "int", "rational", …) and its value written out as text.
struct PhotoAttribute {
  std::string name, type, value;
};

struct PhotoMeta {
  double exposure_time = 0;  // seconds; 0: not in the file
  double f_number = 0;       // 0: not in the file
  double iso = 0;            // 0: not in the file
  std::string make, model;   // camera
  // Every other field the file carries (Exif, TIFF, IPTC, GPS; not OpenImageIO's own "oiio:" ones), kept so
  // that a photograph written back (composite's LDR output) carries what the camera wrote. The five above
  // are written after them and win.
  std::vector<PhotoAttribute> attributes;
  int jpeg_quality = 0;  // a JPEG's quality estimated from its luminance quantisation table (jpeg_quality.h); 0: none
};

// What a raw file's decoding did (LibRaw; see read_photo).
struct RawLevels {
  double black = 0, white = 0;          // the sensor's black and white level, from the file
  std::array<double, 3> multipliers{};  // the white-balance multipliers applied (as shot; the smallest is 1)
  std::string pattern;                  // the colour filter array ("RGGB", "LinearRaw", …)
};

struct Photo {
  Image codes;  // 3 channels (grey repeated, alpha dropped), values code / (2^bits − 1)
  int bits = 8;
  PhotoMeta meta;
  std::string format;  // OpenImageIO's name of the format, or "raw"
  // A raw file (DNG, CR2, NEF, …, by extension: dng.h's is_raw_path), decoded by LibRaw (the "raw"
  // plugin) as dcraw would with `-4 -W -w -H 0 -o 1`: codes linear in the light, (value − black) /
  // (white − black) times the as-shot multipliers (so 1 is saturation in the channel with the smallest, and
  // clipped sites read 1 in every channel), demosaiced (AHD), camera colour to linear sRGB by the file's
  // matrix, 16-bit. No response curve applies.
  bool linear = false;
  RawLevels raw;
};

// Throws ibl::Error naming the file (missing, not an image, not 8/16-bit integer data, a raw file LibRaw
// cannot open).
Photo read_photo(const std::string& path);

// Writes codes (values in [0, 1], 1 or 3 channels) as `bits`-bit integers (8: .jpg/.png/.tif; 16:
// .tif/.png) with the metadata; `quality` for JPEG (1–100). Through an AtomicFile. PNG gets no Exif
// block, and OpenImageIO 2.4's TIFF writer drops the ISO (exposure time and f-number are written).
void write_photo(const std::string& path, const Image& codes, int bits, const PhotoMeta& meta, int quality = 95);

}  // namespace ibl::io
