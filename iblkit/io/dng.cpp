#include "iblkit/io/dng.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"

namespace ibl::io {

namespace {

enum Type : uint16_t { kByte = 1, kAscii = 2, kShort = 3, kLong = 4, kRational = 5, kSRational = 10 };

struct Entry {
  uint16_t tag, type;
  uint32_t count;
  std::vector<uint8_t> bytes;  // the value, little-endian
};

void put16(std::vector<uint8_t>& b, uint16_t v) {
  b.push_back(static_cast<uint8_t>(v & 0xff));
  b.push_back(static_cast<uint8_t>(v >> 8));
}
void put32(std::vector<uint8_t>& b, uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<uint8_t>((v >> (8 * i)) & 0xff));
}

Entry shorts(uint16_t tag, std::initializer_list<uint16_t> v) {
  Entry e{tag, kShort, static_cast<uint32_t>(v.size()), {}};
  for (uint16_t x : v) put16(e.bytes, x);
  return e;
}
Entry longs(uint16_t tag, std::initializer_list<uint32_t> v) {
  Entry e{tag, kLong, static_cast<uint32_t>(v.size()), {}};
  for (uint32_t x : v) put32(e.bytes, x);
  return e;
}
Entry bytes(uint16_t tag, std::initializer_list<uint8_t> v) { return {tag, kByte, static_cast<uint32_t>(v.size()), v}; }
Entry ascii(uint16_t tag, const std::string& s) {
  Entry e{tag, kAscii, static_cast<uint32_t>(s.size() + 1), {s.begin(), s.end()}};
  e.bytes.push_back(0);
  return e;
}
// v as num/den: 1/n exactly for shutter-like times, else to 10^-6.
std::pair<uint32_t, uint32_t> rational(double v) {
  if (v > 0 && v < 1 && std::abs(1 / v - std::round(1 / v)) < 1e-6 / v)
    return {1, static_cast<uint32_t>(std::lround(1 / v))};
  if (v >= 1000) return {static_cast<uint32_t>(std::lround(v)), 1};
  return {static_cast<uint32_t>(std::lround(v * 1e6)), 1000000};
}
Entry rationals(uint16_t tag, const std::vector<double>& v) {
  Entry e{tag, kRational, static_cast<uint32_t>(v.size()), {}};
  for (double x : v) {
    const auto [n, d] = rational(x);
    put32(e.bytes, n), put32(e.bytes, d);
  }
  return e;
}
Entry srationals(uint16_t tag, const std::array<double, 9>& v) {
  Entry e{tag, kSRational, 9, {}};
  for (double x : v) {
    put32(e.bytes, static_cast<uint32_t>(static_cast<int32_t>(std::lround(x * 1000000)))), put32(e.bytes, 1000000);
  }
  return e;
}

}  // namespace

void write_dng(const std::string& path, const DngDesc& d) {
  if (d.width < 2 || d.height < 2 || d.width % 2 || d.height % 2 || d.width > 65536 || d.height > 65536)
    fail(ErrorKind::Value, "{}: a DNG mosaic of {}x{}: width and height must be even, 2 to 65536", path, d.width,
         d.height);
  const int spp = d.mosaic ? 1 : 3;
  if (d.cfa.size() != static_cast<size_t>(d.width) * d.height * spp)
    fail(ErrorKind::Value, "{}: {} sensor values for a {}x{} {}", path, d.cfa.size(), d.width, d.height,
         d.mosaic ? "mosaic" : "LinearRaw image (3 a pixel)");
  if (!(d.black >= 0 && d.black < d.white && d.white <= 65535))
    fail(ErrorKind::Value, "{}: black level {} and white level {}: need 0 <= black < white <= 65535", path, d.black,
         d.white);
  for (double n : d.as_shot_neutral)
    if (!(std::isfinite(n) && n > 0 && n <= 1e3))
      fail(ErrorKind::Value, "{}: as-shot neutral {} not in (0, 1000]", path, n);
  for (double m : d.color_matrix)
    if (!(std::isfinite(m) && std::abs(m) < 1000)) fail(ErrorKind::Value, "{}: colour matrix entry {}", path, m);
  const auto above = std::find_if(d.cfa.begin(), d.cfa.end(), [&](uint16_t v) { return v > d.white; });
  if (above != d.cfa.end())
    fail(ErrorKind::Value, "{}: sensor value {} above the white level {}", path, *above, d.white);

  if (d.cfa.size() * 2 > 0xffffffffu)
    fail(ErrorKind::Value, "{}: {}x{} is too large for one TIFF strip", path, d.width, d.height);
  const uint32_t strip_bytes = static_cast<uint32_t>(d.cfa.size() * 2);
  std::vector<Entry> e;
  e.push_back(longs(254, {0}));  // NewSubFileType: the main image
  e.push_back(longs(256, {static_cast<uint32_t>(d.width)}));
  e.push_back(longs(257, {static_cast<uint32_t>(d.height)}));
  e.push_back(d.mosaic ? shorts(258, {16}) : shorts(258, {16, 16, 16}));        // BitsPerSample
  e.push_back(shorts(259, {1}));                                                // Compression: none
  e.push_back(shorts(262, {static_cast<uint16_t>(d.mosaic ? 32803 : 34892)}));  // Photometric: CFA or LinearRaw
  if (!d.meta.make.empty()) e.push_back(ascii(271, d.meta.make));
  if (!d.meta.model.empty()) e.push_back(ascii(272, d.meta.model));
  e.push_back(longs(273, {0}));                                // StripOffsets: filled below
  e.push_back(shorts(274, {1}));                               // Orientation: top-left
  e.push_back(shorts(277, {static_cast<uint16_t>(spp)}));      // SamplesPerPixel
  e.push_back(longs(278, {static_cast<uint32_t>(d.height)}));  // RowsPerStrip: one strip
  e.push_back(longs(279, {strip_bytes}));
  e.push_back(shorts(284, {1}));  // PlanarConfiguration: chunky
  e.push_back(ascii(305, "iblkit lab"));
  if (d.mosaic) {
    e.push_back(shorts(33421, {2, 2}));       // CFARepeatPatternDim
    e.push_back(bytes(33422, {0, 1, 1, 2}));  // CFAPattern: R G / G B
  }
  // The exposure in an Exif IFD, where cameras and Adobe's converter put it (LibRaw reads the ISO only there).
  std::vector<Entry> exif;
  if (d.meta.exposure_time > 0) exif.push_back(rationals(33434, {d.meta.exposure_time}));
  if (d.meta.f_number > 0) exif.push_back(rationals(33437, {d.meta.f_number}));
  if (d.meta.iso > 0)
    exif.push_back(shorts(34855, {static_cast<uint16_t>(std::clamp(std::lround(d.meta.iso), 1L, 65535L))}));
  // The lens, where the photograph's attributes name it (capture::exif_lens_attributes): FocalLength,
  // FocalPlaneX/YResolution and their unit, FocalLengthIn35mmFilm.
  for (const PhotoAttribute& a : d.meta.attributes) {
    char* end = nullptr;
    const double v = std::strtod(a.value.c_str(), &end);
    if (end == a.value.c_str() || !(std::isfinite(v) && v > 0 && v < 1e6)) continue;
    if (a.name == "Exif:FocalLength") exif.push_back(rationals(37386, {v}));
    if (a.name == "Exif:FocalPlaneXResolution") exif.push_back(rationals(41486, {v}));
    if (a.name == "Exif:FocalPlaneYResolution") exif.push_back(rationals(41487, {v}));
    if (a.name == "Exif:FocalPlaneResolutionUnit") exif.push_back(shorts(41488, {static_cast<uint16_t>(v)}));
    if (a.name == "Exif:FocalLengthIn35mmFilm") exif.push_back(shorts(41989, {static_cast<uint16_t>(std::lround(v))}));
  }
  std::sort(exif.begin(), exif.end(), [](const Entry& a, const Entry& b) { return a.tag < b.tag; });
  if (!exif.empty()) e.push_back(longs(34665, {0}));  // ExifIFD: filled below
  e.push_back(bytes(50706, {1, 4, 0, 0}));            // DNGVersion
  e.push_back(bytes(50707, {1, 1, 0, 0}));            // DNGBackwardVersion
  const std::string camera = (d.meta.make + " " + d.meta.model);
  e.push_back(ascii(50708, camera == " " ? std::string("iblkit lab") : camera));  // UniqueCameraModel
  e.push_back(longs(50714, {static_cast<uint32_t>(d.black)}));                    // BlackLevel
  e.push_back(longs(50717, {static_cast<uint32_t>(d.white)}));                    // WhiteLevel
  e.push_back(srationals(50721, d.color_matrix));                                 // ColorMatrix1
  e.push_back(rationals(50728, {d.as_shot_neutral[0], d.as_shot_neutral[1], d.as_shot_neutral[2]}));
  e.push_back(shorts(50778, {21}));  // CalibrationIlluminant1: D65
  std::sort(e.begin(), e.end(), [](const Entry& a, const Entry& b) { return a.tag < b.tag; });

  // Header, IFD0, the Exif IFD, the values longer than 4 bytes, then the strip (2-byte aligned).
  auto ifd_bytes = [](size_t n) { return static_cast<uint32_t>(2 + 12 * n + 4); };
  const uint32_t ifd_at = 8, exif_at = ifd_at + ifd_bytes(e.size());
  const uint32_t extra_at = exif_at + (exif.empty() ? 0 : ifd_bytes(exif.size()));
  uint32_t strip_at = extra_at;
  for (const auto* list : {&e, &exif})
    for (const Entry& x : *list)
      if (x.bytes.size() > 4) strip_at += static_cast<uint32_t>((x.bytes.size() + 1) & ~size_t(1));
  std::vector<uint8_t> extra;
  auto write_ifd = [&](std::vector<Entry>& list, std::vector<uint8_t>& out) {
    put16(out, static_cast<uint16_t>(list.size()));
    for (Entry& x : list) {
      if (x.tag == 273) x.bytes.clear(), put32(x.bytes, strip_at);
      if (x.tag == 34665) x.bytes.clear(), put32(x.bytes, exif_at);
      put16(out, x.tag), put16(out, x.type), put32(out, x.count);
      if (x.bytes.size() <= 4) {
        std::vector<uint8_t> v = x.bytes;
        v.resize(4, 0);
        out.insert(out.end(), v.begin(), v.end());
      } else {
        put32(out, extra_at + static_cast<uint32_t>(extra.size()));
        extra.insert(extra.end(), x.bytes.begin(), x.bytes.end());
        if (extra.size() % 2) extra.push_back(0);
      }
    }
    put32(out, 0);  // no next IFD
  };
  std::vector<uint8_t> ifd, exif_ifd;
  write_ifd(e, ifd);
  if (!exif.empty()) write_ifd(exif, exif_ifd);
  ifd.insert(ifd.end(), exif_ifd.begin(), exif_ifd.end());
  std::vector<uint8_t> head{'I', 'I', 42, 0};
  put32(head, ifd_at);

  AtomicFile file(path);
  {
    std::ofstream f(file.temp_path(), std::ios::binary);
    if (!f) fail(ErrorKind::Io, "{}: cannot open for writing", path);
    f.write(reinterpret_cast<const char*>(head.data()), static_cast<std::streamsize>(head.size()));
    f.write(reinterpret_cast<const char*>(ifd.data()), static_cast<std::streamsize>(ifd.size()));
    f.write(reinterpret_cast<const char*>(extra.data()), static_cast<std::streamsize>(extra.size()));
    std::vector<uint8_t> strip;
    strip.reserve(strip_bytes);
    for (uint16_t v : d.cfa) put16(strip, v);
    f.write(reinterpret_cast<const char*>(strip.data()), static_cast<std::streamsize>(strip.size()));
    if (!f.flush()) fail(ErrorKind::Io, "{}: write failed (disk full?)", path);
  }
  file.commit();
}

bool is_raw_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  static const char* const kRaw[] = {".dng", ".cr2", ".cr3", ".crw", ".nef", ".nrw", ".arw", ".srf", ".sr2",
                                     ".orf", ".rw2", ".raf", ".pef", ".srw", ".x3f", ".3fr", ".erf", ".kdc",
                                     ".dcr", ".mef", ".mos", ".mrw", ".iiq", ".rwl", ".raw"};
  return std::any_of(std::begin(kRaw), std::end(kRaw), [&](const char* r) { return ext == r; });
}

}  // namespace ibl::io
