// The regular grid of an SH grid (docs/formats.md, .shgrid): point (i,j,k) sits at
// min + (max − min)·(i/(nx−1), j/(ny−1), k/(nz−1)); linear index (k·ny + j)·nx + i.
#pragma once
#include <cstdint>

#include "iblkit/ilf/sequence.h"

namespace ibl::ilf {

struct GridDesc {
  int nx = 16, ny = 16, nz = 16;  // grid points per axis (≥ 2 each)
  Box volume;                     // the box the grid spans, corner points included
  int64_t count() const { return int64_t(nx) * ny * nz; }
  Vec3 spacing() const {
    Vec3 s = volume.size();
    return {s.x / (nx - 1), s.y / (ny - 1), s.z / (nz - 1)};
  }
  Vec3 point(int i, int j, int k) const {
    Vec3 s = spacing();
    return {volume.min.x + s.x * i, volume.min.y + s.y * j, volume.min.z + s.z * k};
  }
  Vec3 point(int64_t g) const { return point(int(g % nx), int((g / nx) % ny), int(g / (int64_t(nx) * ny))); }
};

}  // namespace ibl::ilf
