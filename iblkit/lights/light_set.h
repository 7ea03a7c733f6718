// Directional light sets: the result of every extraction method, their iblkit.lights/1 JSON form,
// the lat-long grid the methods work on, shadow-map ranking and minimum-separation merging.
//
// A directional light is (direction towards the light, irradiance it delivers at normal incidence);
// its radiance is irradiance / solid angle (docs/conventions.md, "Directional lights").
//
// References
//  [1] Debevec, "A median cut algorithm for light probe sampling", SIGGRAPH 2005 poster.
//  [2] Madsen & Laursen, "A scalable GPU-based approach to shading and shadowing for photo-realistic
//      real-time augmented reality", GRAPP 2007 (../shared/papers/001_…).
//  [3] Pedersen, "Fusing environment maps for IBL in large scenes", 2008, §5.3.1 (../shared/papers/003_…).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::lights {

struct Light {
  Vec3 direction;                // unit vector towards the light (world frame of the probe)
  Vec3 irradiance;               // RGB irradiance at normal incidence, W/m² (Σ L·dω over its region)
  double solid_angle = 0;        // sr of the probe region the light stands for
  std::optional<Vec3> position;  // where the light sits when localised (fusion), world metres
  Vec3 radiance() const { return solid_angle > 0 ? irradiance / solid_angle : Vec3{}; }
};

// Which light each pixel of a lat-long grid belongs to (−1: none). Drawn by the overlay picture.
struct RegionMap {
  int width = 0, height = 0;
  std::vector<int32_t> label;
  bool empty() const { return label.empty(); }
  int32_t at(int x, int y) const { return label[static_cast<size_t>(y) * width + x]; }
};

struct LightSet {
  std::string method;         // "median-cut", "variance-cut", "optimize", or the name from a file
  std::vector<Light> lights;  // in shadow-map priority order (rank_for_shadows)
  RegionMap regions;          // optional: the region of every light on the lat-long grid
  // Optional (fusion): the point whose irradiance the lights' `irradiance` values are, world metres.
  // A light with a position is then a point light of intensity irradiance·|position − origin|² (W/sr).
  std::optional<Vec3> origin;
};

// The irradiance light `l` of `set` delivers on a surface at x with unit normal n (no visibility): a
// directional light E·max(0, n·d); a positioned light (its position and the set's origin known) the point
// light of intensity E·|position − origin|², which gives back E at the origin (docs/conventions.md,
// "Directional lights"). The one rule for fusion's localised lights and the GL compositor's hard lights.
inline Vec3 irradiance_at(const LightSet& set, const Light& l, Vec3 x, Vec3 n) {
  if (!l.position || !set.origin) return l.irradiance * std::max(0.0, dot(n, l.direction));
  const Vec3 v = *l.position - x;
  const double r2 = dot(v, v);
  if (!(r2 > 0)) return {};
  const Vec3 c = *l.position - *set.origin;
  return l.irradiance * (dot(c, c) / r2 * std::max(0.0, dot(n, v) / std::sqrt(r2)));
}

// Sum of the lights' irradiance (RGB) — equals ∫ L dω of the probe for every cut.
Vec3 total_irradiance(const LightSet& set);

// ---- the grid the cut methods work on ------------------------------------------------------------

// A probe as a lat-long grid with exact pixel solid angles: what median cut and variance cut read.
struct LatLongGrid {
  int width = 0, height = 0;
  std::vector<Vec3> rgb;                       // radiance, row-major
  std::vector<double> row_solid_angle;         // exact solid angle of one pixel of row y (2π/W)(cosθ0 − cosθ1)
  Vec3 direction(double px, double py) const;  // direction through continuous pixel coordinates
};

// Checks a probe for the errors every method reports the same way (empty, NaN/Inf, negative,
// all black) and for a light count that the probe can serve (1 ≤ count ≤ pixels with light).
// Throws ibl::Error naming the problem.
void validate_probe(const sphere::EnvMap& env, int count);

// The probe as a lat-long grid. Lat-long input is used pixel for pixel; other mappings are resampled
// (sphere::resample) to a lat-long of the same pixel count (height = round(√(pixels/2))).
LatLongGrid to_latlong_grid(const sphere::EnvMap& env);

// ---- post-processing shared by every method ---------------------------------------------------------

// Shadow-map priority score of a light: its luminance radiance Y(E)/Ω. For the equal-energy regions
// of median cut this orders by smallest area first, as Pedersen [3] proposes; for equal areas it
// orders by brightness ("the smallest-area, brightest first").
double shadow_score(const Light& l);
// Sorts the lights by descending shadow_score (relabelling the region map): lights[0..K) are the K
// that deserve shadow maps.
void rank_for_shadows(LightSet& set);

// Merges lights closer than `min_separation_rad` (greedy, brightest first): the merged light sits at
// the irradiance-weighted mean direction and carries the sum of irradiance and solid angle. Returns
// the number of merges. Regions are merged with their lights.
int merge_close_lights(LightSet& set, double min_separation_rad);

// ---- iblkit.lights/1 ----------------------------------------------------------------------------

nlohmann::json to_json(const LightSet& set);
// Throws ibl::Error (Format) naming the field at fault.
LightSet from_json(const nlohmann::json& j, const std::string& what = "lights");
void write_lights(const std::string& path, const LightSet& set);
LightSet read_lights(const std::string& path);

}  // namespace ibl::lights
