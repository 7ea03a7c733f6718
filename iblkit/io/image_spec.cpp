// io::read_image_spec: an image's size from its header, the pixels left undecoded (through the codec
// that reads the file: our own for EXR, RGBE and PFM, OpenImageIO's plugin for the rest).
#include <cstdint>
#include <filesystem>
#include <string>

#include "iblkit/core/error.h"
#include "iblkit/core/input_file.h"
#include "iblkit/io/codecs.h"
#include "iblkit/io/image_io.h"

namespace ibl::io {

ImageSpec read_image_spec(const std::string& path) {
  require_input_file(path, "an image");  // no FIFO, device or folder reaches a codec
  const detail::Header h = detail::read_header(path);
  if (h.width <= 0 || h.height <= 0 || h.channels <= 0)
    fail(ErrorKind::Format, "{}: image has no pixels ({}x{}x{})", path, h.width, h.height, h.channels);
  if (static_cast<int64_t>(h.width) * h.height > (int64_t(1) << 30))
    fail(ErrorKind::Value, "{}: image {}x{} is too large", path, h.width, h.height);
  return {h.width, h.height, h.channels};
}

}  // namespace ibl::io
