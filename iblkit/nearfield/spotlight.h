// One term of Granier et al.'s Eq. 14 as a textured spotlight, and the exact function every renderer
// (CPU reference here, GL in render/gl) evaluates for it. Keep the two in step: the GLSL mirrors the
// formulas below line by line.
//
// Direct illumination of a point x with unit normal n (Eq. 14, irradiance form):
//
//   E(x, n) = Σ_mn V_mn(x) · A · cos θ · cos θ' / δ² · Ē'_mn(x)
//
// with, for spotlight mn (fields of TexturedSpotlight):
//   q      = x − position                      (position = filter centre c_mn on S, world)
//   z      = dot(q, forward)                   (forward = normal of S, from S towards M)
//   δ²     = dot(q, q);   cos θ = z / δ        (angle at the light, against S's normal)
//   cos θ' = dot(n, −q) / δ                    (angle at the receiver)
//   the term is 0 when z ≤ 0 or cos θ' ≤ 0 (x behind S, or facing away)
//   (s, t) = (dot(q, right), dot(q, up)) · d / z      (d = plane_distance; where the ray from the
//                                                      spotlight through x meets M, in metres, relative
//                                                      to the foot point position + d·forward)
//   u      = (s − tex_min.x) / (tex_max.x − tex_min.x)
//   v      = (tex_max.y − t) / (tex_max.y − tex_min.y)     (v = 0 is texture row 0 = the LARGEST t)
//   footprint = support_width · |1 − d / z|   (Φ_mn's footprint on S projected from x through S onto M)
//   texel  = max((tex_max.x − tex_min.x) / W0, (tex_max.y − tex_min.y) / H0)   (level 0 is W0×H0)
//   λ      = clamp(log2(footprint / texel), 0, L − 1)     (λ = 0 when footprint = 0; L = mip levels)
//   Ē'     = (1 − f)·bilinear(level a, u, v) + f·bilinear(level b, u, v),
//            a = floor(λ), b = min(a + 1, L − 1), f = λ − a
//   bilinear(level, u, v): px = u·W_l − ½, py = v·H_l − ½ (texel centres at half-integers),
//            weights from the fractional parts, texels outside the level read as 0.
// That is exactly textureLod(tex, vec2(u, v), λ) with GL_LINEAR_MIPMAP_LINEAR, GL_CLAMP_TO_BORDER and
// a zero border colour, when level l of the GL texture is mips[l] uploaded row 0 first (so that GL's
// t = 0 is row 0). Mip level l+1 is the 2×2 box average of level l, sized max(1, ⌊W_l/2⌋) ×
// max(1, ⌊H_l/2⌋) (an odd last row/column is dropped, as GL's level sizes require).
//
// Frame: frame.t = right (s axis), frame.b = up (t axis), frame.n = forward, with right × up = forward.
// Units: A in m², Ē' in W/(sr·m²) (radiance), E in W/m². Textures may hold negative texels (the dual
// filter has negative lobes); the sum over all spotlights is the light field's irradiance.
#pragma once
#include <memory>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"

namespace ibl::nearfield {

struct Dataset;

struct TexturedSpotlight {
  Vec3 position;              // filter centre c_mn on the sampling plane S (world, metres)
  Frame frame;                // t = right (s axis), b = up (t axis), n = forward (S -> M), world
  double plane_distance = 1;  // d between S and M (metres)
  Vec2 tex_min, tex_max;      // texture extent on M, (right, up) metres relative to position + d·forward
  std::shared_ptr<const std::vector<Image>> mips;  // E'_mn RGB radiance texture, level 0 full size, 2×2 box chain
  double support_area = 1;                         // A = ∫ Φ_mn du dv (m²); h² for the B-spline bases
  double support_width = 0;  // width of the box Ē' averages over on S (metres): half Φ_mn's support,
                             // where its weight sits (docs/nearfield.md); 0 = no filtering (a point light)
  bool shadow = true;        // cast shadows (V_mn from a shadow ray / shadow map towards position)
};

// Ē'(x): the trilinear texture lookup above (no geometric factors). Zero behind S.
Vec3 texture_lookup(const TexturedSpotlight& L, Vec3 x);
// A·cos θ·cos θ'/δ²·Ē'(x) without visibility (the header's formula).
Vec3 irradiance(const TexturedSpotlight& L, Vec3 x, Vec3 n);

// The 2×2 box mip chain of an RGB image, level 0 = a copy of img, down to 1×1.
std::vector<Image> build_mips(const Image& img);

// Where a luminaire sits in the world: its S origin (the centre of the filter grid) and orientation.
struct Placement {
  Vec3 position{0, 1, 0};  // world position of S's origin (metres)
  Vec3 forward{0, 0, 1};   // the direction the luminaire shines (normal of S towards M)
  Vec3 up_hint{0, 1, 0};   // S's t axis is this, made orthogonal to forward
  // right = normalize(cross(up_hint, forward)), up = cross(forward, right). Throws when degenerate.
  Frame frame() const;
  Vec3 to_world(Vec3 local) const;  // luminaire frame (x right, y up, z forward) -> world
};

// The nx·ny spotlights of a dataset placed in the world (reconstruct.h computes the E' textures; this
// is the same as reconstruct then place). `shadow` sets every spotlight's flag.
std::vector<TexturedSpotlight> spotlights(const Dataset& ds, const Placement& placement, bool shadow = true);

}  // namespace ibl::nearfield
