#include "iblkit/render/lighting_io.h"

#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/ilf/adaptive.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/nearfield/dataset.h"
#include "iblkit/render/prefilter.h"
#include "iblkit/sh/project.h"

namespace ibl::render {

int add_light_set(const lights::LightSet& set, const std::vector<bool>& shadow, Lighting* L) {
  int points = 0;
  for (size_t i = 0; i < set.lights.size(); ++i) {
    const lights::Light& l = set.lights[i];
    const bool casts = i < shadow.size() && shadow[i];
    if (l.position && set.origin) {
      Vec3 q = *l.position - *set.origin;
      L->point_lights.push_back({*l.position, l.irradiance * dot(q, q), casts});
      ++points;
    } else {
      L->lights.push_back({normalize(l.direction), l.irradiance, casts});
    }
  }
  return points;
}

namespace {

// An iblkit.lights/1 file's lights: shadow-map priority order (docs/formats.md), the first
// `shadows` get maps unless a light says "shadow" itself.
std::string read_light_set(const nlohmann::json& j, const std::string& path, int shadows, Lighting* L) {
  lights::LightSet set = lights::from_json(j, path);
  std::vector<bool> shadow(set.lights.size());
  for (size_t i = 0; i < set.lights.size(); ++i) {
    shadow[i] = static_cast<int>(i) < shadows;
    const nlohmann::json& lj = j["lights"][i];
    if (lj.contains("shadow")) {
      if (!lj["shadow"].is_boolean())
        fail(ErrorKind::Format, "{}: light {}: \"shadow\" must be true or false", path, i);
      shadow[i] = lj["shadow"].get<bool>();
    }
  }
  const int points = add_light_set(set, shadow, L);
  return points ? fmt::format("{} point lights and {} directional lights", points, set.lights.size() - points)
                : fmt::format("{} directional lights", set.lights.size());
}

}  // namespace

void read_lighting(const std::string& path, const LightingReadDesc& desc, Lighting* L, std::string* kind) {
  std::string what;
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".shgrid" || ext == ".shtree") {  // an adaptive grid resampled at its fine resolution (ilf/adaptive.h)
    const ilf::SHGrid& g = L->grid.emplace(ilf::read_dense(path));
    what = fmt::format("SH grid {}x{}x{}, {} bands{}", g.grid().nx, g.grid().ny, g.grid().nz, g.bands(),
                       ext == ".shtree" ? " (adaptive, resampled to dense)" : "");
  } else if (ext == ".json") {
    const nlohmann::json j = read_json_file(path);
    if (!j.is_object())
      fail(ErrorKind::Format,
           "{}: expected a JSON object (an iblkit.lights/1, iblkit.sh/1 or iblkit.nearfield/1 file), got {}", path,
           j.type_name());
    const std::string format = opt_field(j, path, "format", "");
    if (format == "iblkit.lights/1") {
      what = read_light_set(j, path, desc.shadows, L);
    } else if (format == "iblkit.nearfield/1") {
      nearfield::Dataset ds = nearfield::read_dataset(path);
      L->spotlights = nearfield::spotlights(ds, desc.luminaire, desc.shadows > 0);
      what = fmt::format("near-field luminaire {} ({}x{} textured spotlights{})", ds.name, ds.nx, ds.ny,
                         desc.shadows > 0 ? ", shadows" : "");
    } else if (format == "iblkit.sh/1") {
      L->environment = sh::coeffs_from_json(j, path);
      what = fmt::format("SH environment, {} bands", L->environment->bands);
    } else {
      fail(ErrorKind::Format, "{}: \"format\" is '{}'; expected iblkit.lights/1, iblkit.sh/1 or iblkit.nearfield/1",
           path, format);
    }
  } else {
    auto env = io::read_envmap(path, desc.read);
    L->environment = sh::project(env, desc.bands);
    what = fmt::format("probe projected to {} SH bands", desc.bands);
    if (desc.glossy_exponent > 0) {
      L->glossy_maps.push_back(prefilter_phong(env, desc.glossy_exponent));
      const Image& g = L->glossy_maps.back().latlong;
      what += fmt::format(", glossy from a prefiltered {}x{} Phong map (s = {:g})", g.width(), g.height(),
                          desc.glossy_exponent);
    }
  }
  if (kind) *kind = what;
}

}  // namespace ibl::render
