// Fusion probe sets (iblkit.probes/1, docs/formats.md): a proxy mesh and several HDR
// probes, each with a position, an optional rotation and a depth map. Depth maps that the manifest
// does not name are traced on the proxy with Embree and cached beside the probe.
//
// Proxy orientation: front faces (counter-clockwise, the OBJ/glTF convention) face the space the
// probes and the fused points live in — inwards for walls, outwards for furniture and pillars. A
// point whose rays mostly reach the back of a face is inside geometry or outside the proxy.
//
// References
//  [1] Pedersen, "Fusing environment maps for IBL in large scenes", MSc thesis, Aalborg 2008,
//      §2.4 step 3, §4.1 step 3 and §5.2 (../shared/papers/003_…): per-probe depth maps.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/core/vec.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/geometry/raytracer.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::fusion {

enum class DepthSource {
  File,      // named by the manifest's "depth"
  Cache,     // read from the cache beside the probe (<image stem>_proxydepth.exr)
  Computed,  // traced on the proxy now
};

struct Probe {
  std::string image;       // radiance file (empty when built in memory)
  std::string depth_file;  // depth file read or written (empty when none)
  Vec3 position;           // where the probe was captured, world metres
  Mat3 rotation;           // probe frame -> world
  sphere::EnvMap radiance{Image(2, 1, 3), sphere::Mapping(sphere::MappingKind::LatLong, 2, 1)};
  Image depth;  // 1 channel, same size as `radiance`: metres from `position` to the proxy
                // along each pixel centre's direction; 0 where the ray leaves the proxy
  DepthSource depth_source = DepthSource::Computed;
  std::vector<float> rgbd;     // lat-long probes: radiance and depth interleaved (R,G,B,depth per pixel), built
                               // by prepare() so that a fused lookup touches one cache line, not two
  double escape_fraction = 0;  // share of the probe's solid angle whose rays leave the proxy
};

struct ProbeSet {
  std::string manifest;                         // the file it came from (empty when in memory)
  geometry::TriMesh proxy;                      // the scene proxy, world metres
  std::shared_ptr<geometry::RayTracer> tracer;  // Embree scene of `proxy` (built by prepare)
  std::vector<Probe> probes;
  std::vector<std::string> warnings;  // e.g. an open proxy; the CLI prints them
};

struct LoadDesc {
  bool use_depth_files = true;  // false: ignore the manifest's depth maps and trace the proxy
  bool use_cache = true;        // read <stem>_proxydepth.exr beside a probe when the manifest names none
  bool write_cache = true;      // write depth maps that had to be traced beside their probes
  bool force_depth = false;     // trace every depth map again (and rewrite the cache)
  ProgressFn progress;          // stages "load", "depth"
};

// Reads an iblkit.probes/1 manifest, its proxy (any mesh file geometry::read_mesh reads) and its
// probes, then calls prepare(). Throws ibl::Error naming the file and field at fault.
ProbeSet load_probe_set(const std::string& manifest, const LoadDesc& desc = {});

// Builds the ray tracer, traces missing depth maps (those with an empty `depth`) and checks the set:
// depth and radiance sizes agree (error), every probe lies inside the proxy (error naming the probe;
// when every probe sees back faces the proxy is turned inside out: flipped, with a warning), rays
// that leave the proxy (warning with the share per probe: the fused map falls back there).
void prepare(ProbeSet& set, const ProgressFn& progress = {});

// Distance from `position` to the proxy through every pixel centre of `mapping` (probe frame,
// turned to the world by `rotation`); 0 where the ray leaves the proxy or the pixel has no direction.
Image trace_depth(const geometry::RayTracer& tracer, const sphere::Mapping& mapping, Vec3 position,
                  const Mat3& rotation);

// Share of `rays` directions (spherical Fibonacci) from x whose first proxy hit is the back of a
// face, among those that hit; and the share that hits nothing (both in [0,1]).
struct PointCheck {
  double backface = 0;  // > 0.5: x is inside geometry or outside the proxy
  double escape = 0;    // rays that leave the proxy
};
PointCheck check_point(const ProbeSet& set, Vec3 x, int rays = 256);

// The cache path of a probe's traced depth map: <image without extension>_proxydepth.exr (not _depth:
// that name is the lab's depth of the real scene).
std::string depth_cache_path(const std::string& image);

}  // namespace ibl::fusion
