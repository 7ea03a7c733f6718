// Export of a light set as glTF 2.0 with KHR_lights_punctual directional lights.
//
// One node per light, oriented by its rotation quaternion: a KHR_lights_punctual directional light
// shines along its node's local −Z, so the node's rotation takes +Z to the direction towards the light
// (the light then travels along −direction). Colour and intensity: color = E / max(E) (linear, in
// [0,1] as the schema requires) and intensity = lux_per_unit · max(E), so color × intensity — what an
// engine multiplies — is lux_per_unit · E, and the illuminance of the light is lux_per_unit · Y(E).
// The irradiance, solid angle and method are kept in "extras".
#pragma once
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "iblkit/lights/light_set.h"

namespace ibl::lights {

struct GltfDesc {
  double lux_per_unit = 1.0;           // lux per unit of probe irradiance (1: pixel values read as cd/m²)
  std::string name = "iblkit lights";  // scene name
};

// Unit quaternion (x, y, z, w) that rotates +Z onto unit vector d.
void quaternion_z_to(Vec3 d, double q[4]);

nlohmann::json to_gltf(const LightSet& set, const GltfDesc& desc = {});
void write_gltf(const std::string& path, const LightSet& set, const GltfDesc& desc = {});

}  // namespace ibl::lights
