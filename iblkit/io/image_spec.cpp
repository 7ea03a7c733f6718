// io::read_image_spec: an image's size from its header, the pixels left undecoded.
#include <cstdint>
#include <filesystem>
#include <string>

#include <OpenImageIO/imageio.h>

#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"

namespace ibl::io {

ImageSpec read_image_spec(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(ErrorKind::Io, "{}: no such file", path);
  if (std::filesystem::is_directory(path, ec)) fail(ErrorKind::Io, "{}: is a folder, not an image", path);
  auto in = OIIO::ImageInput::open(path);  // reads the header only
  if (!in) {
    std::string err = OIIO::geterror();
    if (err.find("not exist") != std::string::npos || err.find("Could not open") != std::string::npos)
      fail(ErrorKind::Io, "{}: cannot open ({})", path, err);
    fail(ErrorKind::Format, "{}: not an image format this build reads ({})", path, err);
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    fail(ErrorKind::Format, "{}: image has no pixels ({}x{}x{})", path, spec.width, spec.height, spec.nchannels);
  if (static_cast<int64_t>(spec.width) * spec.height > (int64_t(1) << 30))
    fail(ErrorKind::Value, "{}: image {}x{} is too large", path, spec.width, spec.height);
  return {spec.width, spec.height, spec.nchannels};
}

}  // namespace ibl::io
