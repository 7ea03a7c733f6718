// Portable float maps (.pfm): "PF" (RGB) or "Pf" (grey), width, height and a scale whose sign gives
// the byte order (negative: little-endian), each followed by one whitespace character; then 32-bit
// floats, rows bottom to top. As OpenImageIO 2.4 reads it, the scale's magnitude is not applied.
// (Debian's OpenImageIO has no PFM writer: io/image_io.cpp writes them.)
#include <bit>
#include <cctype>
#include <cstring>
#include <fstream>

#include "iblkit/core/error.h"
#include "iblkit/io/codecs.h"

namespace ibl::io::detail {

namespace {

struct PfmHeader {
  int width = 0, height = 0, channels = 0;
  bool little_endian = true;
};

// Reads one whitespace-delimited token (skipping '#' comments) and the one whitespace after it.
std::string token(std::istream& in) {
  std::string t;
  int c = in.get();
  while (c != EOF && (std::isspace(c) || c == '#')) {
    if (c == '#')
      while (c != EOF && c != '\n') c = in.get();
    c = in.get();
  }
  while (c != EOF && !std::isspace(c)) {
    t.push_back(static_cast<char>(c));
    if (t.size() > 64) break;
    c = in.get();
  }
  return t;
}

PfmHeader parse_header(std::istream& in, const std::string& path) {
  auto bad = [&](const char* why) -> PfmHeader {
    fail(ErrorKind::Format, "{}: not an image format this build reads (PFM header: {})", path, why);
  };
  PfmHeader h;
  std::string magic = token(in);
  if (magic == "PF")
    h.channels = 3;
  else if (magic == "Pf")
    h.channels = 1;
  else
    return bad("no PF/Pf magic");
  try {
    size_t used = 0;
    std::string w = token(in), ht = token(in), s = token(in);
    h.width = std::stoi(w, &used);
    if (used != w.size()) return bad("bad width");
    h.height = std::stoi(ht, &used);
    if (used != ht.size()) return bad("bad height");
    double scale = std::stod(s, &used);
    if (used != s.size() || scale == 0.0) return bad("bad scale");
    h.little_endian = scale < 0;
  } catch (const std::exception&) {
    return bad("bad number");
  }
  if (h.width <= 0 || h.height <= 0)
    fail(ErrorKind::Format, "{}: image has no pixels ({}x{}x{})", path, h.width, h.height, h.channels);
  return h;
}

std::ifstream open_or_fail(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(ErrorKind::Io, "{}: cannot open ({})", path, std::strerror(errno));
  return in;
}

}  // namespace

Header read_pfm_header(const std::string& path) {
  std::ifstream in = open_or_fail(path);
  PfmHeader h = parse_header(in, path);
  return Header{h.width, h.height, h.channels, "pnm"};
}

Decoded read_pfm(const std::string& path) {
  std::ifstream in = open_or_fail(path);
  PfmHeader h = parse_header(in, path);
  check_decoded_size(path, h.width, h.height, h.channels);
  // The pixels must be in the file before they are allocated (a 28-byte header may declare 12.9 GB).
  {
    const std::streamoff here = in.tellg();
    in.seekg(0, std::ios::end);
    const std::streamoff left = in.tellg() - here;
    in.seekg(here);
    const int64_t need = int64_t(h.width) * h.height * h.channels * int64_t(sizeof(float));
    if (left < need)
      fail(ErrorKind::Format,
           "{}: corrupt or truncated image data (the header declares {}x{}x{}: {} bytes, the file holds {})", path,
           h.width, h.height, h.channels, need, static_cast<int64_t>(left));
  }
  Decoded d;
  d.format = "pnm";
  d.image = Image(h.width, h.height, h.channels);
  const size_t row = static_cast<size_t>(h.width) * h.channels;
  for (int y = h.height - 1; y >= 0; --y) {
    float* dst = d.image.data() + static_cast<size_t>(y) * row;
    if (!in.read(reinterpret_cast<char*>(dst), static_cast<std::streamsize>(row * sizeof(float))))
      fail(ErrorKind::Format, "{}: corrupt or truncated image data (file ends inside the pixels)", path);
  }
  if (h.little_endian != (std::endian::native == std::endian::little)) {
    auto* u = reinterpret_cast<uint32_t*>(d.image.data());
    for (size_t i = 0; i < d.image.size(); ++i) u[i] = __builtin_bswap32(u[i]);
  }
  return d;
}

}  // namespace ibl::io::detail
