// Many probes at once: positions on a grid, along a path or at random in a volume, captured one
// after another and streamed to disk (memory stays at two probes), written as an iblkit.sequence/1
// manifest for the ILF builder or an iblkit.probes/1 set (with its proxy mesh) for fusion.
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/progress.h"
#include "iblkit/lab/capture.h"

namespace ibl::lab {

// nx × ny × nz points spanning [lo, hi] (a count of 1 puts the points in the middle), x fastest.
std::vector<Vec3> grid_positions(Vec3 lo, Vec3 hi, int nx, int ny, int nz);
// `count` points spaced evenly by arc length along the polyline `points` (ends included).
std::vector<Vec3> path_positions(const std::vector<Vec3>& points, int count);
// `count` uniform random points in [lo, hi] (a tracked hand-held capture), fixed by `seed`.
std::vector<Vec3> random_positions(Vec3 lo, Vec3 hi, int count, uint64_t seed);
// `count` random points in `clusters` Gaussian clusters (a capture made at a few spots): cluster c's
// centre is uniform in [lo, hi] shrunk by min(spread, a quarter of the edge) on each side; point i
// belongs to cluster i mod `clusters` and lies at its centre plus an isotropic Gaussian offset of
// standard deviation `spread` metres, redrawn until it falls inside [lo, hi] (clamped after 64
// draws). Everything is keyed by (seed, cluster) and (seed, i), not by `count`: the first n points
// of a larger capture are the n-point capture, so the smaller counts of a study are prefixes.
std::vector<Vec3> cluster_positions(Vec3 lo, Vec3 hi, int clusters, int count, double spread, uint64_t seed);

struct SequenceDesc {
  CaptureDesc capture;             // mapping, size, camera, samples, render settings
  std::string out_dir;             // created if missing
  std::string frame_ext = ".exr";  // image format of every frame
  bool half = false;               // .exr frames as 16-bit halves
  int sheet_probes = 16;           // probes on the contact sheet (evenly picked; 0: no sheet)
};

struct SequenceResult {
  std::string manifest;       // path of sequence.json or probes.json
  std::string contact_sheet;  // path of contact_sheet.png (empty when none)
  size_t probes = 0;          // frames written
  double seconds = 0;         // wall time of capture + writing
};

// Writes OUT/frames/000000.EXT … (with 000000_depth.EXT when capture.depth) and OUT/sequence.json
// (iblkit.sequence/1 plus "scene" and per-probe "depth"; volume = the scene's capture volume when
// every position lies in it, else the positions' bounds).
SequenceResult write_sequence(const Scene& scene, const std::vector<Vec3>& positions, const SequenceDesc& desc,
                              const ProgressFn& progress = {});

// Writes OUT/probes/pK.EXT with OUT/probes/pK_depth.EXT, OUT/proxy.obj and OUT/probes.json
// (iblkit.probes/1). Depth maps are always written (the fusion module may recompute them).
SequenceResult write_probe_set(const Scene& scene, const std::vector<Vec3>& positions, const SequenceDesc& desc,
                               const ProgressFn& progress = {});

}  // namespace ibl::lab
