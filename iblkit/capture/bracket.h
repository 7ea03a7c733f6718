// A bracket of photographs read from files (issue 29 §1): code values and each frame's relative
// exposure, from Exif (ExposureTime, FNumber, ISOSpeedRatings) or given; and the merge's report as
// JSON (docs/capture.md).
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "iblkit/capture/merge.h"
#include "iblkit/io/photo.h"

namespace ibl::capture {

struct BracketDesc {
  // Given exposures, one per file: seconds (at the files' f-number and ISO when Exif has them, else
  // f/1 ISO 100), or EV steps relative to the first (relative exposure 2^step) when `ev`. Empty: from Exif.
  std::vector<double> exposures;
  bool ev = false;
};

struct Bracket {
  std::vector<Frame> frames;
  int bits = 8;
  std::string camera;           // "Make Model" from Exif, or empty
  std::string exposure_source;  // "exif", "seconds" or "ev"
  bool iso_assumed = false;     // Exif had no ISO: ISO 100 assumed
  bool linear = false;          // raw files (io/photo.h): linear codes, no response curve
  io::RawLevels raw;            // the first raw file's levels and white balance
};

// Reads every file (8-bit JPEG/PNG, 16-bit TIFF/PNG, raw files); throws ibl::Error naming the file: unreadable,
// other bit depth or camera than the first, raw and non-raw mixed, no exposure time (naming --exposures), wrong count
// of exposures.
Bracket read_bracket(const std::vector<std::string>& files, const BracketDesc& desc);

// Parses "1/250,1/60,0.5" (seconds) or "ev:-2,0,2" (EV steps) for --exposures.
BracketDesc parse_exposures(const std::string& text);

nlohmann::json report_json(const MergeReport& r, const std::vector<Frame>& frames);

}  // namespace ibl::capture
