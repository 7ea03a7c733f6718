// The .shtree file (docs/formats.md, "Adaptive SH grids"): read_adaptive, write_adaptive, read_dense.
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/ilf/adaptive.h"
#include "iblkit/ilf/grid_header.h"

namespace ibl::ilf {
using nlohmann::json;

namespace {

constexpr const char* kMagic = "IBLKIT-SHTREE 1";
constexpr const char* kLayout =
    "levels top first; per level: bricks int32 x,y,z, then each brick's values z,y,x,coefficient,channel";

int64_t brick_points(const AdaptiveGrid::Brick& b) { return int64_t(b.extent[0]) * b.extent[1] * b.extent[2]; }

// FNV-1a (64 bits) over the bytes after the header, in file order: the header's "checksum", so that a
// brick moved or a value changed in the file is found (a count or a size is checked by the sizes).
struct Fnv {
  uint64_t h = 1469598103934665603ull;
  void add(const void* p, size_t n) {
    for (const unsigned char* c = static_cast<const unsigned char*>(p); n--; ++c) h = (h ^ *c) * 1099511628211ull;
  }
  std::string hex() const { return fmt::format("{:016x}", h); }
};
std::string body_checksum(const AdaptiveGrid& g) {
  Fnv f;
  const int KC = g.coeff_count() * 3;
  for (int l = g.levels() - 1; l >= 0; --l) {
    for (const auto& b : g.level(l).bricks) f.add(b.b, 12);
    for (const auto& b : g.level(l).bricks) f.add(g.data().data() + b.offset, size_t(brick_points(b)) * KC * 4);
  }
  return f.hex();
}

// Lines 1 and 2, line 2 padded with spaces so that the data starts at a multiple of 64 bytes.
// `checksum` false: a placeholder of the same length (for the file's size).
std::string header_of(const AdaptiveGrid& g, bool checksum = true) {
  const auto& gd = g.grid();
  json counts = json::array();
  for (int l = 0; l < g.levels(); ++l) counts.push_back(g.level(l).bricks.size());
  json hdr = {{"bands", g.bands()},
              {"resolution", {gd.nx, gd.ny, gd.nz}},
              {"min", {gd.volume.min.x, gd.volume.min.y, gd.volume.min.z}},
              {"max", {gd.volume.max.x, gd.volume.max.y, gd.volume.max.z}},
              {"dtype", "float32"},
              {"brick", g.brick()},
              {"levels", g.levels()},
              {"bricks", counts},
              {"tolerance", g.tolerance()},
              {"rms", g.rms()},
              {"checksum", checksum ? body_checksum(g) : std::string(16, '0')},
              {"layout", kLayout}};
  std::string head = std::string(kMagic) + "\n" + hdr.dump();
  size_t total = ((head.size() + 1 + 63) / 64) * 64;
  head.append(total - head.size() - 1, ' ');
  head.push_back('\n');
  return head;
}

}  // namespace

size_t AdaptiveGrid::file_bytes() const {
  size_t n = header_of(*this, false).size();
  for (const auto& L : levels_) n += L.bricks.size() * 12;
  return n + data_.size() * 4;
}

void write_adaptive(const std::string& path, const AdaptiveGrid& g) {
  if (g.levels() == 0) fail(ErrorKind::Value, "{}: the adaptive SH grid is empty", path);
  const std::string head = header_of(g);
  const int KC = g.coeff_count() * 3;
  AtomicFile file(path);
  std::ofstream out(file.temp_path(), std::ios::binary);
  if (!out) fail(ErrorKind::Io, "{}: cannot write", path);
  out.write(head.data(), std::streamsize(head.size()));
  static_assert(sizeof(float) == 4 && sizeof(int32_t) == 4);
  for (int l = g.levels() - 1; l >= 0; --l) {  // x86: little-endian
    const auto& L = g.level(l);
    std::vector<int32_t> table;
    for (const auto& b : L.bricks) table.insert(table.end(), {b.b[0], b.b[1], b.b[2]});
    out.write(reinterpret_cast<const char*>(table.data()), std::streamsize(table.size() * 4));
    for (const auto& b : L.bricks)
      out.write(reinterpret_cast<const char*>(g.data().data() + b.offset),
                std::streamsize(size_t(brick_points(b)) * KC * 4));
  }
  out.close();
  if (!out) fail(ErrorKind::Io, "{}: write failed", path);
  file.commit();
}

bool is_adaptive_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;  // the reader then says what it is
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  return in && std::getline(in, magic) && magic == kMagic;
}

AdaptiveGrid read_adaptive(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(ErrorKind::Io, "{}: cannot open", path);
  size_t off = 0;
  json h = read_grid_header(in, path, kMagic, ".shtree", &off);
  auto need = [&](const char* f) { return grid_header_field(h, path, f); };
  if (need("dtype") != "float32") fail(ErrorKind::Format, "{}: header field \"dtype\" must be \"float32\"", path);
  if (need("layout") != kLayout) fail(ErrorKind::Format, "{}: header field \"layout\" is not \"{}\"", path, kLayout);
  GridDesc gd;
  int bands = 0, brick = 0, levels = 0;
  double tolerance = 0, rms = 0;
  std::vector<int64_t> counts;
  std::string checksum;
  try {
    if (h.contains("checksum")) checksum = need("checksum").get<std::string>();
    bands = static_cast<int>(grid_header_integer(need("bands"), path, "bands", 1, 16));
    brick = static_cast<int>(grid_header_integer(need("brick"), path, "brick", kMinBrick, kMaxBrick));
    levels = static_cast<int>(grid_header_integer(need("levels"), path, "levels", 1, 64));
    counts = grid_header_integers(need("bricks"), path, "bricks", 0, int64_t{1} << 40);
    tolerance = need("tolerance").get<double>();
    rms = need("rms").get<double>();
    std::vector<int> r;
    for (int64_t n : grid_header_integers(need("resolution"), path, "resolution", 0, 1 << 30))
      r.push_back(static_cast<int>(n));
    auto mn = need("min").get<std::vector<double>>(), mx = need("max").get<std::vector<double>>();
    if (r.size() != 3 || mn.size() != 3 || mx.size() != 3)
      fail(ErrorKind::Format, "{}: \"resolution\", \"min\", \"max\" need 3 values", path);
    gd.nx = r[0];
    gd.ny = r[1];
    gd.nz = r[2];
    gd.volume = {{mn[0], mn[1], mn[2]}, {mx[0], mx[1], mx[2]}};
  } catch (const json::exception& e) {
    fail(ErrorKind::Format, "{}: header field of the wrong type ({})", path, e.what());
  }
  if (off % 64 != 0) fail(ErrorKind::Format, "{}: data does not start at a multiple of 64 bytes", path);
  for (int a = 0; a < 3; ++a) {
    int n = a == 0 ? gd.nx : a == 1 ? gd.ny : gd.nz;
    if (n < 2 || n > 65536)
      fail(ErrorKind::Format, "{}: header field \"resolution\" {}x{}x{}: each axis must be in [2, 65536]", path, gd.nx,
           gd.ny, gd.nz);
  }
  if (bands < 1 || bands > 16) fail(ErrorKind::Format, "{}: header field \"bands\" = {} outside [1, 16]", path, bands);
  if (brick < kMinBrick || brick > kMaxBrick)
    fail(ErrorKind::Format, "{}: header field \"brick\" = {} outside [{}, {}]", path, brick, kMinBrick, kMaxBrick);
  if (!std::isfinite(tolerance) || tolerance < 0)
    fail(ErrorKind::Format, "{}: header field \"tolerance\" = {} is not a finite number ≥ 0", path, tolerance);
  if (!std::isfinite(rms) || rms < 0)
    fail(ErrorKind::Format, "{}: header field \"rms\" = {} is not a finite number ≥ 0", path, rms);
  if (!is_finite(gd.volume.min) || !is_finite(gd.volume.max) || !in_range(gd.volume.min) || !in_range(gd.volume.max))
    fail(ErrorKind::Format, "{}: header fields \"min\", \"max\" must be finite and within ±{:g} m", path,
         kMaxCoordinate);
  for (int a = 0; a < 3; ++a)
    if (!(gd.volume.max[a] > gd.volume.min[a]))
      fail(ErrorKind::Format, "{}: header fields \"min\", \"max\": max must exceed min on axis {}", path, "xyz"[a]);
  std::error_code ec;
  const double file_bytes = double(std::filesystem::file_size(path, ec));
  if (ec) fail(ErrorKind::Io, "{}: cannot stat ({})", path, ec.message());
  // The brick maps are a fraction 1/brick³ of the fine points: bound them by the file's size too (a
  // hostile resolution must not allocate).
  if (double(gd.count()) / (double(brick) * brick * brick) > std::max(64 * file_bytes, double(1 << 24)))
    fail(ErrorKind::Format, "{}: header field \"resolution\" {}x{}x{} is implausibly large for a file of {:.0f} bytes",
         path, gd.nx, gd.ny, gd.nz, file_bytes);
  AdaptiveGrid g(gd, bands, brick);
  g.set_tolerance(tolerance, rms);
  if (levels != g.levels())
    fail(ErrorKind::Format, "{}: header field \"levels\" = {}, but a {}x{}x{} grid has {} levels", path, levels, gd.nx,
         gd.ny, gd.nz, g.levels());
  if (counts.size() != size_t(levels))
    fail(ErrorKind::Format, "{}: header field \"bricks\" has {} entries, not one per level ({})", path, counts.size(),
         levels);
  for (int l = 0; l < levels; ++l) {
    const auto& L = g.level(l);
    if (counts[size_t(l)] < 0 || counts[size_t(l)] > int64_t(L.map.size()))
      fail(ErrorKind::Format, "{}: header field \"bricks\": level {} has {} bricks, outside [0, {}]", path, l,
           counts[size_t(l)], L.map.size());
  }
  if (counts.back() != 1)
    fail(ErrorKind::Format, "{}: header field \"bricks\": the top level needs its one brick, not {}", path,
         counts.back());
  const int KC = bands * bands * 3;
  double pos = double(off);
  in.seekg(std::streamoff(off));
  Fnv fnv;
  for (int l = levels - 1; l >= 0; --l) {
    const auto& L = g.level(l);
    const int64_t count = counts[size_t(l)];
    if (double(count) * (12 + 4.0 * KC) > file_bytes - pos)  // each brick: its entry and at least one point
      fail(ErrorKind::Format, "{}: truncated: level {}'s {} bricks need more than the {:.0f} bytes left", path, l,
           count, std::max(0.0, file_bytes - pos));
    std::vector<int32_t> table(size_t(count) * 3);
    in.read(reinterpret_cast<char*>(table.data()), std::streamsize(table.size() * 4));
    if (size_t(in.gcount()) != table.size() * 4)
      fail(ErrorKind::Format, "{}: truncated in level {}'s brick table", path, l);
    fnv.add(table.data(), table.size() * 4);
    pos += double(table.size()) * 4;
    double values = 0;
    std::vector<char> seen(L.map.size(), 0);
    for (int64_t i = 0; i < count; ++i) {
      const int32_t* b = &table[size_t(i) * 3];
      double pts = 1;
      for (int a = 0; a < 3; ++a) {
        if (b[a] < 0 || b[a] >= L.nb[a])
          fail(ErrorKind::Format, "{}: level {} brick {}: coordinates ({}, {}, {}) outside its {}x{}x{} bricks", path,
               l, i, b[0], b[1], b[2], L.nb[0], L.nb[1], L.nb[2]);
        pts *= std::min(brick, L.n[a] - b[a] * brick);
      }
      char& s = seen[size_t((int64_t(b[2]) * L.nb[1] + b[1]) * L.nb[0] + b[0])];
      if (s) fail(ErrorKind::Format, "{}: level {} brick {}: ({}, {}, {}) listed twice", path, l, i, b[0], b[1], b[2]);
      s = 1;
      values += pts * KC;
    }
    if (values * 4 > file_bytes - pos)
      fail(ErrorKind::Format, "{}: truncated: level {}'s bricks declare {:.0f} data bytes, the file holds {:.0f} more",
           path, l, values * 4, std::max(0.0, file_bytes - pos));
    for (int64_t i = 0; i < count; ++i) {
      const int32_t* b = &table[size_t(i) * 3];
      float* dst = g.add_brick(l, b[0], b[1], b[2]);
      const auto& br = g.level(l).bricks.back();
      const size_t n = size_t(brick_points(br)) * KC;
      in.read(reinterpret_cast<char*>(dst), std::streamsize(n * 4));
      if (size_t(in.gcount()) != n * 4) fail(ErrorKind::Format, "{}: truncated in level {} brick {}", path, l, i);
      fnv.add(dst, n * 4);
      for (size_t q = 0; q < n; ++q)
        if (!std::isfinite(dst[q]))
          fail(ErrorKind::Value, "{}: level {} brick {}: value {} is not finite", path, l, i, q);
      pos += double(n) * 4;
    }
  }
  // Every byte accounted for: a count one short leaves bytes behind, and bytes appended are no part of it.
  if (pos != file_bytes)
    fail(ErrorKind::Format,
         "{}: {:.0f} bytes after the last brick (the header's \"bricks\" counts {:.0f} bytes of "
         "bricks; the file is longer): refused",
         path, file_bytes - pos, pos - double(off));
  if (!checksum.empty() && checksum != fnv.hex())
    fail(ErrorKind::Format,
         "{}: the bricks do not match the header's checksum {} (they hash to {}): the file was changed "
         "after it was written",
         path, checksum, fnv.hex());
  return g;
}

SHGrid read_dense(const std::string& path) {
  return is_adaptive_file(path) ? read_adaptive(path).to_dense() : read_shgrid(path);
}

}  // namespace ibl::ilf
