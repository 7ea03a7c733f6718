// Pieces `iblkit render` and `iblkit view` share: the GL shadow-map options and the warning for an
// object outside an SH grid. What a --light file and a scene argument give is the library's
// (render/lighting_io.h, render/objects.h).
#pragma once
#ifdef IBLKIT_HAVE_GEOMETRY
#include <string>

#include <CLI/CLI.hpp>

#include "iblkit/augment/object.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/render/frame.h"
#include "iblkit/render/shading.h"

namespace iblcli {

// The GL renderer's shadow maps (render and view share the options): --shadow-map,
// --spot-shadow-map and --spot-shadow-share, their defaults FrameDesc's.
struct ShadowMapOptions {
  int size = ibl::render::FrameDesc{}.shadow_map_size;              // each directional or point light's (cube faces too)
  int spot_size = ibl::render::FrameDesc{}.spot_shadow_map_size;    // each textured spotlight's
  double spot_share = ibl::render::FrameDesc{}.spot_shadow_share;   // metres: spotlights this close share a map (0: one each)
  void apply(ibl::render::FrameDesc* d) const {
    d->shadow_map_size = size;
    d->spot_shadow_map_size = spot_size;
    d->spot_shadow_share = spot_share;
  }
};
void add_shadow_map_options(CLI::App& app, ShadowMapOptions* o);

// A warning when the object reaches outside an SH grid's volume (lookups there clamp to the grid's
// faces), naming both boxes and the flags that move and shrink the object; else an empty string.
std::string grid_bounds_warning(const ibl::render::Lighting& L, const ibl::geometry::TriMesh& object);

// The inserted object of `composite` and `lab photograph` from their --object, --object-size,
// --triangles, --at and --albedo values.
ibl::augment::ObjectDesc inserted_object(const std::string& kind, double size, int triangles, const std::string& at,
                                         const std::string& albedo);

// The object's surface from --albedo, --gloss, --exponent, --lobe (phong, blinn) and --texture (which then
// replaces the albedo: white times the texture), as `render` and `composite` take them.
ibl::render::Material object_material(const std::string& albedo, double gloss, double exponent, const std::string& lobe,
                                      const std::string& texture);

}  // namespace iblcli
#endif
