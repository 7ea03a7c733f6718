// The captured light of a composite from files, checked against where the object goes:
//   probes   an iblkit.probes/1 set: one probe is Debevec's case (its map at its position, its depth map
//            when the manifest names one); several are fused at the object's centre (fusion::fuse)
//   grid     an SH grid (.shgrid) plus a proxy mesh (Löw et al.): the grid's radiance at the object's centre
//   probe    one probe image at a given position plus a proxy mesh (optionally its depth map)
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "iblkit/augment/light.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/io/envmap_io.h"

namespace ibl::augment {

struct LightInput {
  std::string probes;            // iblkit.probes/1 manifest (exclusive with `light`)
  std::string light;             // .shgrid or a probe image
  std::string proxy;             // mesh file: the local scene (with `light`)
  std::optional<Vec3> at_probe;  // a probe image's position (required for a probe image)
  std::string probe_depth;       // optional depth map of a probe image (metres, 1 channel, its size)
  io::EnvReadDesc read;          // how a probe image is read
  int grid_map_size = 64;        // lat-long height of the grid's map at the object
  int fused_map_size = 128;      // lat-long height of the fused map
};

struct LoadedLight {
  LocalRadiance light;
  geometry::TriMesh proxy;
  std::vector<std::string> warnings;  // a probe outside the proxy, an object reaching outside a grid
};

// object_lo/hi: the object's bounds (world). Throws ibl::Error when the inputs disagree, the object's
// centre lies outside the grid's volume or outside the proxy (any light); a probe outside the proxy is a warning.
LoadedLight load_light(const LightInput& in, Vec3 object_lo, Vec3 object_hi);

}  // namespace ibl::augment
