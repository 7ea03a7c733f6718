// Pieces `iblkit render` and `iblkit view` share: the lighting a --light file describes and the
// object a scene argument names.
#pragma once
#ifdef IBLKIT_HAVE_GEOMETRY
#include <string>

#include "iblkit/io/envmap_io.h"
#include "iblkit/render/mesh.h"
#include "iblkit/render/shading.h"

namespace iblcli {

// Reads a --light file into L: an SH grid (.shgrid), an iblkit.lights/1 file (lights with a
// position and a set origin become point lights; the first `shadows` cast shadows), an iblkit.sh/1
// file, or a probe image (projected to `bands` SH bands, plus a prefiltered Phong map for
// `glossy_exponent` when it is > 0). *kind receives a one-line description.
void load_lighting(const std::string& path, int bands, int shadows, const ibl::io::EnvReadDesc& rd, double glossy_exponent,
                   ibl::render::Lighting* L, std::string* kind);

// "blob" (the procedural bunny stand-in, `triangles`), "sphere", or a mesh file centred and scaled
// to `size` (its largest extent), then moved to `at`.
ibl::render::Mesh make_object(const std::string& scene, double size, int triangles, ibl::Vec3 at);

}  // namespace iblcli
#endif
