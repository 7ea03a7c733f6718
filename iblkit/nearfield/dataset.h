// A measured (or simulated) luminaire light field in the two-plane setup of Goesele et al. 2003 [1]
// that Granier et al. 2003 [2] render: one pair of images E⁺_ij, E⁻_ij on the measurement plane M per
// position (i,j) of the optical filter on the sampling plane S. Format iblkit.nearfield/1
// (docs/formats.md): a JSON manifest plus one HDR image per measurement.
//
// [1] M. Goesele, X. Granier, W. Heidrich, H.-P. Seidel, "Accurate light source acquisition and
//     rendering", SIGGRAPH 2003 (section 2 of [2]; not in our copy — see docs/nearfield.md).
// [2] X. Granier, M. Goesele, W. Heidrich, H.-P. Seidel, "Interactive visualization of complex
//     real-world light sources", Pacific Graphics 2003, ../shared/papers/004_43a47b47d0ef4e7b.txt.
//
// Luminaire frame (metres): S is the plane z = 0 with s-axis `right` = +x and t-axis `up` = +y; M is
// the plane z = d; `forward` = +z points from S to M (right × up = forward). The luminaire sits at
// z < 0 and shines along +z. Filter (i,j) is centred on S at
//   c_ij = ((i − (nx−1)/2)·h, (j − (ny−1)/2)·h, 0),   i < nx, j < ny, h = spacing.
// Image pixel (x, y) of a W×H measurement covers M coordinates
//   s = m_min.x + (x + ½)·(m_max.x − m_min.x)/W,   t = m_max.y − (y + ½)·(m_max.y − m_min.y)/H
// (row 0 is the largest t, as in any photograph with `up` upwards and `right` to the right, i.e. the
// screen seen from the side of M, looking back towards the luminaire along −forward).
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"

namespace ibl::nearfield {

// The reconstruction basis Φ on S (tensor-product B-splines of spacing h); the physical filter in
// front of the luminaire is its compactly supported dual Φ' (basis.h).
enum class Basis {
  Bilinear,     // Φ: hat of support 2h; dual filter support 3h
  Biquadratic,  // Φ: quadratic B-spline of support 3h; dual filter support 4h (the paper's 5 mm -> 20 mm)
};
const char* basis_name(Basis b);
Basis parse_basis(const std::string& name, const std::string& what);  // throws ibl::Error naming `what`

struct Dataset {
  std::string name;                             // e.g. "flashlight-7x7"
  std::string luminaire;                        // the lab luminaire a simulated dataset came from ("" when measured)
  Basis basis = Basis::Biquadratic;             // Φ on S
  double spacing = 0.005;                       // h: distance between neighbouring filter positions on S, metres
  double filter_width = 0.02;                   // support width of the dual filter Φ' (must match basis and spacing)
  int nx = 5, ny = 5;                           // filter positions along s and t
  double distance = 0.5;                        // d: distance between S and M, metres
  Vec2 m_min{-0.25, -0.25}, m_max{0.25, 0.25};  // extent of every image on M (metres, M's (s,t))
  Basis m_basis = Basis::Bilinear;              // the basis of the images on M (pixels): bilinear = interpolating
  double filter_gain = 1;  // E_ij = gain·(E⁺_ij − E⁻_ij) (transmittance scale of a real slide)
  // Measurements, index j·nx + i, each W×H RGB, non-negative irradiance (W/m²) on M behind the
  // positive and negative parts of the filter Φ'_ij scaled to transmittance h²·Φ'_ij / gain.
  std::vector<Image> positive, negative;

  int count() const { return nx * ny; }
  Vec2 filter_center(int i, int j) const { return {(i - 0.5 * (nx - 1)) * spacing, (j - 0.5 * (ny - 1)) * spacing}; }
  // M coordinates of pixel centre (x, y) of a W×H image.
  Vec2 pixel_to_m(double x, double y, int w, int h) const {
    return {m_min.x + (x + 0.5) * (m_max.x - m_min.x) / w, m_max.y - (y + 0.5) * (m_max.y - m_min.y) / h};
  }
  // The signed measurement E_ij = gain·(E⁺ − E⁻) at (i,j).
  Image measurement(int i, int j) const;
  // Throws ibl::Error naming `what` and the field for: no positions, a missing image, images of
  // different sizes, a filter width that does not match basis and spacing, d ≤ 0, an empty M extent,
  // NaN/Inf/negative pixels.
  void validate(const std::string& what) const;
};

// Reads an iblkit.nearfield/1 manifest and its images (paths relative to the manifest).
Dataset read_dataset(const std::string& manifest_path);
// Writes the manifest and the images (STEM_images/ij_{i}_{j}_pos.exr, …_neg.exr beside the manifest
// STEM.json, so that several datasets can share a folder).
void write_dataset(const std::string& manifest_path, const Dataset& ds);

}  // namespace ibl::nearfield
