#include "render_setup.h"

#include "cli.h"
#ifdef IBLKIT_HAVE_GEOMETRY
#include <fmt/format.h>

#include "iblkit/io/image_io.h"
#include "iblkit/render/objects.h"

namespace iblcli {

void add_shadow_map_options(CLI::App& app, ShadowMapOptions* o) {
  app.add_option("--shadow-map", o->size, "GL: shadow map size of each directional or point light (cube faces too)")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  app.add_option("--spot-shadow-map", o->spot_size,
                 "GL: shadow map size of each textured spotlight (a 9×7 dataset draws 63 of them a frame)")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  app.add_option("--spot-shadow-share", o->spot_share,
                 "GL: textured spotlights within this many metres of each other share one shadow map (0: one each)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
}

std::string grid_bounds_warning(const ibl::render::Lighting& L, const ibl::geometry::TriMesh& object) {
  if (!ibl::render::reaches_outside_grid(L, object)) return {};
  ibl::Vec3 lo, hi;
  object.bounds(&lo, &hi);
  const ibl::Vec3 gmin = L.grid->grid().volume.min, gmax = L.grid->grid().volume.max;
  return fmt::format("the object spans ({:.3g}, {:.3g}, {:.3g})..({:.3g}, {:.3g}, {:.3g}), outside the SH grid's volume "
                     "({:.3g}, {:.3g}, {:.3g})..({:.3g}, {:.3g}, {:.3g}): lookups there clamp to the grid's faces "
                     "(move it with --at, shrink it with --object-size)",
                     lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, gmin.x, gmin.y, gmin.z, gmax.x, gmax.y, gmax.z);
}

ibl::augment::ObjectDesc inserted_object(const std::string& kind, double size, int triangles, const std::string& at,
                                         const std::string& albedo) {
  ibl::augment::ObjectDesc od;
  od.kind = kind;
  od.size = size;
  od.triangles = triangles;
  od.at = parse_vec3(at, "--at");
  od.albedo = parse_vec3(albedo, "--albedo");
  return od;
}

ibl::render::Material object_material(const std::string& albedo, double gloss, double exponent, const std::string& lobe,
                                      const std::string& texture) {
  using ibl::render::Lobe;
  ibl::render::Material m{parse_vec3(albedo, "--albedo"), ibl::Vec3{1, 1, 1} * gloss, exponent, lobe == "blinn" ? Lobe::BlinnPhong : Lobe::Phong};
  if (!texture.empty()) {
    m.albedo = {1, 1, 1};
    m.texture = std::make_shared<ibl::Image>(ibl::io::read_image(texture).with_channels(3));
  }
  return m;
}

}  // namespace iblcli
#endif
