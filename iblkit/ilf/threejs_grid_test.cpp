// The three.js LightProbeGridWebGL atlas: every coefficient of every probe lands in the texel three's
// shader (lightprobes_pars_fragment) reads for it, the padding slices copy the edge slices, and
// three's probe positions coincide with iblkit's grid points.
#include "iblkit/ilf/threejs_grid.h"

#include <gtest/gtest.h>

#include "iblkit/core/error.h"

namespace ibl::ilf {
namespace {

// Value of coefficient k, channel c at point (i, j, l): distinct for every slot.
float code(int i, int j, int l, int k, int c) { return float(1 + i + 10 * j + 100 * l + 1000 * k + 10000 * c); }

SHGrid coded_grid(int bands) {
  GridDesc gd;
  gd.nx = 3;
  gd.ny = 4;
  gd.nz = 2;
  gd.volume = {{-1, 0, 2}, {1, 3, 2.5}};
  SHGrid g(gd, bands);
  for (int l = 0; l < gd.nz; ++l)
    for (int j = 0; j < gd.ny; ++j)
      for (int i = 0; i < gd.nx; ++i)
        for (int k = 0; k < g.coeff_count(); ++k)
          for (int c = 0; c < 3; ++c) g.at(i, j, l)[k * 3 + c] = code(i, j, l, k, c);
  return g;
}

// Texel component of atlas slice z as three's shader unpacks it: coefficient k channel c is flat
// value f = 3k + c, in sub-volume f / 4, component f % 4.
float atlas(const ThreeGrid& t, int x, int y, int z, int comp) {
  return t.atlas[((size_t(z) * t.ny + y) * t.nx + x) * 4 + comp];
}

TEST(ThreeGrid, EveryCoefficientInItsTexelAndPaddingCopiesTheEdges) {
  for (int bands : {3, 5}) {
    SHGrid g = coded_grid(bands);
    ThreeGrid t = to_threejs_grid(g);
    ASSERT_EQ(t.depth(), 7 * (2 + 2));
    ASSERT_EQ(t.atlas.size(), size_t(3 * 4 * t.depth() * 4));
    const int padded = t.nz + 2;
    for (int l = 0; l < t.nz; ++l)
      for (int j = 0; j < t.ny; ++j)
        for (int i = 0; i < t.nx; ++i)
          for (int k = 0; k < 9; ++k)
            for (int c = 0; c < 3; ++c) {
              int f = 3 * k + c, v = f / 4, comp = f % 4;
              EXPECT_EQ(atlas(t, i, j, v * padded + 1 + l, comp), code(i, j, l, k, c));
            }
    for (int j = 0; j < t.ny; ++j)
      for (int i = 0; i < t.nx; ++i)
        for (int v = 0; v < 7; ++v)
          for (int comp = 0; comp < 4; ++comp) {
            EXPECT_EQ(atlas(t, i, j, v * padded, comp), atlas(t, i, j, v * padded + 1, comp));
            EXPECT_EQ(atlas(t, i, j, v * padded + padded - 1, comp), atlas(t, i, j, v * padded + t.nz, comp));
          }
    // The unused fourth component of the last sub-volume is 0.
    EXPECT_EQ(atlas(t, 0, 0, 6 * padded + 1, 3), 0.0f);
  }
}

TEST(ThreeGrid, ProbePositionsAreTheGridPoints) {
  SHGrid g = coded_grid(3);
  ThreeGrid t = to_threejs_grid(g);
  constexpr double kPosTol = 1e-12;  // metres: the same arithmetic in double
  for (int l = 0; l < t.nz; ++l)
    for (int j = 0; j < t.ny; ++j)
      for (int i = 0; i < t.nx; ++i) {
        // LightProbeGridWebGL.getProbePosition: position − size/2 + (index + ½)·size/resolution.
        Vec3 three{t.center.x - t.size.x / 2 + (i + 0.5) * t.size.x / t.nx,
                   t.center.y - t.size.y / 2 + (j + 0.5) * t.size.y / t.ny,
                   t.center.z - t.size.z / 2 + (l + 0.5) * t.size.z / t.nz};
        Vec3 p = g.grid().point(i, j, l);
        EXPECT_NEAR(three.x, p.x, kPosTol);
        EXPECT_NEAR(three.y, p.y, kPosTol);
        EXPECT_NEAR(three.z, p.z, kPosTol);
      }
}

TEST(ThreeGrid, RefusesAnEmptyGrid) { EXPECT_THROW(to_threejs_grid(SHGrid()), Error); }

}  // namespace
}  // namespace ibl::ilf
