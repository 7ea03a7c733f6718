#include "render_setup.h"
#ifdef IBLKIT_HAVE_GEOMETRY
#include <algorithm>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/nearfield/dataset.h"
#include "iblkit/render/prefilter.h"
#include "iblkit/sh/project.h"

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

namespace fs = std::filesystem;
using namespace ibl;
using namespace ibl::render;

void load_lighting(const std::string& path, const LightingOptions& o, Lighting* L, std::string* kind) {
  const int bands = o.bands, shadows = o.shadows;
  const double glossy_exponent = o.glossy_exponent;
  const io::EnvReadDesc& rd = o.read;
  std::string ext = fs::path(path).extension().string();
  if (ext == ".shgrid") {
    const ilf::SHGrid& g = L->grid.emplace(ilf::read_shgrid(path));
    *kind = fmt::format("SH grid {}x{}x{}, {} bands", g.grid().nx, g.grid().ny, g.grid().nz, g.bands());
    return;
  }
  if (ext == ".json") {
    const nlohmann::json j = read_json_file(path);
    std::string format = j.value("format", "");
    if (format == "iblkit.lights/1") {
      lights::LightSet set = lights::from_json(j, path);
      // Lights come in shadow-map priority order (docs/formats.md): the first `shadows` get maps,
      // unless a light says "shadow" itself. A light with a position (fusion's localised lights)
      // is a point light of intensity irradiance·|position − origin|².
      int points = 0;
      for (size_t i = 0; i < set.lights.size(); ++i) {
        const lights::Light& l = set.lights[i];
        bool shadow = static_cast<int>(i) < shadows;
        if (j["lights"][i].contains("shadow")) shadow = j["lights"][i]["shadow"].get<bool>();
        if (l.position && set.origin) {
          Vec3 q = *l.position - *set.origin;
          L->point_lights.push_back({*l.position, l.irradiance * dot(q, q), shadow});
          ++points;
        } else {
          L->lights.push_back({normalize(l.direction), l.irradiance, shadow});
        }
      }
      *kind = points ? fmt::format("{} point lights and {} directional lights", points, set.lights.size() - points)
                     : fmt::format("{} directional lights", set.lights.size());
      return;
    }
    if (format == "iblkit.nearfield/1") {
      nearfield::Dataset ds = nearfield::read_dataset(path);
      L->spotlights = nearfield::spotlights(ds, o.luminaire, shadows > 0);
      *kind = fmt::format("near-field luminaire {} ({}x{} textured spotlights{})", ds.name, ds.nx, ds.ny, shadows > 0 ? ", shadows" : "");
      return;
    }
    if (format == "iblkit.sh/1") {
      sh::Coeffs c;
      c.bands = j.at("bands").get<int>();
      for (const auto& v : j.at("coefficients")) c.c.push_back({v[0].get<double>(), v[1].get<double>(), v[2].get<double>()});
      if (static_cast<int>(c.c.size()) != c.bands * c.bands)
        fail(ErrorKind::Format, "{}: {} bands need {} coefficients, found {}", path, c.bands, c.bands * c.bands, c.c.size());
      L->environment = c;
      *kind = fmt::format("SH environment, {} bands", c.bands);
      return;
    }
    fail(ErrorKind::Format, "{}: \"format\" is '{}'; expected iblkit.lights/1, iblkit.sh/1 or iblkit.nearfield/1", path, format);
  }
  auto env = io::read_envmap(path, rd);
  L->environment = sh::project(env, bands);
  *kind = fmt::format("probe projected to {} SH bands", bands);
  if (glossy_exponent > 0) {
    L->glossy_maps.push_back(prefilter_phong(env, glossy_exponent));
    const Image& g = L->glossy_maps.back().latlong;
    *kind += fmt::format(", glossy from a prefiltered {}x{} Phong map (s = {:g})", g.width(), g.height(), glossy_exponent);
  }
}

std::string grid_bounds_warning(const Lighting& L, const Mesh& object) {
  if (!L.grid) return {};
  Vec3 lo, hi;
  object.bounds(&lo, &hi);
  const Vec3 gmin = L.grid->grid().volume.min, gmax = L.grid->grid().volume.max;
  constexpr double kSlack = 1e-6;  // metres: an object exactly on the volume's faces is inside
  for (int a = 0; a < 3; ++a)
    if (lo[a] < gmin[a] - kSlack || hi[a] > gmax[a] + kSlack)
      return fmt::format("the object spans ({:.3g}, {:.3g}, {:.3g})..({:.3g}, {:.3g}, {:.3g}), outside the SH grid's volume "
                         "({:.3g}, {:.3g}, {:.3g})..({:.3g}, {:.3g}, {:.3g}): lookups there clamp to the grid's faces "
                         "(move it with --at, shrink it with --object-size)",
                         lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, gmin.x, gmin.y, gmin.z, gmax.x, gmax.y, gmax.z);
  return {};
}

Mesh make_object(const std::string& scene, double size, int triangles, Vec3 at) {
  Mesh object;
  if (!(size > 0) && (scene == "blob" || scene == "sphere")) fail(ErrorKind::Value, "--object-size must be > 0 for the {}", scene);
  if (scene == "blob") {
    object = make_blob(triangles, size);
  } else if (scene == "sphere") {
    object = make_sphere(size / 2, 128, 256);
  } else {
    object = from_trimesh(geometry::read_mesh(scene));
    if (size == 0) return object;  // as the file has it
    // Centre the file's mesh on the origin and scale its largest extent to `size`.
    Vec3 lo, hi;
    object.bounds(&lo, &hi);
    double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    if (!(extent > 0)) fail(ErrorKind::Value, "{}: the mesh has no extent", scene);
    object.transform(1.0, (lo + hi) * -0.5);
    object.transform(size / extent, {0, 0, 0});
  }
  object.transform(1.0, at);
  return object;
}

}  // namespace iblcli
#endif
