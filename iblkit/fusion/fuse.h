// The local environment map at any point x from a probe set (Pedersen 2008 [1], §4.2, §5.2), with the
// per-probe visibility test the thesis describes but left untested (Eq. 5.4), three blends and
// fallbacks for rays that leave the proxy or that no probe sees.
//
// For each output direction ω: trace x + tω against the proxy to the hit point p (normal n). For every
// probe i at x_i, with r_i = |p − x_i| and ω'_i = (p − x_i)/r_i, the probe sees p when
//
//   d_i(ω'_i) > 0  and  r_i ≤ d_i(ω'_i) · (1 + ε + κ·δ_i·min(tan α_i, 20)) + τ     (the shadow-map test)
//
// d_i: the probe's depth at the texel nearest ω'_i; ε = depth_bias (relative: depth precision);
// τ = depth_tolerance (absolute: how far the real surfaces a probe's depth map may show stand in front of
// the proxy — a lamp 5 cm before its wall, a coarse model; occluders nearer than τ to the surface they
// hide go undetected); δ_i = √(4π/N_i) the probe's
// texel angle (N_i pixels); α_i the angle between ω'_i and n. The slope term is the usual slope-scaled
// shadow-map bias: across one texel the depth of a surface seen at incidence α changes by ≈ d·δ·tan α,
// so a nearest-texel lookup needs that much slack; κ = slope_bias. The visible probes' radiances
// L_i(ω'_i) are blended with weights w_i (similarity s_i = ω·ω'_i: both point from a viewer to p):
//
//   nearest    (Eq. 5.3)   w_i = 1 for argmax_i s_i, else 0
//   angle      (Eq. 5.5)   w_i = s_i where s_i ≥ angle_threshold (and > 0), normalised: L = Σ w_i L_i / Σ w_i
//                          (the thesis writes 1/N Σ L_i s_i; its "weighted average" needs Σ w_i)
//   footprint  (ours)      w_i = ((1 + s_i)/2)^k · cos α_i / (r_i² Ω_i),  Ω_i = 4π/N_i
//                          ┌──────────────────────────────────────────────────────────────┐
//                          │ angular term: smooth, > 0 except straight behind → no pops   │
//                          │ cos α/(r² Ω): texels of probe i per m² of surface at p —     │
//                          │ the probe that sees p sharpest counts most                   │
//                          └──────────────────────────────────────────────────────────────┘
// With visibility on, a probe's bilinear lookup is also depth-aware (edge_aware): of its four taps only
// those whose depth is within r_i·(ε + 2κ·δ_i·tan α_i) + τ of r_i count (weights renormalised), so that a
// bright surface behind a depth edge does not bleed onto the near one (e.g. a lit hall seen past a
// corridor's corner: 100× brighter, one texel of smear is a wide band in the fused view).
// Rays that hit nothing (windows, open ends) or whose p no probe sees fall back to the distant lookup
// L = Σ v_i L_i(ω) / Σ v_i with v_i = 1/(|x − x_i|² + h²) (h = 0.1 m), over the probes whose own ray
// along ω leaves the proxy too when the ray left it (all probes when none does); the coverage map
// records which pixels were fused and which fell back.
//
//  [1] Pedersen, "Fusing environment maps for IBL in large scenes", MSc thesis, Aalborg 2008
//      (../shared/papers/003_…).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/fusion/probe_set.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::fusion {

enum class Blend { Nearest, Angle, Footprint };
std::string blend_name(Blend b);          // "nearest", "angle", "footprint"
Blend parse_blend(const std::string& s);  // throws ibl::Error on an unknown name

struct FuseDesc {
  sphere::MappingKind mapping = sphere::MappingKind::LatLong;  // output layout (any sphere/ mapping)
  int size = 64;                   // lat-long height, cube face edge, or disc/octahedral diameter (pixels)
  Blend blend = Blend::Footprint;  // how the probes that see a point are combined
  bool visibility = true;          // the per-probe depth test; false reproduces the thesis's Fig. 7.8
  double depth_bias = 0.01;        // ε: relative depth tolerance of the visibility test
  double depth_tolerance = 0.10;   // τ: absolute tolerance (metres) for depth maps that show more than the proxy
  double slope_bias = 1.5;         // κ: multiplies δ_i·tan α_i, the slope-scaled part of the bias
  double angle_threshold = 0.0;    // angle blend: probes with ω·ω'_i below this cosine are left out
  double angle_power = 4.0;        // footprint blend: k of the angular term ((1 + s)/2)^k
  bool edge_aware = true;          // with visibility: bilinear probe lookups skip taps at another depth
  int samples = 1;                 // n×n rays per output pixel (radiance averaged; depth from the centre)
  bool check_point = true;         // throw when x is inside geometry or outside the proxy
  ProgressFn progress;             // stage "fuse", by rows
};

// What happened to an output pixel's centre ray.
enum class PixelStatus : uint8_t {
  Fused = 0,      // hit the proxy at a point that at least one probe sees
  LeftProxy = 1,  // hit nothing: distant lookup
  Unseen = 2,     // hit the proxy where no probe sees: distant lookup
  NoData = 255,   // the output pixel has no direction (unused cube-cross cell, outside a disc)
};

struct CoverageStats {
  double fused = 0;        // share of the sphere (solid angle) fused from probes that see it
  double left_proxy = 0;   // share whose rays left the proxy
  double unseen = 0;       // share that hit the proxy where no probe sees
  double mean_probes = 0;  // mean number of probes that see a fused pixel (solid-angle weighted)
};

struct LocalMap {
  Vec3 point;                                                                                    // x, world metres
  sphere::EnvMap radiance{Image(2, 1, 3), sphere::Mapping(sphere::MappingKind::LatLong, 2, 1)};  // RGB
  Image depth;                      // 1 channel: |p − x| in metres, 0 where the ray left the proxy
  Image coverage;                   // 1 channel: the number of probes that see the pixel's p (0: fallback)
  std::vector<PixelStatus> status;  // per pixel, row-major
  CoverageStats stats;
  std::vector<std::string> warnings;  // e.g. nothing fused at all
};

// The mapping of an output map: width × height from `size` (see FuseDesc::size).
sphere::Mapping output_mapping(sphere::MappingKind kind, int size);

// The local environment map at x. The set must be prepared (load_probe_set does it). Throws
// ibl::Error for bad settings or when x is inside geometry (with FuseDesc::check_point).
LocalMap fuse(const ProbeSet& set, Vec3 x, const FuseDesc& desc = {});

// Radiance arriving at x from each direction (rays of fuse, in parallel); for pictures other than
// sphere maps, e.g. a pinhole view of the back-projected probes as in the thesis's Fig. 7.8.
std::vector<Vec3> fuse_rays(const ProbeSet& set, Vec3 x, const std::vector<Vec3>& directions, const FuseDesc& desc = {},
                            std::vector<PixelStatus>* status = nullptr);
// One ray of the same.
Vec3 fuse_ray(const ProbeSet& set, Vec3 x, Vec3 omega, const FuseDesc& desc = {}, PixelStatus* status = nullptr);

}  // namespace ibl::fusion
