// IES LM-63 photometric files (LM-63-1995/2002, type C photometry) as the degenerate, far-field case
// of a measured luminaire: one point light with a goniometric texture (one TexturedSpotlight).
//
// Reads the keyword lines, TILT=NONE (other TILT values are refused), the ten numbers of line 10
// (lamps, lumens per lamp, candela multiplier, vertical and horizontal angle counts, photometric
// type, units, width, length, height), ballast factor, file-generation type, input watts, the angles
// and the candela table (one row of vertical angles per horizontal angle). Horizontal symmetry as the
// standard allows: a single angle (rotationally symmetric), 0–90 (quadrant), 0–180 (bilateral), 0–360.
// Intensity = candela · multiplier · ballast factor, taken as W/sr (the renderer's unit; scale it with
// --scale for photometric work).
// Frame: vertical angle γ = 0 (nadir) is the spotlight's forward axis; horizontal angle C = 0 is its
// right axis and C = 90° its up axis: for a unit direction w in the luminaire frame (x right, y up,
// z forward), γ = acos(w.z), C = atan2(w.y, w.x).
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/vec.h"
#include "iblkit/nearfield/spotlight.h"

namespace ibl::nearfield {

struct IesProfile {
  std::string source;              // file name
  std::vector<double> vertical;    // γ in degrees, increasing
  std::vector<double> horizontal;  // C in degrees, increasing
  std::vector<double> candela;     // [h·nv + v], multiplier and ballast factor applied
  int photometric_type = 1;        // 1 = C
  double lumens = 0;               // lumens per lamp (−1: absolute photometry)

  // Intensity along unit w (luminaire frame), bilinear in (γ, C); 0 outside the vertical range.
  double intensity(Vec3 w) const;
  // Total flux ∫ I dω over the sphere and over the cone γ ≤ max_deg (numerical, 0.25° steps).
  double flux(double max_deg = 180) const;
};

IesProfile read_ies(const std::string& path);
IesProfile parse_ies(const std::string& text, const std::string& what);

// The far-field spotlight of a profile: texture on the plane at distance 1 covering γ ≤ max_deg
// (< 90°), resolution² texels, white light scaled by `scale`.
TexturedSpotlight ies_spotlight(const IesProfile& p, const Placement& placement, double max_deg = 80,
                                int resolution = 256, double scale = 1);

}  // namespace ibl::nearfield
