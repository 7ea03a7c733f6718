#include "iblkit/lights/gltf.h"

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"

namespace ibl::lights {

void quaternion_z_to(Vec3 d, double q[4]) {
  d = normalize(d);
  // q = normalize(1 + z·d, z × d) with z × d = (−d.y, d.x, 0); for d = −Z any half turn about X.
  constexpr double kOpposite = 1e-12;
  if (1.0 + d.z < kOpposite) {
    q[0] = 1;
    q[1] = 0;
    q[2] = 0;
    q[3] = 0;
    return;
  }
  double x = -d.y, y = d.x, z = 0, w = 1.0 + d.z;
  double n = std::sqrt(x * x + y * y + z * z + w * w);
  q[0] = x / n;
  q[1] = y / n;
  q[2] = z / n;
  q[3] = w / n;
}

nlohmann::json to_gltf(const LightSet& set, const GltfDesc& desc) {
  if (!(desc.lux_per_unit > 0) || !std::isfinite(desc.lux_per_unit))
    fail(ErrorKind::Value, "glTF export: lux per unit must be positive (got {})", desc.lux_per_unit);
  nlohmann::json lights = nlohmann::json::array(), nodes = nlohmann::json::array(),
                 scene_nodes = nlohmann::json::array();
  for (size_t i = 0; i < set.lights.size(); ++i) {
    const Light& l = set.lights[i];
    double mx = max_component(l.irradiance);
    Vec3 color = mx > 0 ? l.irradiance / mx : Vec3{1, 1, 1};
    std::string name = "light_" + std::to_string(i);
    lights.push_back({{"type", "directional"},
                      {"name", name},
                      {"color", {color.x, color.y, color.z}},
                      {"intensity", desc.lux_per_unit * mx}});
    double q[4];
    quaternion_z_to(l.direction, q);
    nodes.push_back({{"name", name},
                     {"rotation", {q[0], q[1], q[2], q[3]}},
                     {"extensions", {{"KHR_lights_punctual", {{"light", i}}}}},
                     {"extras",
                      {{"direction", {l.direction.x, l.direction.y, l.direction.z}},
                       {"irradiance", {l.irradiance.x, l.irradiance.y, l.irradiance.z}},
                       {"solid_angle", l.solid_angle},
                       {"shadow_rank", i}}}});
    scene_nodes.push_back(i);
  }
  nlohmann::json scene = {{"name", desc.name}};
  if (!scene_nodes.empty()) scene["nodes"] = scene_nodes;
  nlohmann::json j = {{"asset", {{"version", "2.0"}, {"generator", "iblkit lights"}}},
                      {"extensionsUsed", {"KHR_lights_punctual"}},
                      {"extensions", {{"KHR_lights_punctual", {{"lights", lights}}}}},
                      {"scene", 0},
                      {"scenes", {scene}},
                      {"extras", {{"method", set.method}, {"lux_per_unit", desc.lux_per_unit}}}};
  if (!nodes.empty()) j["nodes"] = nodes;
  return j;
}

void write_gltf(const std::string& path, const LightSet& set, const GltfDesc& desc) {
  write_json_file(path, to_gltf(set, desc), 2);
}

}  // namespace ibl::lights
