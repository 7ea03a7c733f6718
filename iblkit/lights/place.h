// Where the lights of a set sit: the one placement rule for every light that is localised (fusion's lights
// of a fused map, the GL compositor's hard lights of a probe on its proxy). Pedersen 2008 [1] §4.2, §5.3.1:
// a light of direction d and region R sits at P = origin + t̃·d, t̃ the energy-weighted median of the depths
// t_j of R's pixels that see something at a finite distance (energy E_j = Y(L_j)·dω_j) — the median, not the
// mean, because a rectangular region drags dim pixels at other depths along — when those pixels carry at
// least half of R's energy; otherwise the light stays directional (light through a window or an open end).
// t̃ is never more than the depth the pixel along d itself sees: a wide region's median depth along its mean
// direction can land behind the surface (a window's light 12 cm above low-scene2's ceiling, whose shadow map
// then saw only the ceiling: the GL object's error went from 4.2 % to 12.3 %).
// A renderer treats a positioned light as a point light (light_set.h, irradiance_at).
//
//  [1] Pedersen, "Fusing environment maps for IBL in large scenes", MSc thesis, Aalborg 2008.
#pragma once
#include <functional>

#include "iblkit/lights/light_set.h"

namespace ibl::lights {

// `set` from a cut of `grid` (its regions filled: median_cut does); depth(x, y) the metres from `origin` to
// what pixel (x, y) of the grid sees, ≤ 0 or not finite where it sees nothing near. It is asked only for
// pixels that carry light. Sets the positions and set.origin = origin.
void place_by_depth(LightSet& set, const LatLongGrid& grid, Vec3 origin, const std::function<double(int, int)>& depth);

}  // namespace ibl::lights
