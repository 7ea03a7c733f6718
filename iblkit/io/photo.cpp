#include "iblkit/io/photo.h"

#include <cmath>
#include <filesystem>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/input_file.h"
#include "iblkit/io/codecs.h"
#include "iblkit/io/dng.h"
#include "iblkit/io/jpeg_quality.h"

namespace ibl::io {

Photo read_photo(const std::string& path) {
  require_input_file(path, "photograph");
  if (is_raw_path(path)) return detail::raw_codec.get().read_photo(path);
  Photo p = detail::oiio_codec.get().read_photo(path);
  if (p.format == "jpeg") p.meta.jpeg_quality = estimate_jpeg_quality(path);
  return p;
}

void write_photo(const std::string& path, const Image& codes, int bits, const PhotoMeta& meta, int quality) {
  if (codes.empty() || (codes.channels() != 1 && codes.channels() != 3))
    fail(ErrorKind::Value, "{}: a photograph has 1 or 3 channels of code values (got {})", path, codes.channels());
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  const bool ok8 = ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".tif" || ext == ".tiff";
  const bool ok16 = ext == ".png" || ext == ".tif" || ext == ".tiff";
  if (!(bits == 8 ? ok8 : bits == 16 && ok16))
    fail(ErrorKind::Value, "{}: {}-bit photographs are written as {}", path, bits,
         bits == 16 ? ".tif or .png" : ".jpg, .png or .tif");
  if (quality < 1 || quality > 100) fail(ErrorKind::Value, "{}: JPEG quality {} outside [1, 100]", path, quality);
  for (size_t i = 0; i < codes.size(); ++i)
    if (!(codes.data()[i] >= 0 && codes.data()[i] <= 1))
      fail(ErrorKind::Value, "{}: code value {} outside [0, 1]", path, codes.data()[i]);
  AtomicFile file(path);
  try {
    detail::oiio_codec.get().write_photo(file.temp_path(), codes, bits, meta, quality);
  } catch (const Error& e) {
    throw file.naming_path(e);
  }
  file.commit();
}

}  // namespace ibl::io
