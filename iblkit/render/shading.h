// What the renderers compute at a surface point: one shading model, written once here in C++ (the
// CPU reference uses it directly; the GLSL in gl/shaders/shade.frag implements the same formulas and
// a test holds the two to a named tolerance).
//
// Outgoing radiance towards the eye at point p with normal n, reflection vector r = reflect(−v, n):
//   L_o = (albedo/π)·E(n) + specular·G(r)
// with, for a distant SH environment or an SH grid sampled at p (coefficients c_lm),
//   E(n) = Σ_lm Â_l c_lm Y_lm(n)         Â_l: clamped cosine (Ramamoorthi & Hanrahan 2001)
//   G(r) = Σ_lm ρ̂_l(s) c_lm Y_lm(r)      ρ̂_l(s): normalised Phong lobe (s+1)/2π (r·ω)^s, its
//                                          zonal harmonics rotated to r (Löw et al. 2009 §4)
// and for each directional light (direction l towards the light, irradiance E_i, visibility V_i)
//   E(n) += V_i E_i max(0, n·l),   G(r) += V_i E_i (s+1)/2π max(0, r·l)^s   (only where n·l > 0),
// point lights the same with l = (q − p)/|q − p| and E_i = I_i/|q − p|², and textured spotlights with
// l towards the spotlight and E_i·max(0, n·l) = nearfield::irradiance(spot, p, n) (which may be
// negative for one term: the dual filter's lobes; the sum of all terms is not).
// A distant probe may instead give G(r) through a prefiltered map (render/prefilter.h): G(r) = G_s(r).
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/nearfield/spotlight.h"
#include "iblkit/render/prefilter.h"
#include "iblkit/sh/coeffs.h"

namespace ibl::render {

enum class Lobe {
  Phong,       // (s+1)/2π (r·l)^s: the lobe Löw et al. filter SH with (zonal harmonics about r)
  BlinnPhong,  // (s+8)/8π (n·h)^s (n·l) for lights (h the half vector); for SH and prefiltered maps,
               // the Phong lobe of exponent s/4, its usual equivalent (Blinn's (n·h)^s ≈ (r·l)^(s/4))
};

struct Material {
  Vec3 albedo{0.8, 0.8, 0.8};  // Lambertian reflectance (RGB, 0..1)
  Vec3 specular{0, 0, 0};      // weight of the normalised glossy lobe (RGB)
  double exponent = 20.0;      // exponent s of the glossy lobe
  Lobe lobe = Lobe::Phong;     // shape of the glossy lobe
  // Albedo texture (linear RGB), multiplying `albedo` at the mesh's UVs: bilinear, repeating, uv (0,0)
  // at the image's bottom-left (OBJ/GL). Meshes without UVs read it at (0,0).
  std::shared_ptr<const Image> texture;
  // Exponent of the Phong lobe that filters SH and prefiltered maps for this material.
  double environment_exponent() const { return lobe == Lobe::BlinnPhong ? exponent / 4 : exponent; }
};

// The one check of a material, for every renderer and compositor: albedo and glossy weight finite and in
// [0, 1] per channel, the lobe's exponent in [1, 10000], a texture (when given) a non-empty RGB image.
// `who` starts the message ("object", "object 2"). Throws ibl::Error (ErrorKind::Value).
void check_material(const Material& m, const std::string& who = "object");

// The albedo texture's value at uv (the lookup both renderers make).
Vec3 texture_albedo(const Image& texture, Vec2 uv);

// The glossy lobe for light arriving along unit l (towards the light) at a point of normal n seen along v
// (towards the eye; r = reflect(−v, n)), per unit irradiance at normal incidence: Phong (s+1)/2π max(0, r·l)^s,
// Blinn-Phong (s+8)/8π max(0, n·h)^s (n·l); 0 where n·l ≤ 0. What shade() adds for each light, times `specular`.
double glossy_lobe(const Material& m, Vec3 n, Vec3 v, Vec3 r, Vec3 l);

struct DirectionalLight {
  Vec3 direction;       // unit direction towards the light
  Vec3 irradiance;      // W/m² delivered at normal incidence (RGB)
  bool shadow = false;  // cast shadows (shadow rays on the CPU, shadow maps on the GPU)
};

// An isotropic point light: E = I/d² at normal incidence. Fusion's localised lights (a light of
// irradiance E at the set's origin o, sitting at position q) become I = E·|q − o|² (docs/fusion.md).
struct PointLight {
  Vec3 position;        // world metres
  Vec3 intensity;       // radiant intensity, W/sr (RGB)
  bool shadow = false;  // shadow rays on the CPU; a perspective shadow map on the GPU
};

struct Lighting {
  std::optional<sh::Coeffs> environment;  // distant light
  std::optional<ilf::SHGrid> grid;        // local light field (takes precedence over environment)
  std::vector<DirectionalLight> lights;   // directional lights
  std::vector<PointLight> point_lights;   // point lights (e.g. fusion's localised lights)
  // Textured spotlights: the terms of a measured luminaire's near field (Granier et al. 2003,
  // Eq. 14; nearfield/spotlight.h defines each term's irradiance E_i(p, n), visibility towards its
  // filter centre).
  std::vector<nearfield::TexturedSpotlight> spotlights;
  // Glossy term of a distant probe without the SH band limit (render/prefilter.h): a material whose
  // exponent equals a map's takes G(r) from the map instead of from the SH environment.
  std::vector<GlossyMap> glossy_maps;
  // The map for exponent s, or null.
  const GlossyMap* glossy_map(double s) const {
    for (const auto& g : glossy_maps)
      if (g.exponent == s) return &g;
    return nullptr;
  }
};

// Visibility of a light from point p: true when nothing blocks the segment from p along the unit
// direction `to_light` for `distance` metres (+inf for a directional light). Null: all lit.
using VisibilityFn = std::function<bool(Vec3 p, Vec3 to_light, double distance)>;

Vec3 shade(const Lighting& lighting, const Material& m, Vec3 p, Vec3 n, Vec3 v, const VisibilityFn& visible = {});

}  // namespace ibl::render
