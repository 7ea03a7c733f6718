// The quality a JPEG was saved with, estimated from its luminance quantisation table: libjpeg (and most
// cameras' encoders) scale the example table of ITU-T T.81 Annex K (Table K.1) by
// s = q < 50 ? 5000 / q : 200 − 2q, each entry ⌊(K·s + 50) / 100⌋ clamped to [1, 255]. The estimate is
// the q in 1..100 whose scaled table is nearest (sum of absolute differences) to the file's table 0, so a
// photograph rewritten at its own quality keeps its compression. An encoder with tables of its own gets
// the nearest libjpeg quality.
#pragma once
#include <string>

namespace ibl::io {

// 1..100; 0 when the file is not a JPEG or carries no luminance table. Reads the markers only.
int estimate_jpeg_quality(const std::string& path);

// The same for an 8-bit table in natural (row-major) order (64 entries), or 0 for a table of zeros.
int jpeg_quality_of_table(const int table[64]);

}  // namespace ibl::io
