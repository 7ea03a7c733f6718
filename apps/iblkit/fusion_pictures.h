// Pictures for `iblkit fuse` and its demo step: the fused map, its coverage, the chosen lights.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/fusion/fuse.h"
#include "iblkit/lights/light_set.h"

namespace iblcli {

// Coverage of a fused map as colours (same layout as the map): green = fused, brighter the more probes
// see the point (full at `probes`); blue = the ray left the proxy; red = no probe sees the point.
ibl::Image coverage_picture(const ibl::fusion::LocalMap& map, int probes);

// A tone-mapped copy of an HDR image with a fixed linear scale (pictures that must compare).
ibl::Image tone(const ibl::Image& img, double scale);

// The fused lat-long map, its coverage and (when given) the lights on it, side by side.
ibl::Image fused_sheet(const ibl::fusion::LocalMap& latlong, int probes, const ibl::lights::LightSet* lights,
                       const std::string& title);

}  // namespace iblcli
