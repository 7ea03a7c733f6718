// Pieces `iblkit render` and `iblkit view` share: the GL shadow-map options and the warning for an
// object outside an SH grid. What a --light file and a scene argument give is the library's
// (render/lighting_io.h, render/objects.h).
#pragma once
#ifdef IBLKIT_HAVE_GEOMETRY
#include <string>

#include <CLI/CLI.hpp>

#include "iblkit/augment/load.h"
#include "iblkit/core/image.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/render/frame.h"
#include "iblkit/render/objects.h"
#include "iblkit/render/shading.h"

namespace iblcli {

// The GL renderer's shadow maps (render and view share the options): --shadow-map,
// --spot-shadow-map and --spot-shadow-share, their defaults FrameDesc's.
struct ShadowMapOptions {
  int size = ibl::render::FrameDesc{}.shadow_map_size;            // each directional or point light's (cube faces too)
  int spot_size = ibl::render::FrameDesc{}.spot_shadow_map_size;  // each textured spotlight's
  double spot_share =
      ibl::render::FrameDesc{}.spot_shadow_share;  // metres: spotlights this close share a map (0: one each)
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

// The inserted object of `composite`, `view --composite` and `lab photograph` from their --object,
// --object-size, --triangles and --at values (its surface is object_material's).
ibl::render::ObjectDesc inserted_object(const std::string& kind, double size, int triangles, const std::string& at);

// The object's surface from --albedo, --gloss, --exponent, --lobe (phong, blinn) and --texture (which then
// replaces the albedo: white times the texture), as `render` and `composite` take them.
ibl::render::Material object_material(const std::string& albedo, double gloss, double exponent, const std::string& lobe,
                                      const std::string& texture);

// The photograph's camera and the captured light of `composite` and `view --composite` (one set of
// options, two commands): --eye --target --up --fov or --camera, and --probes, --proxy, --at-probe
// (--light is each command's own). `prefix` goes before each help text ("composite: " in view).
struct PhotoSceneOptions {
  std::string eye, target, up = "0,1,0", camera, probes, proxy, at_probe;
  double fov = 40;
};
void add_photo_scene_options(CLI::App& app, PhotoSceneOptions* o, const std::string& prefix);
// The camera of `photo` (read from photo_path): --camera's file (its size, where it names one, must be
// the photograph's) or --eye/--target/--up/--fov; the frame's size is the photograph's; validated.
// `who` starts the message when neither is given ("" or "--composite: ").
ibl::geometry::Camera photo_camera(const PhotoSceneOptions& o, const ibl::Image& photo, const std::string& photo_path,
                                   const std::string& who);
// What augment::load_light reads: --probes, or the one --light file with --proxy and --at-probe.
ibl::augment::LightInput photo_light_input(const PhotoSceneOptions& o, const std::vector<std::string>& light);

}  // namespace iblcli
#endif
