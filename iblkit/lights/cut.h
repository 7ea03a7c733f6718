// Region cuts of a lat-long probe into directional lights: median cut (Debevec [1], in the classic
// 2^K form and an any-N form) and variance-minimisation cut (Viriyothai & Debevec [2]).
//
//  [1] Debevec, "A median cut algorithm for light probe sampling", SIGGRAPH 2005 poster; as described by
//      Madsen & Laursen 2007 §4.1 and Pedersen 2008 §5.3.1, §6.1 (summed-area tables).
//  [2] Viriyothai & Debevec, "Variance minimization light probe sampling", SIGGRAPH 2009 poster.
//
// Both cuts work on the probe's lat-long grid (light_set.h, to_latlong_grid) with the energy of a pixel
// E = Y(L)·dω (luminance × exact pixel solid angle). Every region becomes one light at the region's
// energy centroid direction normalize(Σ E·ω), with irradiance Σ L·dω (RGB) and solid angle Σ dω, so
// the lights of a cut sum to ∫ L dω of the probe. Regions never wrap around the u = 0/1 seam.
#pragma once
#include "iblkit/core/progress.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::lights {

struct CutDesc {
  int count = 16;                 // number of lights N ≥ 1 (1 ≤ N ≤ pixels that carry light)
  bool power_of_two = false;      // median cut only: the classic form, every region split K times (N = 2^K)
  double min_separation_deg = 0;  // merge lights closer than this angle, then cut further to reach N (0: off)
  ProgressFn progress;            // optional progress callback
};

// Median cut [1]. Each split goes along the region's longest side measured on the sphere (width
// scaled by sin θ at the region's middle row) at the energy median, moved where needed so that both
// halves hold at least one pixel with light. Any-N form: always split the region with the most energy.
LightSet median_cut(const sphere::EnvMap& env, const CutDesc& desc);
LightSet median_cut(const LatLongGrid& grid, const CutDesc& desc);

// Variance-minimisation cut [2]: each region is split, along either axis, where the summed
// energy-weighted angular variance of its two halves is least; the region whose split removes the
// most variance goes next (any N). Variance of a region R on the sphere, exact from four summed-area
// tables: V(R) = Σ E‖ω − μ‖² = W − ‖S‖²/W, with W = Σ E, S = Σ E·ω, μ = S/W (since ‖ω‖ = 1).
LightSet variance_cut(const sphere::EnvMap& env, const CutDesc& desc);
LightSet variance_cut(const LatLongGrid& grid, const CutDesc& desc);

}  // namespace ibl::lights
