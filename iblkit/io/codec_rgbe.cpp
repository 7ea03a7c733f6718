// Radiance RGBE (.hdr) files, as OpenImageIO 2.4 reads and writes them (Ward, "Real pixels",
// Graphics Gems II; the file layout of Radiance's color.c and B. Walter's rgbe.c).
//
// Header: "#?" program line, variable lines up to an empty line, then the resolution line. We read
// "-Y H +X W" (rows top to bottom, the layout every probe uses); other orientations and XYZE data
// go to OpenImageIO. Scanlines 8…32767 wide may be run-length encoded per channel ("2 2 hi lo"
// then, for each of the four channels, runs: n > 128 repeats the next byte n − 128 times,
// n ≤ 128 copies n bytes); a first scanline that does not start so means flat pixels throughout.
//
// Pixel (R, G, B, E) with E ≠ 0 decodes to (R, G, B)·2^(E − 136), 0 otherwise (no ½ offset).
// Encoding: m = max(r, g, b); m < 1e−32 gives zero; else m = f·2^e with f in [½, 1) and each
// channel becomes ⌊c·256·f/m⌋ = ⌊c·2^(8−e)⌋, E = e + 128: truncation loses less than 2^(e−8),
// i.e. less than 1/128 of m.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "iblkit/core/error.h"
#include "iblkit/io/codecs.h"

namespace ibl::io::detail {

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

File open_or_fail(const std::string& path) {
  File f(std::fopen(path.c_str(), "rb"));
  if (!f) fail(ErrorKind::Io, "{}: cannot open ({})", path, std::strerror(errno));
  return f;
}

bool read_line(std::FILE* f, std::string& line) {
  line.clear();
  int c;
  while ((c = std::fgetc(f)) != EOF && c != '\n') {
    line.push_back(static_cast<char>(c));
    if (line.size() > 4096) return false;
  }
  return c != EOF || !line.empty();
}

// Reads the header; returns false when the file is valid for OpenImageIO but not in our layout.
bool read_header(std::FILE* f, const std::string& path, int& w, int& h) {
  std::string line;
  if (!read_line(f, line) || line.rfind("#?", 0) != 0)
    fail(ErrorKind::Format, "{}: not an image format this build reads (no Radiance '#?' header line)", path);
  bool keep = true;
  while (true) {
    if (!read_line(f, line))
      fail(ErrorKind::Format, "{}: not an image format this build reads (header ends early)", path);
    if (line.empty()) break;
    if (line.rfind("FORMAT=", 0) == 0 && line != "FORMAT=32-bit_rle_rgbe") keep = false;
  }
  if (!read_line(f, line))
    fail(ErrorKind::Format, "{}: not an image format this build reads (no resolution line)", path);
  char a[3] = {}, b[3] = {};
  int n1 = 0, n2 = 0;
  if (std::sscanf(line.c_str(), "%2s %d %2s %d", a, &n1, b, &n2) != 4)
    fail(ErrorKind::Format, "{}: not an image format this build reads (bad resolution line '{}')", path, line);
  if (std::strcmp(a, "-Y") != 0 || std::strcmp(b, "+X") != 0) keep = false;
  if (n1 <= 0 || n2 <= 0) fail(ErrorKind::Format, "{}: image has no pixels ({}x{}x3)", path, n2, n1);
  h = n1;
  w = n2;
  return keep;
}

void rgbe_to_float(const unsigned char* p, float* out) {
  if (p[3] == 0) {
    out[0] = out[1] = out[2] = 0.0f;
    return;
  }
  const float f = std::ldexp(1.0f, static_cast<int>(p[3]) - (128 + 8));
  out[0] = p[0] * f;
  out[1] = p[1] * f;
  out[2] = p[2] * f;
}

[[noreturn]] void corrupt(const std::string& path, const char* why) {
  fail(ErrorKind::Format, "{}: corrupt or truncated image data ({})", path, why);
}

// Decodes all scanlines, the rest of the file read at once, into `img` (RGB float).
void read_pixels(std::FILE* f, const std::string& path, Image& img) {
  std::vector<unsigned char> data;
  unsigned char chunk[1 << 16];
  for (size_t n; (n = std::fread(chunk, 1, sizeof chunk, f)) > 0;) data.insert(data.end(), chunk, chunk + n);
  const unsigned char* p = data.data();
  const unsigned char* end = p + data.size();
  const int w = img.width(), h = img.height();
  const size_t total = static_cast<size_t>(w) * h;
  float* out = img.data();
  auto read_flat = [&](size_t from_pixel) {
    if (static_cast<size_t>(end - p) < (total - from_pixel) * 4) corrupt(path, "file ends inside the pixels");
    for (size_t i = from_pixel; i < total; ++i, p += 4) rgbe_to_float(p, out + i * 3);
  };
  if (w < 8 || w > 0x7fff) return read_flat(0);
  std::vector<unsigned char> line(static_cast<size_t>(w) * 4);
  for (int y = 0; y < h; ++y) {
    if (end - p < 4) corrupt(path, "file ends inside the pixels");
    if (p[0] != 2 || p[1] != 2 || (p[2] & 0x80)) {
      // Not run-length encoded: the file holds flat pixels from here.
      if (y != 0) corrupt(path, "scanline without its run-length header");
      return read_flat(0);
    }
    if (((p[2] << 8) | p[3]) != w) corrupt(path, "wrong scanline width");
    p += 4;
    for (int c = 0; c < 4; ++c) {
      for (int x = 0; x < w;) {
        if (p == end) corrupt(path, "file ends inside the pixels");
        int n = *p++;
        if (n > 128) {
          n -= 128;
          if (p == end) corrupt(path, "file ends inside the pixels");
          if (n > w - x) corrupt(path, "bad scanline data");
          for (unsigned char v = *p++; n > 0; --n) line[static_cast<size_t>(x++) * 4 + c] = v;
        } else {
          if (n == 0 || n > w - x) corrupt(path, "bad scanline data");
          if (end - p < n) corrupt(path, "file ends inside the pixels");
          for (; n > 0; --n) line[static_cast<size_t>(x++) * 4 + c] = *p++;
        }
      }
    }
    float* row = out + static_cast<size_t>(y) * w * 3;
    for (int x = 0; x < w; ++x) rgbe_to_float(&line[static_cast<size_t>(x) * 4], row + x * 3);
  }
}

void float_to_rgbe(const float* c, unsigned char* p) {
  float v = c[0];
  if (c[1] > v) v = c[1];
  if (c[2] > v) v = c[2];
  if (!(v >= 1e-32f)) {  // also NaN
    p[0] = p[1] = p[2] = p[3] = 0;
    return;
  }
  int e;
  v = static_cast<float>(std::frexp(v, &e) * 256.0 / v);
  for (int k = 0; k < 3; ++k) {
    float s = c[k] * v;
    p[k] = s > 0.0f ? static_cast<unsigned char>(s) : 0;  // negative values are not representable
  }
  p[3] = static_cast<unsigned char>(e + 128);
}

// One channel of a scanline, run-length encoded: runs of 4 or more equal bytes as runs, the rest as
// literal blocks of up to 128.
void encode_channel(const unsigned char* v, int n, int stride, std::vector<unsigned char>& out) {
  int x = 0;
  while (x < n) {
    int run = 1;
    while (x + run < n && run < 127 && v[(x + run) * stride] == v[x * stride]) ++run;
    if (run >= 4) {
      out.push_back(static_cast<unsigned char>(128 + run));
      out.push_back(v[x * stride]);
      x += run;
      continue;
    }
    // Literal block up to the next run of 4.
    int start = x, len = 0;
    while (x < n && len < 128) {
      int r = 1;
      while (x + r < n && r < 4 && v[(x + r) * stride] == v[x * stride]) ++r;
      if (r >= 4) break;
      ++x;
      ++len;
    }
    out.push_back(static_cast<unsigned char>(len));
    for (int k = 0; k < len; ++k) out.push_back(v[(start + k) * stride]);
  }
}

}  // namespace

std::optional<Header> read_rgbe_header(const std::string& path) {
  File f = open_or_fail(path);
  int w = 0, h = 0;
  if (!read_header(f.get(), path, w, h)) return std::nullopt;
  return Header{w, h, 3, "hdr"};
}

std::optional<Decoded> read_rgbe(const std::string& path) {
  File f = open_or_fail(path);
  int w = 0, h = 0;
  if (!read_header(f.get(), path, w, h)) return std::nullopt;
  check_decoded_size(path, w, h, 3);
  // Every scanline takes at least 4 bytes in any RGBE encoding: check the file can hold the rows the
  // header declares before allocating them (a 60-byte header may declare 10.8 GB).
  {
    const long here = std::ftell(f.get());
    std::fseek(f.get(), 0, SEEK_END);
    const long left = std::ftell(f.get()) - here;
    std::fseek(f.get(), here, SEEK_SET);
    if (here < 0 || left < 4L * h)
      fail(ErrorKind::Format,
           "{}: corrupt or truncated image data (the header declares {} rows, the file holds {} bytes of pixels)", path,
           h, left);
  }
  Decoded d;
  d.format = "hdr";
  d.image = Image(w, h, 3);
  read_pixels(f.get(), path, d.image);
  return d;
}

void write_rgbe(const std::string& path, const Image& img) {
  if (img.channels() != 3) fail(ErrorKind::Internal, "{}: write_rgbe takes 3 channels (got {})", path, img.channels());
  const int w = img.width(), h = img.height();
  File f(std::fopen(path.c_str(), "wb"));
  if (!f) fail(ErrorKind::Io, "{}: cannot write ({})", path, std::strerror(errno));
  std::string head = fmt::format("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {} +X {}\n", h, w);
  bool ok = std::fwrite(head.data(), 1, head.size(), f.get()) == head.size();
  const bool rle = w >= 8 && w <= 0x7fff;
  std::vector<unsigned char> px(static_cast<size_t>(w) * 4), out;
  for (int y = 0; y < h && ok; ++y) {
    const float* row = img.data() + static_cast<size_t>(y) * w * 3;
    for (int x = 0; x < w; ++x) float_to_rgbe(row + x * 3, &px[static_cast<size_t>(x) * 4]);
    out.clear();
    if (rle) {
      out.insert(out.end(), {2, 2, static_cast<unsigned char>(w >> 8), static_cast<unsigned char>(w & 0xff)});
      for (int c = 0; c < 4; ++c) encode_channel(px.data() + c, w, 4, out);
    } else {
      out = px;
    }
    ok = std::fwrite(out.data(), 1, out.size(), f.get()) == out.size();
  }
  ok = (std::fclose(f.release()) == 0) && ok;
  if (!ok) fail(ErrorKind::Io, "{}: write failed", path);
}

}  // namespace ibl::io::detail
