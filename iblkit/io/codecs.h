// The image codecs behind io/image_io.h (internal to io/). iblkit reads and writes the formats of
// its everyday work itself — OpenEXR through the OpenEXR library, Radiance RGBE and PFM by hand, PNG
// output through libpng — and hands everything else (PNG/JPEG/TIFF/… input, JPEG/TIFF/… output,
// text in pictures) to OpenImageIO, which sits in the "oiio" plugin (core/plugin.h) because it
// brings ~250 shared libraries with it. Each own codec gives the pixels OpenImageIO 2.4 gives
// (codecs_test.cpp compares them file by file); a file it does not handle exactly the same way (an
// EXR with layers or integer channels, an RGBE file stored in another orientation, …) goes to
// OpenImageIO too.
#pragma once
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

#include "iblkit/core/error.h"
#include "iblkit/core/image.h"
#include "iblkit/core/plugin.h"
#include "iblkit/io/photo.h"

namespace ibl::io::detail {

// Pixels as a codec decodes them, before image_io's common steps (sRGB decoding, channel limit,
// pixel check).
struct Decoded {
  Image image;
  bool srgb = false;   // 8/16-bit data in sRGB encoding: image_io decodes it to linear
  std::string format;  // OpenImageIO's name of the format: "openexr", "hdr", "pnm", "png", …
};

// Size and channel count from the header alone.
struct Header {
  int width = 0, height = 0, channels = 0;
  std::string format;
};

// What every decoder checks before it allocates the pixels a header declares: at most 2^30 pixels, and no more
// decoded bytes (channels × 4) than the file could hold at kMaxCompression : 1, above a floor of
// kAnyFileMayDecodeTo (fuzz_image: a 1.9 KB EXR header declared an image that OpenEXR allocated 1 GB for before
// it found the pixels missing). ZIP's deflate stops near 1032 : 1 and RLE near 64 : 1, on half floats; the decoded
// floats are twice those. Throws ibl::Error naming the file.
inline constexpr int64_t kMaxCompression = 4096;
inline constexpr int64_t kAnyFileMayDecodeTo = int64_t(256) << 20;
inline void check_decoded_size(const std::string& path, int64_t width, int64_t height, int64_t channels) {
  if (width * height > (int64_t(1) << 30)) fail(ErrorKind::Value, "{}: image {}x{} is too large", path, width, height);
  const int64_t bytes = width * height * std::max<int64_t>(channels, 1) * int64_t(sizeof(float));
  std::error_code ec;
  const auto file = std::filesystem::file_size(path, ec);
  if (!ec && bytes > kAnyFileMayDecodeTo && bytes / kMaxCompression > static_cast<int64_t>(file))
    fail(ErrorKind::Format,
         "{}: corrupt or truncated: its header declares a {}x{} image of {} channels ({} MB of pixels), which its {} "
         "bytes "
         "cannot hold",
         path, width, height, channels, bytes >> 20, static_cast<int64_t>(file));
}

// What a file is, from its first bytes.
enum class FileKind { OpenExr, Rgbe, Pfm, Other };
FileKind sniff(const std::string& path);

// The file decoded by our own codec for its kind, or nullopt when it is for OpenImageIO; and the
// header of any image file through the codec that reads it (both defined in image_io.cpp).
std::optional<Decoded> read_own(const std::string& path);
Header read_header(const std::string& path);

// Own codecs. read_* return std::nullopt for a valid file they leave to OpenImageIO; they throw
// ibl::Error naming the file for a broken one. Writers throw ibl::Error on failure.
std::optional<Decoded> read_exr(const std::string& path);
std::optional<Header> read_exr_header(const std::string& path);
std::optional<Decoded> read_rgbe(const std::string& path);
std::optional<Header> read_rgbe_header(const std::string& path);
Decoded read_pfm(const std::string& path);
Header read_pfm_header(const std::string& path);
void write_exr(const std::string& path, const Image& img, bool half);  // every channel, ZIP compression
void write_rgbe(const std::string& path, const Image& img);            // 3 channels
// 8 bits per channel, grey or RGB, or either with alpha (which is stored as it is: unassociated, as
// PNG defines it); `img` holds values in [0, 1] already encoded (sRGB): each becomes round(255·v).
// srgb: tag the file as sRGB-encoded (pictures); false for data textures.
void write_png(const std::string& path, const Image& img, bool srgb = true);

// OpenImageIO's side, provided by the oiio plugin (io/codec_oiio.cpp).
struct OiioCodec {
  Decoded (*read)(const std::string& path);
  Header (*read_header)(const std::string& path);
  // Writes `img` (already converted as image_io's write_image documents) in the format of the
  // extension: 8-bit when `ldr`, half floats when `half`.
  void (*write)(const std::string& path, const Image& img, bool ldr, bool half);
  // Draws text as io/draw.h's draw_text documents, with the TrueType font at `font`.
  bool (*draw_text)(Image& img, int x, int y, const std::string& text, int size, const char* font, Vec3 rgb);
  // A photograph's code values and Exif exposure data (io/photo.h), and the writer of one.
  Photo (*read_photo)(const std::string& path);
  void (*write_photo)(const std::string& path, const Image& codes, int bits, const PhotoMeta& meta, int quality);
};
extern plugin::Provided<OiioCodec> oiio_codec;

// Raw files through LibRaw (the "raw" plugin, libiblkit_raw.so; codec_raw.cpp): io/photo.h's read_photo
// for a path dng.h's is_raw_path names.
struct RawCodec {
  Photo (*read_photo)(const std::string& path);
};
extern plugin::Provided<RawCodec> raw_codec;

}  // namespace ibl::io::detail
