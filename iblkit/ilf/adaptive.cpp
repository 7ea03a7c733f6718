#include "iblkit/ilf/adaptive.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/sh/convolve.h"

namespace ibl::ilf {

namespace {

// Level point i along an axis of n fine points at step s: fine index min(i·s, n − 1).
inline int level_coord(int i, int s, int n) { return int(std::min<int64_t>(int64_t(i) * s, n - 1)); }

}  // namespace

AdaptiveGrid::AdaptiveGrid(const GridDesc& grid, int bands, int brick) : grid_(grid), bands_(bands), brick_(brick) {
  if (bands < 1 || bands > 16) fail(ErrorKind::Value, "adaptive SH grid: bands = {} outside [1, 16]", bands);
  require_box("adaptive SH grid: volume", grid.volume.min, grid.volume.max, true);
  if (brick < kMinBrick || brick > kMaxBrick)
    fail(ErrorKind::Value, "adaptive SH grid: brick {} outside [{}, {}]", brick, kMinBrick, kMaxBrick);
  const int n[3] = {grid.nx, grid.ny, grid.nz};
  for (int a = 0; a < 3; ++a)
    if (n[a] < 2 || n[a] > (1 << 20))
      fail(ErrorKind::Value, "adaptive SH grid: {} points on axis {} outside [2, 2^20]", n[a], "xyz"[a]);
  for (int step = 1;; step *= 2) {
    Level L;
    L.step = step;
    int64_t cells = 1;
    for (int a = 0; a < 3; ++a) {
      L.n[a] = (n[a] - 1 + step - 1) / step + 1;
      L.nb[a] = (L.n[a] + brick - 1) / brick;
      cells *= L.nb[a];
    }
    require_allocation("adaptive SH grid: brick map", double(cells), sizeof(int32_t),
                       "choose a coarser grid or larger bricks");
    L.map.assign(size_t(cells), -1);
    levels_.push_back(std::move(L));
    const auto& last = levels_.back();
    if (last.n[0] == 2 && last.n[1] == 2 && last.n[2] == 2) break;
  }
}

float* AdaptiveGrid::add_brick(int l, int bx, int by, int bz) {
  if (l < 0 || l >= levels()) fail(ErrorKind::Value, "adaptive SH grid: level {} outside [0, {}]", l, levels() - 1);
  Level& L = levels_[size_t(l)];
  const int b[3] = {bx, by, bz};
  for (int a = 0; a < 3; ++a)
    if (b[a] < 0 || b[a] >= L.nb[a])
      fail(ErrorKind::Value, "adaptive SH grid: brick ({}, {}, {}) lies outside level {}'s {}x{}x{} bricks", bx, by, bz,
           l, L.nb[0], L.nb[1], L.nb[2]);
  int32_t& slot = L.map[size_t((int64_t(bz) * L.nb[1] + by) * L.nb[0] + bx)];
  if (slot >= 0) fail(ErrorKind::Value, "adaptive SH grid: brick ({}, {}, {}) of level {} given twice", bx, by, bz, l);
  Brick br{};
  int64_t pts = 1;
  for (int a = 0; a < 3; ++a) {
    br.b[a] = b[a];
    br.extent[a] = std::min(brick_, L.n[a] - b[a] * brick_);
    pts *= br.extent[a];
  }
  br.offset = data_.size();
  require_allocation("adaptive SH grid: values", double(data_.size() + size_t(pts) * coeff_count() * 3), sizeof(float),
                     "choose a larger tolerance or a coarser fine grid");
  slot = int32_t(L.bricks.size());
  L.bricks.push_back(br);
  data_.resize(data_.size() + size_t(pts) * coeff_count() * 3, 0.0f);
  return data_.data() + br.offset;
}

namespace {

// The cell of level L around fine index coordinates f (clamped), per axis: its lower corner, and the
// bricks and in-brick coordinates of its two corners.
struct CellAxes {
  int cell[3], brick[2][3], local[2][3];
};

CellAxes cell_of(const AdaptiveGrid::Level& L, int B, const double f[3]) {
  CellAxes c;
  for (int a = 0; a < 3; ++a) {
    // The cell (and so the bricks) of a point within 1e-7 cells of a fine point is that fine point's:
    // the one make_adaptive checked it in (a world coordinate may miss its index by an ulp).
    double r = std::round(f[a]), fc = std::abs(f[a] - r) < 1e-7 ? r : f[a];
    c.cell[a] = std::min(int(fc / L.step), L.n[a] - 2);  // f/1 = f at level 0: SHGrid's cell
    for (int e = 0; e < 2; ++e) {
      c.brick[e][a] = (c.cell[a] + e) / B;
      c.local[e][a] = c.cell[a] + e - c.brick[e][a] * B;
    }
  }
  return c;
}

size_t slot_of(const AdaptiveGrid::Level& L, const CellAxes& c, int corner) {
  return size_t((int64_t(c.brick[corner >> 2][2]) * L.nb[1] + c.brick[(corner >> 1) & 1][1]) * L.nb[0] +
                c.brick[corner & 1][0]);
}

void clamp_index(const GridDesc& g, const double in[3], double out[3]) {
  const int n[3] = {g.nx, g.ny, g.nz};
  for (int a = 0; a < 3; ++a) out[a] = std::isnan(in[a]) ? 0.0 : std::clamp(in[a], 0.0, double(n[a] - 1));
}

}  // namespace

void AdaptiveGrid::corner_slots(int l, const double f_in[3], size_t corners[8]) const {
  double f[3];
  clamp_index(grid_, f_in, f);
  const Level& L = levels_[size_t(l)];
  CellAxes c = cell_of(L, brick_, f);
  for (int k = 0; k < 8; ++k) corners[k] = slot_of(L, c, k);
}

int AdaptiveGrid::lookup(const double f[3], double* out) const { return lookup_in(f, f, out); }

int AdaptiveGrid::lookup_in(const double cell_in[3], const double f_in[3], double* out) const {
  const int KC = coeff_count() * 3;
  std::fill(out, out + KC, 0.0);
  const int n[3] = {grid_.nx, grid_.ny, grid_.nz};
  double f[3], cf[3];
  clamp_index(grid_, f_in, f);
  clamp_index(grid_, cell_in, cf);
  for (int l = 0; l < levels(); ++l) {
    const Level& L = levels_[size_t(l)];
    CellAxes c = cell_of(L, brick_, cf);
    const float* src[8];
    bool complete = true;
    for (int k = 0; k < 8 && complete; ++k) {
      int32_t idx = L.map[slot_of(L, c, k)];
      if (idx < 0) {
        complete = false;
        break;
      }
      const Brick& br = L.bricks[size_t(idx)];
      const int x = c.local[k & 1][0], y = c.local[(k >> 1) & 1][1], z = c.local[k >> 2][2];
      src[k] = data_.data() + br.offset + size_t((int64_t(z) * br.extent[1] + y) * br.extent[0] + x) * KC;
    }
    if (!complete) continue;
    double t[3];
    for (int a = 0; a < 3; ++a) {
      int x0 = level_coord(c.cell[a], L.step, n[a]), x1 = level_coord(c.cell[a] + 1, L.step, n[a]);
      t[a] = (f[a] - x0) / double(x1 - x0);  // (f − i0)/1 at level 0: SHGrid's weight, bit for bit
    }
    for (int k = 0; k < 8; ++k) {
      double w = ((k & 1) ? t[0] : 1 - t[0]) * ((k & 2) ? t[1] : 1 - t[1]) * ((k & 4) ? t[2] : 1 - t[2]);
      if (w == 0) continue;
      for (int j = 0; j < KC; ++j) out[j] += src[k][j] * w;
    }
    return l;
  }
  fail(ErrorKind::Value, "adaptive SH grid: the top level has no brick (every lookup needs it)");
}

Vec3 AdaptiveGrid::fine_index(Vec3 p) const {
  if (!is_finite(p))
    fail(ErrorKind::Value, "adaptive SH grid lookup: the point ({}, {}, {}) is not finite", p.x, p.y, p.z);
  Vec3 s = grid_.volume.size();
  return {(p.x - grid_.volume.min.x) / s.x * (grid_.nx - 1), (p.y - grid_.volume.min.y) / s.y * (grid_.ny - 1),
          (p.z - grid_.volume.min.z) / s.z * (grid_.nz - 1)};
}

sh::Coeffs AdaptiveGrid::coeffs_at(Vec3 p) const {
  Vec3 fi = fine_index(p);
  const double f[3] = {fi.x, fi.y, fi.z};
  std::vector<double> v(size_t(coeff_count()) * 3);
  lookup(f, v.data());
  sh::Coeffs out;
  out.bands = bands_;
  out.c.resize(size_t(coeff_count()));
  for (int k = 0; k < coeff_count(); ++k)
    out.c[size_t(k)] = {v[3 * size_t(k)], v[3 * size_t(k) + 1], v[3 * size_t(k) + 2]};
  return out;
}

int AdaptiveGrid::level_at(Vec3 p) const {
  Vec3 fi = fine_index(p);
  const double f[3] = {fi.x, fi.y, fi.z};
  std::vector<double> v(size_t(coeff_count()) * 3);
  return lookup(f, v.data());
}

Vec3 AdaptiveGrid::irradiance(Vec3 p, Vec3 n) const { return sh::irradiance_at(coeffs_at(p), normalize(n)); }
Vec3 AdaptiveGrid::radiance(Vec3 p, Vec3 w) const { return sh_radiance(coeffs_at(p), w); }
Vec3 AdaptiveGrid::glossy(Vec3 p, Vec3 r, double exponent) const {
  if (!(exponent >= 0)) fail(ErrorKind::Value, "glossy: Phong exponent {} must be ≥ 0", exponent);
  return sh_glossy(coeffs_at(p), r, exponent);
}

SHGrid AdaptiveGrid::to_dense(int nx, int ny, int nz) const {
  SHGrid out(GridDesc{nx, ny, nz, grid_.volume}, bands_);
  const int KC = coeff_count() * 3;
  const int N[3] = {nx, ny, nz}, n[3] = {grid_.nx, grid_.ny, grid_.nz};
  parallel_for(0, int64_t(nz) * ny, [&](int64_t zy) {
    std::vector<double> v(static_cast<size_t>(KC));
    int k = int(zy / ny), j = int(zy % ny);
    for (int i = 0; i < nx; ++i) {
      const int ijk[3] = {i, j, k};
      double f[3];
      for (int a = 0; a < 3; ++a)
        f[a] = double(ijk[a]) * (n[a] - 1) / (N[a] - 1);  // = i exactly at the fine resolution
      lookup(f, v.data());
      float* dst = out.at(i, j, k);
      for (int q = 0; q < KC; ++q) dst[q] = float(v[size_t(q)]);
    }
  });
  return out;
}

AdaptiveGrid make_adaptive(const SHGrid& fine, const AdaptDesc& desc) {
  if (!fine.content().empty())
    fail(ErrorKind::Value, "adaptive SH grid: the grid holds \"{}\", not radiance SH", fine.content());
  if (fine.data().empty()) fail(ErrorKind::Value, "adaptive SH grid: the fine grid is empty");
  require_number("adaptive SH grid: tolerance", desc.tolerance, 0, 1e6);
  const GridDesc& gd = fine.grid();
  AdaptiveGrid tree(gd, fine.bands(), desc.brick);
  const int KC = fine.coeff_count() * 3;
  const int n[3] = {gd.nx, gd.ny, gd.nz};
  double sum = 0;
  for (float v : fine.data()) sum += double(v) * v;
  const double rms = std::sqrt(sum / double(gd.count()));
  const double bound = desc.tolerance * rms;
  tree.set_tolerance(desc.tolerance, rms);
  auto fill = [&](int l, const int b[3]) {
    const auto& L = tree.level(l);
    float* dst = tree.add_brick(l, b[0], b[1], b[2]);
    const auto& br = tree.level(l).bricks.back();
    for (int z = 0; z < br.extent[2]; ++z)
      for (int y = 0; y < br.extent[1]; ++y)
        for (int x = 0; x < br.extent[0]; ++x) {
          const float* src = fine.at(level_coord(b[0] * desc.brick + x, L.step, n[0]),
                                     level_coord(b[1] * desc.brick + y, L.step, n[1]),
                                     level_coord(b[2] * desc.brick + z, L.step, n[2]));
          std::copy(src, src + KC, dst + size_t((int64_t(z) * br.extent[1] + y) * br.extent[0] + x) * KC);
        }
  };
  const int top = tree.levels() - 1;
  const int origin[3] = {0, 0, 0};
  fill(top, origin);
  // Top down, per fine cell C: where the interpolant that answers in C (that of the finest complete
  // level above l) misses the fine values at one of C's 8 corners by more than the bound, the corner
  // bricks of the level-l cell around C are stored, so that C is answered at level l or finer. A cell
  // answered at level m > 0 was within the bound at its corners when level m−1 was decided (else its
  // level-(m−1) cell would be complete), the levels from m up have not changed since, and a trilinear
  // difference within the bound at the corners is within it in the whole cell (the norm is convex): the
  // lookup is within the bound of the fine grid's trilinear lookup everywhere.
  for (int l = top - 1; l >= 0; --l) {
    const auto& L = tree.level(l);
    std::vector<uint8_t> need(L.map.size(), 0);
    parallel_for(0, int64_t(gd.nz - 1) * (gd.ny - 1), [&](int64_t zy) {
      std::vector<double> v(static_cast<size_t>(KC));
      const int k = int(zy / (gd.ny - 1)), j = int(zy % (gd.ny - 1));
      for (int i = 0; i + 1 < gd.nx; ++i) {
        const double centre[3] = {i + 0.5, j + 0.5, k + 0.5};
        size_t slots[8];
        tree.corner_slots(l, centre, slots);
        bool all = true;
        for (size_t s : slots) all = all && std::atomic_ref<uint8_t>(need[s]).load(std::memory_order_relaxed);
        if (all) continue;
        bool miss = false;
        for (int c = 0; c < 8 && !miss; ++c) {
          const int q[3] = {i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2)};
          const double f[3] = {double(q[0]), double(q[1]), double(q[2])};
          tree.lookup_in(centre, f, v.data());
          const float* src = fine.at(q[0], q[1], q[2]);
          double e = 0;
          for (int m = 0; m < KC; ++m) e += (v[size_t(m)] - src[m]) * (v[size_t(m)] - src[m]);
          miss = std::sqrt(e) > bound;
        }
        if (miss)
          for (size_t s : slots) std::atomic_ref<uint8_t>(need[s]).store(1, std::memory_order_relaxed);
      }
    });
    for (int bz = 0; bz < L.nb[2]; ++bz)
      for (int by = 0; by < L.nb[1]; ++by)
        for (int bx = 0; bx < L.nb[0]; ++bx)
          if (need[size_t((int64_t(bz) * L.nb[1] + by) * L.nb[0] + bx)]) {
            const int b[3] = {bx, by, bz};
            fill(l, b);
          }
  }
  // The bricks some lookup reads: the answering level of every fine cell is that of its centre (coarse
  // cells are unions of fine ones; a point on a face answers as the cell above it, one of them).
  std::vector<std::vector<uint8_t>> used(size_t(tree.levels()));
  for (int l = 0; l < tree.levels(); ++l) used[size_t(l)].assign(tree.level(l).map.size(), 0);
  used[size_t(top)][0] = 1;  // the format needs the top brick
  parallel_for(0, int64_t(gd.nz - 1) * (gd.ny - 1), [&](int64_t zy) {
    std::vector<double> v(static_cast<size_t>(KC));
    const int k = int(zy / (gd.ny - 1)), j = int(zy % (gd.ny - 1));
    for (int i = 0; i + 1 < gd.nx; ++i) {
      const double f[3] = {i + 0.5, j + 0.5, k + 0.5};
      const int l = tree.lookup(f, v.data());
      size_t slots[8];
      tree.corner_slots(l, f, slots);
      for (size_t s : slots) std::atomic_ref<uint8_t>(used[size_t(l)][s]).store(1, std::memory_order_relaxed);
    }
  });
  AdaptiveGrid out(gd, fine.bands(), desc.brick);
  out.set_tolerance(desc.tolerance, rms);
  for (int l = top; l >= 0; --l) {
    const auto& L = tree.level(l);
    for (const auto& br : L.bricks) {
      if (!used[size_t(l)][size_t((int64_t(br.b[2]) * L.nb[1] + br.b[1]) * L.nb[0] + br.b[0])]) continue;
      float* dst = out.add_brick(l, br.b[0], br.b[1], br.b[2]);
      const size_t n = size_t(br.extent[0]) * br.extent[1] * br.extent[2] * KC;
      std::copy(tree.data().data() + br.offset, tree.data().data() + br.offset + n, dst);
    }
  }
  return out;
}

}  // namespace ibl::ilf
