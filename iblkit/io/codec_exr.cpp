// OpenEXR files through the OpenEXR library, as OpenImageIO 2.4 reads and writes them.
// Read: part 0, its data window, channels R, G, B, Y, A in that order (OpenImageIO sorts a layer's
// channels by a list of known names: R, Red, G, Green, B, Blue, Y, …, A, …); half and float
// channels become float. Files with layers, other channel names, subsampled, integer or deep
// channels are left to OpenImageIO. Write: channels named as OpenImageIO names them (one channel
// "Y", else R, G, B, A), ZIP compression, float or half (Imath's round-to-nearest conversion).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfThreading.h>

#include "iblkit/core/error.h"
#include "iblkit/io/codecs.h"

namespace ibl::io::detail {

namespace {

// OpenImageIO decodes with a thread per core; so do we (the pool starts on the first EXR).
void use_all_cores() {
  static std::once_flag once;
  std::call_once(
      once, [] { Imf::setGlobalThreadCount(static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))); });
}

// Position of a channel name in the order OpenImageIO gives, or -1 for a name we leave to it.
int channel_rank(const std::string& name) {
  static const char* order[] = {"R", "G", "B", "Y", "A"};
  for (int i = 0; i < 5; ++i)
    if (name == order[i]) return i;
  return -1;
}

// OpenEXR allocates what a header declares before it reads a pixel: each attribute's declared size (fuzz_image: a
// 1.9 KB file whose "capDate" string declared 1.04 GB) and, when it opens the file, a line or tile buffer as wide as
// the data window (a 1.3 KB file whose 8388624 x 8 window cost 400 MB and 22 s before check_decoded_size saw it).
// Walks the header(s) as the file format lays them out — after the magic number and version, attributes of name\0
// type\0 int32 size and value, an empty name ending a header, and in a multi-part file an empty header ending the
// list — and refuses a size beyond the file's end, and a data window or tile that check_decoded_size refuses, before
// OpenEXR or OpenImageIO opens the file.
void check_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return;  // OpenEXR's open says why
  in.seekg(0, std::ios::end);
  const std::streamoff file_size = in.tellg();
  in.seekg(4);
  uint32_t version = 0;
  if (!in.read(reinterpret_cast<char*>(&version), 4)) return;
  const bool multipart = (version & 0x1000u) != 0;
  auto read_name = [&](std::string* out) {
    out->clear();
    for (char c; in.get(c);) {
      if (c == '\0') return true;
      if (out->size() >= 255) return false;
      out->push_back(c);
    }
    return false;
  };
  std::string name, type, value;
  for (;;) {  // headers
    bool empty = true;
    int64_t width = 0, height = 0, channels = 0, tile_w = 0, tile_h = 0;
    for (;;) {                        // attributes
      if (!read_name(&name)) return;  // OpenEXR reports the broken header itself
      if (name.empty()) break;        // the end of this header
      empty = false;
      int32_t size = 0;
      if (!read_name(&type) || !in.read(reinterpret_cast<char*>(&size), 4)) return;
      const std::streamoff left = file_size - in.tellg();
      if (size < 0 || size > left)
        fail(ErrorKind::Format,
             "{}: corrupt or truncated: the header's attribute '{}' ({}) declares {} bytes, {} are left in the file",
             path, name, type, size, static_cast<int64_t>(left));
      const bool window = name == "dataWindow" && type == "box2i" && size == 16;
      const bool tiles = name == "tiles" && type == "tiledesc" && size == 9;
      const bool chlist = name == "channels" && type == "chlist";
      if (!window && !tiles && !chlist) {
        in.seekg(size, std::ios::cur);
        continue;
      }
      value.resize(static_cast<size_t>(size));
      if (!in.read(value.data(), size)) return;
      if (window) {
        int32_t box[4];
        std::memcpy(box, value.data(), sizeof box);
        width = int64_t(box[2]) - box[0] + 1;
        height = int64_t(box[3]) - box[1] + 1;
      } else if (tiles) {
        uint32_t xy[2];
        std::memcpy(xy, value.data(), sizeof xy);
        tile_w = xy[0];
        tile_h = xy[1];
      } else {  // name\0 then 16 bytes per channel, an empty name at the end
        channels = 0;
        for (size_t at = 0; at < value.size() && value[at] != '\0'; ++channels) {
          const size_t end = value.find('\0', at);
          if (end == std::string::npos) break;  // OpenEXR reports the broken list
          at = end + 1 + 16;
        }
      }
    }
    if (width > 0 && height > 0) check_decoded_size(path, width, height, std::max<int64_t>(channels, 1));
    // A tile larger than the window is legal, but OpenEXR allocates its buffer whole.
    if (tile_w > 0 && tile_h > 0 && tile_w * tile_h > std::max<int64_t>(width * height, 1)) {
      const int64_t bytes = tile_w * tile_h * std::max<int64_t>(channels, 1) * int64_t(sizeof(float));
      if (tile_w * tile_h > (int64_t(1) << 30) ||
          (bytes > kAnyFileMayDecodeTo && bytes / kMaxCompression > static_cast<int64_t>(file_size)))
        fail(ErrorKind::Format,
             "{}: corrupt: its header declares {}x{} tiles for a {}x{} image, which its {} bytes cannot hold", path,
             tile_w, tile_h, width, height, static_cast<int64_t>(file_size));
    }
    if (!multipart || empty) return;  // one header, or the empty one that ends a multi-part list
  }
}

struct Layout {
  int width = 0, height = 0;
  Imath::Box2i window;
  std::vector<std::string> channels;  // in the order they are returned
};

// The layout of a file we read ourselves, or nullopt when OpenImageIO should read it.
std::optional<Layout> layout_of(const Imf::Header& h) {
  if (h.hasType() && Imf::isDeepData(h.type())) return std::nullopt;
  Layout l;
  l.window = h.dataWindow();
  l.width = l.window.max.x - l.window.min.x + 1;
  l.height = l.window.max.y - l.window.min.y + 1;
  std::vector<std::pair<int, std::string>> ranked;
  for (auto c = h.channels().begin(); c != h.channels().end(); ++c) {
    int r = channel_rank(c.name());
    const Imf::Channel& ch = c.channel();
    if (r < 0 || ch.xSampling != 1 || ch.ySampling != 1 || ch.type == Imf::UINT) return std::nullopt;
    ranked.push_back({r, c.name()});
  }
  if (ranked.empty()) return std::nullopt;
  std::sort(ranked.begin(), ranked.end());
  for (auto& [r, n] : ranked) l.channels.push_back(n);
  return l;
}

template <typename F>
auto header_step(const std::string& path, F&& f) {
  try {
    return f();
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    fail(ErrorKind::Format, "{}: not an image format this build reads ({})", path, e.what());
  }
}

}  // namespace

std::optional<Header> read_exr_header(const std::string& path) {
  check_header(path);
  return header_step(path, [&]() -> std::optional<Header> {
    Imf::InputFile file(path.c_str());
    auto l = layout_of(file.header());
    if (!l) return std::nullopt;
    return Header{l->width, l->height, static_cast<int>(l->channels.size()), "openexr"};
  });
}

std::optional<Decoded> read_exr(const std::string& path) {
  use_all_cores();
  check_header(path);
  return header_step(path, [&]() -> std::optional<Decoded> {
    Imf::InputFile file(path.c_str());
    auto l = layout_of(file.header());
    if (!l) return std::nullopt;
    if (l->width <= 0 || l->height <= 0)
      fail(ErrorKind::Format, "{}: image has no pixels ({}x{})", path, l->width, l->height);
    const int nc = static_cast<int>(l->channels.size());
    check_decoded_size(path, l->width, l->height, nc);
    Decoded d;
    d.format = "openexr";
    d.image = Image(l->width, l->height, nc);
    // The frame buffer's origin sits at the data window's corner: OpenEXR's Slice::Make takes the window and does
    // the offset itself (done here as pointer arithmetic it overflowed for a window far from 0: UBSan, fuzz_image).
    const size_t xs = sizeof(float) * nc, ys = xs * l->width;
    char* base = reinterpret_cast<char*>(d.image.data());
    Imf::FrameBuffer fb;
    for (int c = 0; c < nc; ++c)
      fb.insert(l->channels[c], Imf::Slice::Make(Imf::FLOAT, base + c * sizeof(float), l->window, xs, ys));
    file.setFrameBuffer(fb);
    try {
      file.readPixels(l->window.min.y, l->window.max.y);
    } catch (const std::exception& e) {
      fail(ErrorKind::Format, "{}: corrupt or truncated image data ({})", path, e.what());
    }
    return d;
  });
}

void write_exr(const std::string& path, const Image& img, bool half) {
  use_all_cores();
  static const char* rgba[] = {"R", "G", "B", "A"};
  const int nc = img.channels();
  if (nc > 4) fail(ErrorKind::Internal, "{}: write_exr takes 1 to 4 channels (got {})", path, nc);
  const int w = img.width(), h = img.height();
  Imf::Header header(w, h);
  header.compression() = Imf::ZIP_COMPRESSION;
  const Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
  std::vector<std::string> names;
  for (int c = 0; c < nc; ++c) names.push_back(nc == 1 ? "Y" : rgba[c]);
  for (auto& n : names) header.channels().insert(n, Imf::Channel(type));
  std::vector<Imath::half> halves;
  Imf::FrameBuffer fb;
  if (half) {
    halves.resize(img.size());
    std::transform(img.data(), img.data() + img.size(), halves.begin(), [](float v) { return Imath::half(v); });
    for (int c = 0; c < nc; ++c)
      fb.insert(names[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(halves.data() + c), sizeof(Imath::half) * nc,
                                     sizeof(Imath::half) * nc * w));
  } else {
    char* base = const_cast<char*>(reinterpret_cast<const char*>(img.data()));  // OpenEXR only reads it
    for (int c = 0; c < nc; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), sizeof(float) * nc, sizeof(float) * nc * w));
  }
  try {
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(h);
  } catch (const std::exception& e) {
    fail(ErrorKind::Io, "{}: cannot write ({})", path, e.what());
  }
}

}  // namespace ibl::io::detail
