// Export of 3-band SH radiance coefficients into other engines' layouts (docs/formats.md). Each is
// a conversion of iblkit's coefficients (docs/conventions.md: real, orthonormal, no Condon–Shortley phase,
// world axes +Y up, right-handed — the same axes as three.js, Filament and glTF; but Filament's cmgen
// puts a lat-long probe into its world turned by 90° about +Y relative to iblkit and three.js, see
// filament_from_iblkit):
//
//  - threejs:  SphericalHarmonics3 [1]: radiance coefficients in the same basis and order, as
//              the flat array of 27 numbers that SphericalHarmonics3.fromArray() reads.
//  - filament: cmgen's sh.txt [2]: the shader-ready, "pre-scaled" irradiance of
//              Irradiance_SphericalHarmonics(n) = Σ_i s_i p_i(n), p = (1, y, z, x, yx, yz, 3z²−1,
//              zx, x²−y²), which is E(n)/π (the Lambertian 1/π folded in):
//              s_i = (Â_l / π) · K_i · L'_i with K_i the constant of the basis polynomial and L' the
//              radiance turned into cmgen's frame (L'(d) = L(Mᵀd), M = filament_from_iblkit()), so
//              that the file equals `cmgen --sh=3 --sh-shader --sh-window=no` on the same probe.
//  - gltf:     EXT_lights_image_based "irradianceCoefficients" [3]: the 9×3 SH coefficients of
//              irradiance E_lm = Â_l L_lm in the basis its reference loader (Babylon.js) evaluates,
//              which carries the Condon–Shortley phase: odd-m coefficients change sign.
//
// References
//  [1] three.js src/math/SphericalHarmonics3.js (getAt, fromArray).
//  [2] Filament libs/ibl CubemapSH (preprocessSHForShader, renderPreScaledSH3Bands), cmgen.
//  [3] KhronosGroup/glTF extensions/2.0/Vendor/EXT_lights_image_based; Babylon.js
//      sphericalPolynomial (SH3ylmBasisConstants) and its EXT_lights_image_based loader.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "iblkit/sh/coeffs.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::sh {

enum class ExportFormat { Iblkit, ThreeJs, Filament, Gltf };
std::string export_format_name(ExportFormat f);
// "iblkit", "threejs", "filament", "gltf"; throws ibl::Error on anything else.
ExportFormat parse_export_format(const std::string& name);

// The 9 values each layout stores, from radiance coefficients (bands ≠ 3 are truncated or
// zero-padded to 3 bands; truncation does not change the lower coefficients).
Coeffs to_threejs(const Coeffs& radiance);
// The rotation M from iblkit's world to the world in which cmgen (Filament's tool, its default
// mirrored output) places the same lat-long file: d_filament = M d_iblkit, (x, y, z) ↦ (−z, y, x).
// A spot that iblkit sees at +X, cmgen's cube maps and SH see at +Z; iblkit's +Z is cmgen's −X.
// Found by running cmgen on lat-longs with bright spots at known directions; proved by
// ShExport.FilamentMatchesCmgen and engine's SpecularCmgen tests (docs/conventions.md).
Mat3 filament_from_iblkit();
// The frame cmgen puts a probe file of mapping k in. cmgen reads lat-longs and cube maps; it turns
// every cube map it builds or reads by its default mirror (x ↦ −x, "Mirroring..."), so
//   - a lat-long: filament_from_iblkit() (its equirect convention, then the mirror: a rotation);
//   - a cube layout (crosses, strips, six faces): diag(−1, 1, 1), the mirror alone (iblkit reads
//     faces in the GL orientation as they are);
//   - mappings cmgen does not read (mirror ball, angular, octahedral): as a lat-long, the file a
//     user converts them to (iblkit convert) before running cmgen.
Mat3 filament_frame(sphere::MappingKind k);
Coeffs to_filament(const Coeffs& radiance, const Mat3& frame = filament_from_iblkit());
Coeffs to_gltf(const Coeffs& radiance);
// Inverses, for round-trip tests and for reading other engines' numbers back.
Coeffs from_filament(const Coeffs& filament, const Mat3& frame = filament_from_iblkit());
Coeffs from_gltf(const Coeffs& gltf);

// The file text of each layout: iblkit.sh/1 JSON (all bands), three.js JSON
// {"type":"SphericalHarmonics3","coefficients":[27 numbers]}, Filament sh.txt lines
// "( r, g, b); // L00, irradiance, pre-scaled base", glTF JSON fragment
// a whole glTF 2.0 document (asset, extensionsUsed, the EXT_lights_image_based light with its
// "irradianceCoefficients" [[r,g,b]×9], and scene 0 referring to it) — see gltf_ibl_text.
// `filament_frame`: the frame of the Filament layout (filament_frame of the probe's mapping).
std::string export_text(const Coeffs& radiance, ExportFormat f, const Mat3& filament_frame = filament_from_iblkit());

// The prefiltered specular cube EXT_lights_image_based also requires: per mip level the URIs of its six
// face images (+X −X +Y −Y +Z −Z; the extension's RGBD PNGs, which engine::write_gltf_ibl writes
// with this document), level 0 of `size` pixels. Empty: the light carries the irradiance alone.
struct GltfSpecular {
  std::vector<std::array<std::string, 6>> levels;
  int size = 0;
};
// The glTF document of export_text(…, Gltf), with the specular images listed in "images" and
// referenced from the light's "specularImages" (N×6 image indices) and "specularImageSize" when given.
std::string gltf_ibl_text(const Coeffs& radiance, const GltfSpecular& specular = {});

}  // namespace ibl::sh
