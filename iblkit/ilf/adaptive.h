// An adaptive SH grid (docs/ilf.md "Adaptive storage"; Löw et al. 2009 §5.3, §6): the coefficients of a dense fine grid
// (SHGrid) kept at full resolution only where a coarser level's trilinear interpolation misses them.
// Level 0 is the fine grid, level l+1 halves level l's resolution (every 2^l-th fine point per axis,
// the last fine point always included), up to the top level of 2 points per axis. Each level's points
// are stored in bricks of `brick`³ points (fewer at the level's far faces; no point stored twice).
// A lookup answers from the finest level whose cell around the point has all 8 corners stored,
// trilinearly there; so where level 0 is kept it returns exactly what the fine SHGrid returns (bit for
// bit; within rounding closer than 1e-7 cells to a grid point, where the cell is chosen as that
// point's). make_adaptive, top down, stores the corner bricks of a level's cell wherever the
// interpolant the levels above answer with in a fine cell misses the fine values at one of its corners
// by more than tolerance · (RMS over the fine points of the coefficient vector's L2 norm): the lookup is
// then within that bound of the fine grid's trilinear lookup everywhere in the volume (so the relative
// L2 difference at the fine points is at most `tolerance`); bricks no lookup reaches are left out.
// Across a face between cells answered at different levels the lookup may jump (by ≤ 2 · the bound).
// File format .shtree (docs/formats.md): like .shgrid, a magic line, a JSON header padded to 64
// bytes, then per level (top first) the brick table (int32) and the bricks' float32 values.
// Renderers take a dense grid: to_dense (read_dense) resamples, the GL path (docs/ilf.md).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "iblkit/ilf/shgrid.h"

namespace ibl::ilf {

inline constexpr int kMinBrick = 2, kMaxBrick = 16;

struct AdaptDesc {
  double tolerance = 0.01;  // per fine point: ‖coefficients − fine‖₂ ≤ tolerance · RMS of ‖fine‖₂
  int brick = 4;            // points per brick axis, in [kMinBrick, kMaxBrick]
};

class AdaptiveGrid {
 public:
  struct Brick {
    int b[3];       // brick coordinates in the level's brick grid
    int extent[3];  // points per axis (brick, fewer at the level's far faces)
    size_t offset;  // of its first value in data(); values at ((z·ey + y)·ex + x)·K·3 + k·3 + c
  };
  struct Level {
    int step = 1;              // fine points between this level's points (the last cell may be shorter)
    int n[3] = {2, 2, 2};      // points per axis: ⌈(fine − 1)/step⌉ + 1
    int nb[3] = {1, 1, 1};     // bricks per axis: ⌈n/brick⌉
    std::vector<int32_t> map;  // brick index per brick-grid cell (x fastest), −1 where pruned
    std::vector<Brick> bricks;
  };

  AdaptiveGrid() = default;
  // The levels of a fine grid `grid`, no bricks yet.
  AdaptiveGrid(const GridDesc& grid, int bands, int brick);

  const GridDesc& grid() const { return grid_; }  // the fine grid (level 0)
  int bands() const { return bands_; }
  int coeff_count() const { return bands_ * bands_; }
  int brick() const { return brick_; }
  int levels() const { return int(levels_.size()); }
  const Level& level(int l) const { return levels_[size_t(l)]; }
  const std::vector<float>& data() const { return data_; }
  int64_t stored_points() const { return int64_t(data_.size()) / (coeff_count() * 3); }
  // Bytes of the .shtree file write_adaptive writes (header, brick tables, values).
  size_t file_bytes() const;
  // What make_adaptive was asked for and measured (header fields "tolerance", "rms"; 0 when unknown).
  double tolerance() const { return tolerance_; }
  double rms() const { return rms_; }
  void set_tolerance(double tolerance, double rms) {
    tolerance_ = tolerance;
    rms_ = rms;
  }

  // Adds brick (bx, by, bz) of level l and returns its values to fill (zeros); fails where it exists
  // or lies outside the level.
  float* add_brick(int l, int bx, int by, int bz);

  // The K·3 coefficients at fine-grid index coordinates f (clamped to [0, n − 1]), as doubles; returns
  // the level that answered. With `corners`, the 8 brick slots (indices into level(l).map, corner c at
  // x + (c & 1), y + (c >> 1 & 1), z + (c >> 2)) of the cell of level l around f instead: no lookup.
  int lookup(const double f[3], double* out) const;
  // The same with the cells chosen around cell_f and the interpolant evaluated at f (on the cell's
  // faces or corners: make_adaptive checks each fine cell's interpolant at its corners).
  int lookup_in(const double cell_f[3], const double f[3], double* out) const;
  void corner_slots(int l, const double f[3], size_t corners[8]) const;
  // Trilinear lookup at p (clamped to the volume), as SHGrid::coeffs_at.
  sh::Coeffs coeffs_at(Vec3 p) const;
  int level_at(Vec3 p) const;  // the level whose brick answers at p
  Vec3 irradiance(Vec3 p, Vec3 n) const;
  Vec3 radiance(Vec3 p, Vec3 w) const;
  Vec3 glossy(Vec3 p, Vec3 r, double exponent) const;

  // The dense grid of nx × ny × nz points over the same volume, each point looked up (the fine grid's
  // resolution reproduces the fine grid where level 0 is kept and within the tolerance elsewhere).
  SHGrid to_dense(int nx, int ny, int nz) const;
  SHGrid to_dense() const { return to_dense(grid_.nx, grid_.ny, grid_.nz); }

 private:
  Vec3 fine_index(Vec3 p) const;
  GridDesc grid_;
  int bands_ = 0, brick_ = 4;
  double tolerance_ = 0, rms_ = 0;
  std::vector<Level> levels_;  // levels_[0] the fine grid, levels_.back() the top (2 points per axis)
  std::vector<float> data_;
};

// The adaptive grid of `fine` (a radiance SH grid: no "content").
AdaptiveGrid make_adaptive(const SHGrid& fine, const AdaptDesc& desc = {});

// Reads/writes a .shtree; errors name the file and the field; sizes are checked before allocation.
AdaptiveGrid read_adaptive(const std::string& path);
void write_adaptive(const std::string& path, const AdaptiveGrid& g);
// Whether the file at path starts with the .shtree magic line (false where it cannot be read).
bool is_adaptive_file(const std::string& path);
// A radiance SH grid from either file: an .shgrid as read_shgrid reads it, an .shtree resampled at its
// fine resolution (to_dense) — what the renderers and exports load.
SHGrid read_dense(const std::string& path);

}  // namespace ibl::ilf
