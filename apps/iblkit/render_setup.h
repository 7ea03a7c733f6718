// Pieces `iblkit render` and `iblkit view` share: the lighting a --light file describes and the
// object a scene argument names.
#pragma once
#ifdef IBLKIT_HAVE_GEOMETRY
#include <string>

#include <CLI/CLI.hpp>

#include "iblkit/geometry/mesh.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/nearfield/spotlight.h"
#include "iblkit/render/frame.h"
#include "iblkit/render/shading.h"

namespace iblcli {

// How --light files are read (render and view share the options).
struct LightingOptions {
  int bands = 5;                  // SH bands when projecting a probe
  int shadows = 4;                // lights of a light set (priority order) that cast shadows
  double glossy_exponent = 0;     // > 0: also a prefiltered Phong map of a probe for this exponent
  ibl::io::EnvReadDesc read;      // probe reading (--mapping, --dead-angle, --sanitize)
  ibl::nearfield::Placement luminaire;  // where a near-field dataset's luminaire sits and shines
};

// The GL renderer's shadow maps (render and view share the options): --shadow-map,
// --spot-shadow-map and --spot-shadow-share.
struct ShadowMapOptions {
  int size = 2048;       // each directional or point light's (cube faces too)
  int spot_size = 512;   // each textured spotlight's
  double spot_share = 0; // metres: spotlights this close share a map (0: one each)
  void apply(ibl::render::FrameDesc* d) const {
    d->shadow_map_size = size;
    d->spot_shadow_map_size = spot_size;
    d->spot_shadow_share = spot_share;
  }
};
void add_shadow_map_options(CLI::App& app, ShadowMapOptions* o);

// Reads a --light file into L: an SH grid (.shgrid), an iblkit.lights/1 file (lights with a
// position and a set origin become point lights), an iblkit.nearfield/1 dataset (a textured
// spotlight per filter position, Granier et al. Eq. 14, placed by o.luminaire), an iblkit.sh/1
// file, or a probe image (projected to SH, plus a prefiltered Phong map). *kind gets a one-line
// description.
void load_lighting(const std::string& path, const LightingOptions& o, ibl::render::Lighting* L, std::string* kind);

// A warning when the object reaches outside an SH grid's volume (lookups there clamp to the grid's
// faces), or an empty string.
std::string grid_bounds_warning(const ibl::render::Lighting& L, const ibl::geometry::TriMesh& object);

// "blob" (the procedural bunny stand-in, `triangles`), "sphere", or a mesh file centred and scaled
// to `size` (its largest extent), then moved to `at`; size 0 keeps a mesh file where and as large
// as it is (a room such as examples/crypt.obj).
ibl::geometry::TriMesh make_object(const std::string& scene, double size, int triangles, ibl::Vec3 at);

}  // namespace iblcli
#endif
