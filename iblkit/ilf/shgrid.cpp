#include "iblkit/ilf/shgrid.h"
#include "iblkit/core/input_file.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/ilf/grid_header.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sh/convolve.h"

namespace ibl::ilf {
using nlohmann::json;

SHGrid::SHGrid(const GridDesc& grid, int bands) : grid_(grid), bands_(bands) {
  if (grid.nx < 2 || grid.ny < 2 || grid.nz < 2)
    fail(ErrorKind::Value, "SH grid: resolution {}x{}x{} must be at least 2 per axis", grid.nx, grid.ny, grid.nz);
  if (bands < 1 || bands > 16) fail(ErrorKind::Value, "SH grid: bands = {} outside [1, 16]", bands);
  for (int a = 0; a < 3; ++a)
    if (!(grid.volume.max[a] > grid.volume.min[a]))
      fail(ErrorKind::Value, "SH grid: volume max must exceed min on axis {}", "xyz"[a]);
  require_box("SH grid: volume", grid.volume.min, grid.volume.max, true);
  require_allocation(fmt::format("SH grid: {}x{}x{} points of {} bands", grid.nx, grid.ny, grid.nz, bands),
                     double(grid.count()) * bands * bands * 3, sizeof(float), "choose a coarser grid or fewer bands");
  data_.assign(size_t(grid.count()) * coeff_count() * 3, 0.0f);
}

sh::Coeffs SHGrid::coeffs_at(Vec3 p) const {
  int K = coeff_count();
  if (!is_finite(p)) fail(ErrorKind::Value, "SH grid lookup: the point ({}, {}, {}) is not finite", p.x, p.y, p.z);
  sh::Coeffs out;
  out.bands = bands_;
  out.c.assign(size_t(K), Vec3{0, 0, 0});
  if (data_.empty()) return out;  // a default-constructed grid: no coefficients
  Vec3 s = grid_.volume.size();
  double f[3] = {(p.x - grid_.volume.min.x) / s.x * (grid_.nx - 1), (p.y - grid_.volume.min.y) / s.y * (grid_.ny - 1),
                 (p.z - grid_.volume.min.z) / s.z * (grid_.nz - 1)};
  int n[3] = {grid_.nx, grid_.ny, grid_.nz}, i0[3];
  double t[3];
  for (int a = 0; a < 3; ++a) {
    if (std::isnan(f[a])) f[a] = 0;  // unreachable for grids within the checked range; keeps the index defined
    f[a] = std::clamp(f[a], 0.0, double(n[a] - 1));
    i0[a] = std::min(int(f[a]), n[a] - 2);
    t[a] = f[a] - i0[a];
  }
  for (int c = 0; c < 8; ++c) {
    double w = ((c & 1) ? t[0] : 1 - t[0]) * ((c & 2) ? t[1] : 1 - t[1]) * ((c & 4) ? t[2] : 1 - t[2]);
    if (w == 0) continue;
    const float* src = at(i0[0] + (c & 1), i0[1] + ((c >> 1) & 1), i0[2] + (c >> 2));
    for (int k = 0; k < K; ++k) out.c[k] += Vec3(src[3 * k], src[3 * k + 1], src[3 * k + 2]) * w;
  }
  return out;
}

Vec3 SHGrid::irradiance(Vec3 p, Vec3 n) const { return sh::irradiance_at(coeffs_at(p), normalize(n)); }

Vec3 SHGrid::radiance(Vec3 p, Vec3 w) const { return sh_radiance(coeffs_at(p), w); }

Vec3 sh_radiance(const sh::Coeffs& c, Vec3 w) {
  std::vector<double> y(c.c.size());
  sh::eval_basis(c.bands, normalize(w), y.data());
  Vec3 r{0, 0, 0};
  for (size_t k = 0; k < c.c.size(); ++k) r += c.c[k] * y[k];
  return r;
}

// ∫ L(ω) h(ω·r) dω for a zonal kernel h with convolution factors Λ_l (sh/convolve.h, Funk–Hecke):
// Σ_lm Λ_l·c_lm·Y_lm(r) — the zonal harmonic rotated to r (Sloan et al. 2005, eq. 1).
Vec3 SHGrid::glossy(Vec3 p, Vec3 r, double exponent) const {
  if (!(exponent >= 0)) fail(ErrorKind::Value, "glossy: Phong exponent {} must be ≥ 0", exponent);
  return sh_glossy(coeffs_at(p), r, exponent);
}

Vec3 sh_glossy(const sh::Coeffs& c, Vec3 r, double exponent) {
  if (!(exponent >= 0)) fail(ErrorKind::Value, "glossy: Phong exponent {} must be ≥ 0", exponent);
  auto z = sh::phong_zh(c.bands, exponent);
  std::vector<double> y(c.c.size());
  sh::eval_basis(c.bands, normalize(r), y.data());
  Vec3 out{0, 0, 0};
  for (int l = 0; l < c.bands; ++l) {
    double s = z[l];
    for (int m = -l; m <= l; ++m) out += c.c[sh::index(l, m)] * (s * y[sh::index(l, m)]);
  }
  return out;
}

void write_shgrid(const std::string& path, const SHGrid& g) {
  const auto& gd = g.grid();
  json hdr = {{"bands", g.bands()},
              {"resolution", {gd.nx, gd.ny, gd.nz}},
              {"min", {gd.volume.min.x, gd.volume.min.y, gd.volume.min.z}},
              {"max", {gd.volume.max.x, gd.volume.max.y, gd.volume.max.z}},
              {"dtype", "float32"},
              {"layout", "z,y,x,coefficient,channel"}};
  if (!g.content().empty()) hdr["content"] = g.content();
  std::string head = "IBLKIT-SHGRID 1\n" + hdr.dump();
  size_t total = ((head.size() + 1 + 63) / 64) * 64;
  head.append(total - head.size() - 1, ' ');
  head.push_back('\n');
  AtomicFile file(path);
  std::ofstream out(file.temp_path(), std::ios::binary);
  if (!out) fail(ErrorKind::Io, "{}: cannot write", path);
  out.write(head.data(), std::streamsize(head.size()));
  static_assert(sizeof(float) == 4);
  out.write(reinterpret_cast<const char*>(g.data().data()),
            std::streamsize(g.data().size() * 4));  // x86: little-endian
  out.close();
  if (!out) fail(ErrorKind::Io, "{}: write failed", path);
  file.commit();
}

SHGrid read_shgrid(const std::string& path, bool any_content) {
  require_input_file(path, "an SH grid");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(ErrorKind::Io, "{}: cannot open", path);
  size_t off = 0;
  json h = read_grid_header(in, path, "IBLKIT-SHGRID 1", ".shgrid", &off);
  auto need = [&](const char* f) { return grid_header_field(h, path, f); };
  if (need("dtype") != "float32") fail(ErrorKind::Format, "{}: header field \"dtype\" must be \"float32\"", path);
  if (need("layout") != "z,y,x,coefficient,channel")
    fail(ErrorKind::Format, "{}: header field \"layout\" is not \"z,y,x,coefficient,channel\"", path);
  GridDesc gd;
  int bands = 0;
  try {
    bands = static_cast<int>(grid_header_integer(need("bands"), path, "bands", 1, 16));
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
  if (gd.nx < 2 || gd.ny < 2 || gd.nz < 2)
    fail(ErrorKind::Format, "{}: header field \"resolution\" {}x{}x{} must be at least 2 per axis", path, gd.nx, gd.ny,
         gd.nz);
  if (bands < 1 || bands > 16) fail(ErrorKind::Format, "{}: header field \"bands\" = {} outside [1, 16]", path, bands);
  if (!is_finite(gd.volume.min) || !is_finite(gd.volume.max) || !in_range(gd.volume.min) || !in_range(gd.volume.max))
    fail(ErrorKind::Format,
         "{}: header fields \"min\", \"max\" ({}, {}, {})–({}, {}, {}) must be finite and within ±{:g} m", path,
         gd.volume.min.x, gd.volume.min.y, gd.volume.min.z, gd.volume.max.x, gd.volume.max.y, gd.volume.max.z,
         kMaxCoordinate);
  {  // the declared size against the file's, before anything is allocated
    std::error_code ec;
    const double file_bytes = double(std::filesystem::file_size(path, ec));
    const double want = double(gd.count()) * bands * bands * 3 * 4;
    if (!ec && want > file_bytes - double(off))
      fail(ErrorKind::Format,
           "{}: truncated: the header declares {}x{}x{} points of {} bands ({:.0f} data bytes), the file holds {:.0f}",
           path, gd.nx, gd.ny, gd.nz, bands, want, std::max(0.0, file_bytes - double(off)));
    if (!ec && want < file_bytes - double(off))
      fail(ErrorKind::Format,
           "{}: {:.0f} bytes after the data the header declares ({}x{}x{} points of {} bands): refused", path,
           file_bytes - double(off) - want, gd.nx, gd.ny, gd.nz, bands);
  }
  SHGrid g(gd, bands);
  if (h.contains("content")) {
    if (!h["content"].is_string()) fail(ErrorKind::Format, "{}: header field \"content\" is not a string", path);
    g.set_content(h["content"].get<std::string>());
    if (!any_content && !g.content().empty())
      fail(ErrorKind::Format, "{}: holds \"{}\", not radiance SH (an error volume: `iblkit ilf slice` shows it)", path,
           g.content());
  }
  size_t n = g.data().size();
  in.read(reinterpret_cast<char*>(g.data().data()), std::streamsize(n * 4));
  if (size_t(in.gcount()) != n * 4)
    fail(ErrorKind::Format, "{}: truncated: {} of {} data bytes", path, in.gcount(), n * 4);
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(g.data()[i])) fail(ErrorKind::Value, "{}: value {} is not finite", path, i);
  return g;
}

}  // namespace ibl::ilf
