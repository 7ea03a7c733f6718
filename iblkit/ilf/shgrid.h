// An SH grid ([1] §3–4): SH coefficients of the incident radiance at the points of a regular grid,
// with trilinear lookup and the diffuse and Phong-glossy responses of [1] §4. File format .shgrid
// (docs/formats.md): line 1 "IBLKIT-SHGRID 1", line 2 a JSON header padded with spaces so
// that the data starts at a multiple of 64 bytes, then little-endian float32 values at index
// (((z·ny + y)·nx + x)·K + k)·3 + c.
#pragma once
#include <string>
#include <vector>

#include "iblkit/ilf/grid.h"
#include "iblkit/sh/coeffs.h"

namespace ibl::ilf {

class SHGrid {
 public:
  SHGrid() = default;
  SHGrid(const GridDesc& grid, int bands);

  const GridDesc& grid() const { return grid_; }
  int bands() const { return bands_; }
  // What the values are: "" radiance SH (the default); "cv-error" an error volume (ilf/crossval.h).
  const std::string& content() const { return content_; }
  void set_content(std::string c) { content_ = std::move(c); }
  int coeff_count() const { return bands_ * bands_; }
  std::vector<float>& data() { return data_; }
  const std::vector<float>& data() const { return data_; }
  // Pointer to the K·3 floats of grid point (i, j, k).
  float* at(int i, int j, int k) {
    return data_.data() + size_t((int64_t(k) * grid_.ny + j) * grid_.nx + i) * coeff_count() * 3;
  }
  const float* at(int i, int j, int k) const {
    return data_.data() + size_t((int64_t(k) * grid_.ny + j) * grid_.nx + i) * coeff_count() * 3;
  }

  // Trilinear interpolation of the coefficients at p (clamped to the volume).
  sh::Coeffs coeffs_at(Vec3 p) const;
  // Irradiance E(p, n) = ∫ L(p, ω) max(0, ω·n) dω (W/m²) from the interpolated coefficients.
  Vec3 irradiance(Vec3 p, Vec3 n) const;
  // Radiance L(p, ω) of the SH expansion (band-limited, may ring).
  Vec3 radiance(Vec3 p, Vec3 w) const;
  // Phong-glossy response around the reflection direction r ([1] §4) with the normalised lobe:
  // ∫ L(p, ω)·(s+1)/(2π)·max(0, ω·r)^s dω (a white lobe under constant radiance L returns L), the
  // lobe's zonal harmonics rotated to r (Sloan et al. 2005).
  Vec3 glossy(Vec3 p, Vec3 r, double exponent) const;

 private:
  GridDesc grid_;
  int bands_ = 0;
  std::string content_;
  std::vector<float> data_;
};

// The radiance and the Phong-glossy response (SHGrid::radiance, SHGrid::glossy) of coefficients c.
Vec3 sh_radiance(const sh::Coeffs& c, Vec3 w);
Vec3 sh_glossy(const sh::Coeffs& c, Vec3 r, double exponent);

// Reads/writes a .shgrid; errors name the file and the field.
// A file whose header names a "content" (an error volume, ilf/crossval.h) is refused unless any_content.
SHGrid read_shgrid(const std::string& path, bool any_content = false);
void write_shgrid(const std::string& path, const SHGrid& g);

// Writes the grid as OpenVDB (one Vec3f grid per coefficient named "sh_l{l}_m{m}", index space = grid
// points, a linear transform to world; metadata "iblkit_bands", "iblkit_min", "iblkit_max",
// "iblkit_resolution"). Throws ErrorKind::Unsupported in builds without OpenVDB.
void write_vdb(const std::string& path, const SHGrid& g);
bool have_vdb();

}  // namespace ibl::ilf
