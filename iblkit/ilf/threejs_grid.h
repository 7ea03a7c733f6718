// An SH grid as three.js r187's LightProbeGridWebGL (examples/jsm/lighting/LightProbeGridWebGL.js and
// src/renderers/shaders/ShaderChunk/lightprobes_pars_fragment.glsl.js) stores it, so that a page can
// put the data into a Data3DTexture, assign it to a LightProbeGridWebGL's .texture and light a scene
// with a captured light field instead of a baked one (docs/web.md, docs/conventions.md).
//
// three's layout, read from its source:
//  - the volume is a box of `size` centred at `center`, split into one cell per probe with the probe
//    at the cell's centre: probe (i,j,k) at center − size/2 + (i + ½, j + ½, k + ½)·size/res. An
//    iblkit grid point sits on its box's corners and faces (min + (max − min)·i/(n − 1)), so the
//    three.js box grows by half a spacing on every side: size = (max − min)·n/(n − 1).
//  - one RGBA float 3D texture nx × ny × 7(nz + 2): seven sub-volumes stacked along Z, sub-volume t
//    holding the flat radiance coefficients [c0.rgb, c1.rgb, …, c8.rgb] from 4t to 4t + 3 (t = 6:
//    c8.rgb and 0); each sub-volume has one padding slice before and after its nz data slices, a
//    copy of its first and last data slice, so that the trilinear filter never blends two
//    sub-volumes. Texel (x, y, z) at ((z·ny + y)·nx + x)·4.
//  - the coefficients are radiance in the orthonormal real basis of SphericalHarmonics3 (iblkit's own,
//    docs/conventions.md), 3 bands; the shader turns them into irradiance E(n) = Σ Â_l c_lm Y_lm(n) (π, 2π/3, π/4),
//    the same as iblkit's `ilf query`. Grids of more bands are truncated to 3 (the bands above carry
//    no or little irradiance: Â_3 = 0, Â_4 = π/24).
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "iblkit/ilf/shgrid.h"

namespace ibl::ilf {

constexpr int kThreeAtlasPadding = 1;  // ATLAS_PADDING in LightProbeGridWebGL.js
constexpr int kThreeAtlasVolumes = 7;  // 27 coefficients in RGBA texels

struct ThreeGrid {
  int nx = 0, ny = 0, nz = 0;  // probes per axis (three's `resolution`)
  Vec3 center, size;           // three's position and (width, height, depth)
  int depth() const { return kThreeAtlasVolumes * (nz + 2 * kThreeAtlasPadding); }
  std::vector<float> atlas;  // nx·ny·depth()·4 floats
};

ThreeGrid to_threejs_grid(const SHGrid& g);

// The JSON header the viewer reads (format "iblkit.threejs-grid/1"): resolution, center, size, atlas
// {file, width, height, depth, type "float32", channels 4}, and the source grid's min/max/bands.
nlohmann::json threejs_grid_header(const ThreeGrid& t, const SHGrid& g, const std::string& atlas_file);

// Writes DIR/NAME.json and DIR/NAME_atlas.bin (little-endian float32), each atomically; returns the
// JSON path.
std::string write_threejs_grid(const SHGrid& g, const std::string& dir, const std::string& name = "grid");

}  // namespace ibl::ilf
