// Virtual luminaires for the lab: a set of small disc emitters with angular radiance patterns, whose
// light field — and so the exact near-field irradiance anywhere — is an integral over the discs.
// Coordinates are the luminaire frame of dataset.h (S at z = 0, shining along +z); every emitter
// sits at z < 0.
//
//   L_e(ω) = radiance · lobe(ω) · housing(ω)
//   lobe(ω)    = max(0, ω·axis)^exponent · (1 + ripple·cos(facets·φ))   φ = azimuth of ω about axis
//   housing(ω) = 1 for θ_z ≤ cutoff − taper, ½(1 + cos(π(θ_z − cutoff + taper)/taper)) up to cutoff, 0 beyond
// (θ_z the angle between ω and +z). The housing cut-off keeps every ray inside the measured extent of M.
//
// Exact irradiance at x with normal n (no occlusion, or one visibility test per disc centre):
//   E(x, n) = Σ_e ∫_disc L_e(ω_yx) cos θ_e cos θ_x / |x − y|² dA_y
// with the disc integral an equal-area polar rule of rings × sectors points (exact to < 10⁻³ relative
// at 0.1 m for the 2.5 mm discs used here; checked against a 16× finer rule in the tests).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "iblkit/core/progress.h"
#include "iblkit/core/vec.h"
#include "iblkit/nearfield/dataset.h"

namespace ibl::nearfield {

struct DiscEmitter {
  Vec3 center;             // luminaire frame, metres (z < 0)
  Vec3 normal{0, 0, 1};    // the disc faces this way (unit)
  double radius = 0.001;   // metres
  Vec3 radiance{1, 1, 1};  // W/(sr·m²) on the lobe axis
  Vec3 axis{0, 0, 1};      // lobe axis (unit)
  double exponent = 1;     // lobe sharpness
  double ripple = 0;       // azimuthal modulation depth in [0, 1)
  int facets = 0;          // azimuthal modulation frequency (reflector facets)
  Vec3 lobe_ref{1, 0, 0};  // φ = 0 direction about the axis (made orthogonal to it)
};

struct Luminaire {
  std::string name;  // "flashlight", "bikelight"
  std::vector<DiscEmitter> emitters;
  double cutoff_deg = 30;      // housing: no light beyond this angle from +z
  double taper_deg = 5;        // housing: cosine taper width below the cut-off
  int rings = 2, sectors = 8;  // the disc quadrature rule (rings·sectors points per disc)

  // Radiance of emitter e towards unit direction w (luminaire frame).
  Vec3 emitted(const DiscEmitter& e, Vec3 w) const;
  // Quadrature points (position, area weight) of emitter e.
  std::vector<std::pair<Vec3, double>> quadrature(const DiscEmitter& e) const;
  // Exact irradiance at x with unit normal n (luminaire frame); `visible(e)` (optional) says whether
  // emitter e's centre is seen from x (one shadow ray per disc).
  Vec3 irradiance(Vec3 x, Vec3 n, const std::function<bool(int)>& visible = {}) const;
  // Radiant intensity (W/sr) of the whole luminaire along unit w: Σ_e ∫ L_e(w) cos θ_e dA (far field).
  Vec3 intensity(Vec3 w) const;
  // The half-extent of M (metres) that catches every ray at plane distance d: d·tan(cutoff) + size.
  double extent_at(double d) const;
  // Largest |x| and |y| of any emitter point, metres.
  Vec2 half_size() const;
};

// The lab's luminaires: "flashlight" (a warm bulb inside a ring of 24 narrow, faceted reflector
// beams tilted 4° inwards: they cross 11 cm ahead and open into a ring) and "bikelight" (seven LEDs:
// a row of five with different tilts and widths, and two warm ones above). Throws on other names.
Luminaire make_luminaire(const std::string& name);
std::vector<std::string> luminaire_names();

struct SimulateDesc {
  Basis basis = Basis::Biquadratic;  // Φ on S (the filter is its dual)
  int nx = 7, ny = 7;                // filter positions
  double spacing = 0.005;            // h (metres)
  double distance = 0.5;             // d (metres)
  int resolution = 128;              // W = H of the images on M
  double extent = 0;                 // half-extent of M (metres); 0: luminaire.extent_at(d)
};

// Simulates the acquisition: for every filter position (i,j), the irradiance on M behind the
// positive and negative parts of the dual filter (transmittance h²Φ'_ij), by integrating every disc
// emitter: E±_ij(p) = Σ_e ∫ L_e(ω) max(±h²Φ'_ij(c(y,p)), 0) cos θ_e cos θ_M / |p − y|² dA_y, where
// c(y,p) is where the segment y → p crosses S. Images are sampled at pixel centres (bilinear basis on M).
Dataset simulate(const Luminaire& lum, const SimulateDesc& desc, const ProgressFn& progress = {});

}  // namespace ibl::nearfield
