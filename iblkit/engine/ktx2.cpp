#include "iblkit/engine/ktx2.h"
#include "iblkit/core/input_file.h"

#include <Imath/half.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"

namespace ibl::engine {

uint16_t to_half(float f) { return imath_float_to_half(f); }
float from_half(uint16_t h) { return imath_half_to_float(h); }

namespace {

constexpr unsigned char kIdentifier[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
constexpr size_t kHeaderBytes = 12 + 68;  // identifier, header and index up to the level index

int channels_of(int vk_format) {
  if (vk_format == kVkFormatRgba16f) return 4;
  if (vk_format == kVkFormatRg16f) return 2;
  fail(ErrorKind::Value, "KTX2: vkFormat {} is not one iblkit writes (97 R16G16B16A16_SFLOAT, 83 R16G16_SFLOAT)",
       vk_format);
}

void put32(std::string& s, uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void set32(std::string& s, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) s[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
}
void set64(std::string& s, size_t at, uint64_t v) {
  for (int i = 0; i < 8; ++i) s[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
}
void pad_to(std::string& s, size_t align) {
  while (s.size() % align) s.push_back('\0');
}

// The basic descriptor block for nc 16-bit float channels (R, G[, B, A]).
std::string data_format_descriptor(int nc) {
  std::string d;
  const uint32_t block = 24 + 16 * nc;
  put32(d, 4 + block);                      // dfdTotalSize
  put32(d, 0);                              // vendorId 0 (Khronos), descriptorType 0 (basic)
  put32(d, 2u | (block << 16));             // versionNumber 2 (KDF 1.3), descriptorBlockSize
  put32(d, 1u | (1u << 8) | (1u << 16));    // colorModel RGBSDA, primaries BT709, transfer LINEAR, flags 0
  put32(d, 0);                              // texelBlockDimension 1×1×1×1 (stored minus one)
  put32(d, static_cast<uint32_t>(2 * nc));  // bytesPlane0
  put32(d, 0);                              // bytesPlane4..7
  constexpr uint32_t kSignedFloat = 0x40 | 0x80;
  for (int c = 0; c < nc; ++c) {
    uint32_t channel = (nc == 4 && c == 3) ? 15u : static_cast<uint32_t>(c);                   // R 0, G 1, B 2, A 15
    put32(d, static_cast<uint32_t>(16 * c) | (15u << 16) | ((channel | kSignedFloat) << 24));  // offset, length−1
    put32(d, 0);                                                                               // samplePosition 0
    put32(d, 0xBF800000u);                                                                     // sampleLower −1.0f
    put32(d, 0x3F800000u);                                                                     // sampleUpper  1.0f
  }
  return d;
}

std::string key_value(const std::string& key, const std::string& value) {
  std::string kv = key;
  kv.push_back('\0');
  kv += value;
  kv.push_back('\0');
  std::string s;
  put32(s, static_cast<uint32_t>(kv.size()));
  s += kv;
  pad_to(s, 4);
  return s;
}

void check_chain(const Ktx2Texture& t) {
  if (t.faces != 1 && t.faces != 6) fail(ErrorKind::Value, "KTX2: {} faces (1 or 6)", t.faces);
  if (t.levels.empty()) fail(ErrorKind::Value, "KTX2: no levels");
  const int w = t.width(), h = t.height();
  if (w < 1 || h < 1) fail(ErrorKind::Value, "KTX2: empty base level");
  if (t.faces == 6 && w != h) fail(ErrorKind::Value, "KTX2: cube faces must be square (got {}×{})", w, h);
  int most = 1;
  while ((std::max(w, h) >> most) >= 1) ++most;
  if (static_cast<int>(t.levels.size()) > most)
    fail(ErrorKind::Value, "KTX2: {} levels for a {}×{} base (at most {})", t.levels.size(), w, h, most);
  for (size_t m = 0; m < t.levels.size(); ++m) {
    if (static_cast<int>(t.levels[m].size()) != t.faces)
      fail(ErrorKind::Value, "KTX2: level {} has {} faces (expected {})", m, t.levels[m].size(), t.faces);
    const int lw = std::max(1, w >> m), lh = std::max(1, h >> m);
    for (const Image& im : t.levels[m])
      if (im.width() != lw || im.height() != lh)
        fail(ErrorKind::Value, "KTX2: level {} is {}×{} (expected {}×{})", m, im.width(), im.height(), lw, lh);
  }
}

std::string level_bytes(const std::vector<Image>& faces, int nc) {
  std::string s;
  for (const Image& im : faces) {
    const int ic = im.channels();
    for (size_t p = 0; p < im.pixel_count(); ++p) {
      const float* px = im.data() + p * ic;
      for (int c = 0; c < nc; ++c) {
        float v = c < ic ? px[c] : (c == 3 ? 1.0f : 0.0f);
        if (ic == 1 && c < 3) v = px[0];
        uint16_t hb = to_half(v);
        s.push_back(static_cast<char>(hb & 0xFF));
        s.push_back(static_cast<char>(hb >> 8));
      }
    }
  }
  return s;
}

}  // namespace

std::string ktx2_bytes(const Ktx2Texture& t) {
  const int nc = channels_of(t.vk_format);
  check_chain(t);
  const int n = static_cast<int>(t.levels.size());
  std::string s(reinterpret_cast<const char*>(kIdentifier), sizeof kIdentifier);
  put32(s, static_cast<uint32_t>(t.vk_format));
  put32(s, 2);  // typeSize
  put32(s, static_cast<uint32_t>(t.width()));
  put32(s, static_cast<uint32_t>(t.height()));
  put32(s, 0);  // pixelDepth
  put32(s, 0);  // layerCount (not an array)
  put32(s, static_cast<uint32_t>(t.faces));
  put32(s, static_cast<uint32_t>(n));
  put32(s, 0);  // supercompressionScheme none
  const size_t index_at = s.size();
  s.resize(s.size() + 4 * 4 + 2 * 8);  // dfd offset/length, kvd offset/length, sgd offset/length (0, 0)
  const size_t level_index_at = s.size();
  s.resize(s.size() + static_cast<size_t>(n) * 24);

  const std::string dfd = data_format_descriptor(nc);
  const size_t dfd_at = s.size();
  s += dfd;
  std::string kvd;
  if (t.faces == 1) kvd += key_value("KTXorientation", "rd");
  kvd += key_value("KTXwriter", "iblkit");
  const size_t kvd_at = s.size();
  s += kvd;
  set32(s, index_at + 0, static_cast<uint32_t>(dfd_at));
  set32(s, index_at + 4, static_cast<uint32_t>(dfd.size()));
  set32(s, index_at + 8, static_cast<uint32_t>(kvd_at));
  set32(s, index_at + 12, static_cast<uint32_t>(kvd.size()));

  const size_t align = nc == 4 ? 8 : 4;  // lcm(texel block bytes, 4)
  for (int m = n - 1; m >= 0; --m) {     // the smallest level first ([1] §3.9)
    pad_to(s, align);
    std::string lv = level_bytes(t.levels[static_cast<size_t>(m)], nc);
    set64(s, level_index_at + 24 * m + 0, s.size());
    set64(s, level_index_at + 24 * m + 8, lv.size());
    set64(s, level_index_at + 24 * m + 16, lv.size());
    s += lv;
  }
  return s;
}

void write_ktx2(const std::string& path, const Ktx2Texture& tex) { write_file_atomically(path, ktx2_bytes(tex)); }

namespace {
uint32_t get32(const std::string& s, size_t at, const std::string& path, const char* field) {
  if (at + 4 > s.size()) fail(ErrorKind::Format, "{}: KTX2 file ends inside {}", path, field);
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(static_cast<unsigned char>(s[at + i])) << (8 * i);
  return v;
}
uint64_t get64(const std::string& s, size_t at, const std::string& path, const char* field) {
  return get32(s, at, path, field) | (static_cast<uint64_t>(get32(s, at + 4, path, field)) << 32);
}
}  // namespace

Ktx2Texture read_ktx2(const std::string& path) {
  require_input_file(path, "a KTX2 texture");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(ErrorKind::Io, "{}: cannot open", path);
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (s.size() < kHeaderBytes || std::memcmp(s.data(), kIdentifier, sizeof kIdentifier) != 0)
    fail(ErrorKind::Format, "{}: not a KTX 2.0 file (identifier)", path);
  Ktx2Texture t;
  t.vk_format = static_cast<int>(get32(s, 12, path, "vkFormat"));
  if (t.vk_format != kVkFormatRgba16f && t.vk_format != kVkFormatRg16f)
    fail(ErrorKind::Format, "{}: vkFormat {} (iblkit reads 97 R16G16B16A16_SFLOAT and 83 R16G16_SFLOAT)", path,
         t.vk_format);
  const int nc = channels_of(t.vk_format);
  const uint32_t w = get32(s, 20, path, "pixelWidth"), h = std::max(1u, get32(s, 24, path, "pixelHeight"));
  if (get32(s, 28, path, "pixelDepth") != 0 || get32(s, 32, path, "layerCount") > 1)
    fail(ErrorKind::Format, "{}: 3D and array textures are not read", path);
  t.faces = static_cast<int>(get32(s, 36, path, "faceCount"));
  const uint32_t n = std::max(1u, get32(s, 40, path, "levelCount"));
  if (get32(s, 44, path, "supercompressionScheme") != 0)
    fail(ErrorKind::Format, "{}: supercompressed levels are not read", path);
  if (t.faces != 1 && t.faces != 6) fail(ErrorKind::Format, "{}: faceCount {} (1 or 6)", path, t.faces);
  if (w < 1 || w > 65536 || h > 65536 || n > 17)
    fail(ErrorKind::Format, "{}: size {}×{} with {} levels is out of range", path, w, h, n);
  for (uint32_t m = 0; m < n; ++m) {
    const uint32_t lw = std::max(1u, w >> m), lh = std::max(1u, h >> m);
    const uint64_t off = get64(s, kHeaderBytes + 24 * m, path, "level index");
    const uint64_t len = get64(s, kHeaderBytes + 24 * m + 8, path, "level index");
    const uint64_t want = uint64_t(lw) * lh * nc * 2 * t.faces;
    if (len != want || off > s.size() || len > s.size() - off)
      fail(ErrorKind::Format, "{}: level {} holds {} bytes at {} (expected {} within the file's {})", path, m, len, off,
           want, s.size());
    std::vector<Image> faces;
    size_t at = off;
    for (int f = 0; f < t.faces; ++f) {
      Image im(static_cast<int>(lw), static_cast<int>(lh), nc);
      for (size_t i = 0; i < im.size(); ++i, at += 2)
        im.data()[i] = from_half(
            static_cast<uint16_t>(static_cast<unsigned char>(s[at]) | (static_cast<unsigned char>(s[at + 1]) << 8)));
      faces.push_back(std::move(im));
    }
    t.levels.push_back(std::move(faces));
  }
  return t;
}

}  // namespace ibl::engine
