// Lights from a fused local map, localised by its depth channel (Pedersen 2008 [1] §4.2, §5.3.1
// "Shadow handling"), and their tracking along a path of a moving object: identities kept from frame
// to frame and positions/powers low-pass filtered, the thesis's open problem (§7, §8.1).
//
// Localisation: median cut (lights/) on the lat-long fused map, each light placed by its region's depths
// (lights/place.h: the one placement rule, the energy-weighted median depth); the set's origin is the
// map's point x, and a positioned light is a point light of intensity E·|P − x|² (W/sr), which gives back
// the cut's irradiance E at x.
//
// Tracking: frame k's lights are matched to the tracks of frame k−1 by a minimum-cost assignment
// (Hungarian method) on c = 1 − d_a·d_b + ½·|ln(Y_a/Y_b)| (direction and power), then each track is
// filtered with an exponential moving average of time constant τ: α = 1 − exp(−Δt/τ),
//   P̄ ← P̄ + α(P − P̄)   (directions of unpositioned lights: d̄ ← normalise(d̄ + α(d − d̄)))
//   Ē ← Ē + α(E − Ē), then all Ē scaled by Σ Y(E)/Σ Y(Ē) so that the frame's total stays the map's.
//
// Flicker of a sequence of light sets: F_k = RMS_n |E_k(n) − E_{k−1}(n)| / mean_n E_k(n), irradiance
// E(n) = Σ_i E_i max(0, n·d_i) over 1280 normals (icosphere level 3), averaged over frames.
//
//  [1] Pedersen, "Fusing environment maps for IBL in large scenes", MSc thesis, Aalborg 2008.
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include "iblkit/core/error.h"
#include "iblkit/fusion/fuse.h"
#include "iblkit/lights/light_set.h"

namespace ibl::fusion {

struct LocalLightsDesc {
  int count = 16;                 // median-cut lights (any N ≥ 1)
  double min_separation_deg = 0;  // merge lights closer than this (lights/ CutDesc), 0: off
};

// Lights of a lat-long fused map (throws ibl::Error for another mapping), localised by its depth.
lights::LightSet localize_lights(const LocalMap& map, const LocalLightsDesc& desc = {});

// ---- paths ------------------------------------------------------------------------------------

struct PathPoint {
  Vec3 position;    // world metres
  double time = 0;  // seconds; frame index when the path has no times
};
// A path file: {"format":"iblkit.path/1","points":[{"position":[x,y,z],"time":t}, …]} ("time"
// optional, increasing, on every point or none) or a bare array [[x,y,z], …]. Throws ibl::Error.
std::vector<PathPoint> read_path(const std::string& path);

struct TrackDesc {
  bool filter = true;          // false: identities only, no low-pass filter
  double time_constant = 2.0;  // τ of the filter, in the path's time unit (frames when untimed)
};

// Frame-to-frame light tracking and filtering.
class LightTracker {
 public:
  explicit LightTracker(const TrackDesc& desc = {}) : desc_(desc) {
    if (!(desc.time_constant > 0) || !std::isfinite(desc.time_constant))
      fail(ErrorKind::Value, "light tracker: time constant {} must be a finite number > 0", desc.time_constant);
  }
  // Takes frame k's raw lights (dt: time since the previous frame) and returns the filtered set, in the
  // raw set's order, with ids()[j] the track of light j (tracks keep their id for their whole life).
  lights::LightSet update(const lights::LightSet& raw, double dt);
  const std::vector<int>& ids() const { return ids_; }

 private:
  struct Track {
    int id;
    Vec3 direction, irradiance;
    std::optional<Vec3> position;
    double solid_angle;
  };
  TrackDesc desc_;
  std::vector<Track> tracks_;
  std::vector<int> ids_;
  int next_id_ = 0;
};

// Minimum-cost assignment of rows to columns of an n×m cost matrix (row-major): result[r] = column of
// row r, or −1 when n > m leaves it unassigned.
std::vector<int> assign_min_cost(const std::vector<double>& cost, int rows, int cols);

struct FlickerStats {
  double mean = 0;  // mean over frame pairs of F_k
  double max = 0;   // max over frame pairs
};
// Flicker of a sequence of light sets (their irradiance field at each set's own origin).
FlickerStats light_flicker(const std::vector<lights::LightSet>& frames);
// The same measure for a sequence of maps (their exact irradiance fields): the change the scene itself makes.
FlickerStats map_flicker(const std::vector<sphere::EnvMap>& maps);
// The part of the lights' change that the maps do not make: mean over frame pairs of
// RMS_n |(E_k − E_{k−1}) − (M_k − M_{k−1})| / mean_n M_k (E: the lights' field, M: the map's).
double excess_flicker(const std::vector<lights::LightSet>& frames, const std::vector<sphere::EnvMap>& maps);
// How far the shadow-casting lights jump: mean over frame pairs of the luminance-weighted angle (radians)
// between each of the first `count` lights of frame k (shadow-map priority order) and the light with
// the same track id in frame k−1 (lights without one there are skipped).
double shadow_light_jitter(const std::vector<lights::LightSet>& frames, const std::vector<std::vector<int>>& ids,
                           int count);
// Mean over frames of RMS_n |E_lights(n) − E_map(n)| / mean_n E_map(n): how far filtered lights lag
// behind (or raw lights miss) the map they stand for.
double lights_vs_maps(const std::vector<lights::LightSet>& frames, const std::vector<sphere::EnvMap>& maps);

}  // namespace ibl::fusion
