// The renderers' lighting from a file: an SH grid (.shgrid), an iblkit.lights/1 light set, an
// iblkit.nearfield/1 luminaire dataset, iblkit.sh/1 coefficients, or a probe image — what
// `iblkit render --light` and `iblkit view --light` take (docs/render.md).
#pragma once
#include <string>
#include <vector>

#include "iblkit/io/envmap_io.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/nearfield/spotlight.h"
#include "iblkit/render/shading.h"

namespace ibl::render {

struct LightingReadDesc {
  int bands = 5;                   // SH bands a probe image is projected to
  int shadows = 4;                 // lights of a light set (in its priority order) that cast shadows;
                                   // > 0: a near-field dataset's spotlights cast shadows
  double glossy_exponent = 0;      // > 0: also a prefiltered Phong map of a probe image for this exponent
  io::EnvReadDesc read;            // how a probe image is read (mapping, dead angle, sanitising)
  nearfield::Placement luminaire;  // where a near-field dataset's luminaire sits and shines
};

// A light set's lights added to L: a light with a position (fusion's localised lights) in a set with
// an origin o becomes a point light of intensity I = E·|position − o|² (docs/fusion.md), every other
// light a directional light. Light i casts shadows when shadow[i] (false beyond shadow's end).
// Returns the number of point lights added.
int add_light_set(const lights::LightSet& set, const std::vector<bool>& shadow, Lighting* L);

// Reads the lighting file at `path` (its extension and "format" say which kind) into L, which gets
// one of: `grid` (.shgrid), lights and point lights (iblkit.lights/1: the first desc.shadows cast
// shadows unless a light says "shadow" itself), spotlights (iblkit.nearfield/1: a textured
// spotlight per filter position, Granier et al. Eq. 14, placed by desc.luminaire), `environment`
// (iblkit.sh/1, or a probe image projected to desc.bands, plus a prefiltered Phong map with
// desc.glossy_exponent > 0). *kind (when given) gets a one-line description.
void read_lighting(const std::string& path, const LightingReadDesc& desc, Lighting* L, std::string* kind = nullptr);

}  // namespace ibl::render
