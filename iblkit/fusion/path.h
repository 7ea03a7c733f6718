// Fused maps and tracked lights along a path (Pedersen 2008 §7, §8.1: the moving object's open
// problem): at every path point a lat-long local map, its localised median-cut lights, and those lights
// tracked twice — identities only ("raw") and identities plus the low-pass filter ("filtered") — so
// that the filter's effect on flicker, shadow-light jitter and fidelity to the maps can be measured on
// the same frames (local_lights.h defines the measures).
#pragma once
#include <functional>
#include <vector>

#include "iblkit/core/progress.h"
#include "iblkit/fusion/fuse.h"
#include "iblkit/fusion/local_lights.h"

namespace ibl::fusion {

struct PathDesc {
  FuseDesc fuse;          // the maps (mapping must be lat-long: the lights are cut from them; progress unused)
  int lights = 16;        // median-cut lights per frame (N ≥ 1)
  TrackDesc track;        // the filtered tracker's settings (the raw one never filters)
  int shadow_lights = 4;  // the first K lights a renderer would give shadow maps (their jitter is measured)
  ProgressFn progress;    // optional: stage "path", per frame
};

// One frame, as fuse_path hands it to its callback (valid during the call).
struct PathFrame {
  size_t index;                          // frame k
  const PathPoint& point;                // where and when
  const LocalMap& map;                   // the fused map at the point
  const lights::LightSet& cut;           // this frame's localised median cut, with its region map
  const lights::LightSet& raw;           // the cut's lights tracked (identities only), in its order, no regions
  const lights::LightSet& filtered;      // the same after the filter, in the same order, no regions
  const std::vector<int>& raw_ids;       // track id of each raw light
  const std::vector<int>& filtered_ids;  // track id of each filtered light
};
using PathFrameFn = std::function<void(const PathFrame&)>;

struct PathResult {
  size_t frames = 0;
  double seconds = 0;                            // wall time of the whole path (the callback's time included)
  FlickerStats map_flicker;                      // the maps' own change from frame to frame
  FlickerStats raw_flicker, filtered_flicker;    // the lights', unfiltered and filtered
  double raw_excess = 0, filtered_excess = 0;    // excess_flicker: the change the maps do not make
  double raw_jitter = 0, filtered_jitter = 0;    // shadow_light_jitter of the first shadow_lights lights, radians
  double raw_vs_maps = 0, filtered_vs_maps = 0;  // lights_vs_maps: how far the lights miss their maps
};

// Fuses a map at every point of the path, cuts and localises desc.lights lights from it, tracks them
// (raw and filtered) and measures the sequence. `on_frame` sees each frame as it is made (to write it
// out); the maps are kept only for the measures. Throws ibl::Error for an empty path, a mapping other
// than lat-long, lights < 1, and whatever fuse() throws for a point.
PathResult fuse_path(const ProbeSet& set, const std::vector<PathPoint>& path, const PathDesc& desc = {},
                     const PathFrameFn& on_frame = {});

}  // namespace ibl::fusion
