// The lab's raw files: a Bayer mosaic written as a DNG 1.4 (Adobe's Digital Negative, a TIFF), the
// format every raw reader takes, so that the lab's camera can hand `hdr merge` and `composite` what a
// real camera's raw file holds: sensor values with a black and a white level, the as-shot white
// balance, a colour matrix and the exposure (TIFF/EP tags in the main IFD). Written by hand (a TIFF
// with one uncompressed strip): no library writes DNG. Read through LibRaw (io/photo.h's read_photo).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "iblkit/io/photo.h"

namespace ibl::io {

struct DngDesc {
  int width = 0, height = 0;  // even, so that the 2×2 pattern tiles the image
  // The sensor values, row-major: with `mosaic` width × height of an RGGB Bayer pattern ((0,0) red, (1,0) and
  // (0,1) green); else LinearRaw, 3 a pixel (R, G, B interleaved).
  std::vector<uint16_t> cfa;
  bool mosaic = true;
  int black = 0, white = 0;  // BlackLevel and WhiteLevel; 0 <= black < white <= 65535
  // AsShotNeutral: the camera's raw values of a neutral (white-balance multipliers are their inverses).
  std::array<double, 3> as_shot_neutral{1, 1, 1};
  // ColorMatrix1 (XYZ -> camera, row-major), under CalibrationIlluminant1 D65. Default: the inverse of
  // linear sRGB's (Rec. 709 primaries, D65) RGB -> XYZ, so a camera whose channels are linear sRGB's.
  std::array<double, 9> color_matrix{3.2404542, -1.5371385, -0.4985314, -0.9692660, 1.8760108,
                                     0.0415560, 0.0556434,  -0.2040259, 1.0572252};
  // Exposure time, f-number, ISO, make, model, and of the other attributes the lens's Exif ones
  // (Exif:FocalLength, Exif:FocalPlaneX/YResolution, Exif:FocalPlaneResolutionUnit, Exif:FocalLengthIn35mmFilm).
  PhotoMeta meta;
};

// Writes the DNG through an AtomicFile; throws ibl::Error naming the file (sizes, levels, a value above
// the white level).
void write_dng(const std::string& path, const DngDesc& d);

// Whether the path names a raw file by its extension (.dng, .cr2, .cr3, .nef, .arw, .orf, .rw2, .raf,
// .pef, .srw, … as LibRaw reads them); such files go to the raw plugin.
bool is_raw_path(const std::string& path);

}  // namespace ibl::io
