// Differential rendering (Debevec, "Rendering synthetic objects into real scenes", SIGGRAPH 1998 [1]):
// a virtual object inserted into a photograph with its shading, its occlusion by the local scene, its
// shadows on it and its light reflected onto it. CPU reference, ray traced with Embree.
//
// For a photograph pixel that sees the proxy at y (normal n) and the light field of light.h:
//
//   E₀(y) = Σ_t L_t Ω_t(y) cos θ V_proxy(y, q_t)                 the light there without the object
//   ρ(y)  = π · photo / E₀(y)                                    the proxy's Lambertian albedo [1, §5]
//   ΔE(y) = − Σ_t L_t Ω_t(y) cos θ V_proxy [object blocks y→q_t]  its shadow, from every patch (sun and sky)
//           + ∫_{ω hits the object} L_obj(z(ω)) cos θ dω          its light on y: one bounce object → proxy
//   ┌────────────────────────────────────────────────────────────────┐
//   │ composite = photo + min(ρ, 1)/π · ΔE   (= photo · (1 + ΔE/E₀))  │
//   └────────────────────────────────────────────────────────────────┘
// (ρ > 1 means the captured light misses some of the light the photograph shows; the change is then
// limited to what a white surface would show.)
//
// E₀ is estimated with patch samples (power-and-solid-angle sampling, light.h); the blocked light with
// the same patch samples and directions in the cone of the object's bounding sphere, combined by the balance
// heuristic (multiple importance sampling); only sample rays that meet the object add to ΔE, so a pixel from
// which no ray meets the object keeps the photograph's value exactly. The bounce term uses the cone samples; the
// object's radiance L_obj = ρ_obj/π · E_obj is computed once per triangle. Pixels that see the object
// (camera ray's first hit: the depth test against the proxy) show its render, ρ_obj/π · E_obj(z), with E_obj
// from all patches (so the proxy's light reaches it) occluded by the proxy and the object itself; edge
// pixels mix object and composite by the share of n×n camera rays that hit the object.
//
//  [1] P. Debevec, "Rendering synthetic objects into real scenes: bridging traditional and image-based
//      graphics with global illumination and high dynamic range photography", SIGGRAPH 1998.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "iblkit/augment/light.h"
#include "iblkit/augment/split_light.h"
#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/render/shading.h"

namespace ibl::augment {

// The real-time backend's own options (augment/gl/compositor.h). The options both backends share are
// CompositeDesc's: its albedo estimate takes light_samples and seed, `shadows`, and the object's light on
// the proxy is on when bounce_samples > 0.
struct GlOptions {
  SplitDesc split;              // hard lights (≤ 16) and their threshold
  int shadow_map_size = 512;    // texels per side of each light's two maps (fitted to the object's bounding sphere)
  int pcf = 1;                  // (2·pcf + 1)² taps per shadow lookup
  int msaa = 4;                 // samples per pixel of the object pass (its coverage at edges)
  double soft_cutoff = 4e-3;    // the soft term is 0 where the sphere's cosine-weighted share is below this, whole
                                // above 2×
  int visibility_samples = -1;  // patch samples per object triangle of its soft light's factor (soft_visibility.h);
                                // 0: the object's soft light as the map's centre sees it; −1: kVisibilityRays over
                                // the triangles, 16 to 1024 each
  static constexpr int64_t kVisibilityRays = int64_t(1) << 22;  // 209 a triangle for the 20k-triangle blob
};

struct CompositeDesc {
  int light_samples = 96;      // patch samples per proxy pixel (albedo and shadow)
  int object_samples = 1024;   // patch samples per object pixel (split over its camera rays)
  int bounce_samples = 64;     // cone samples per proxy pixel: the object's light on it (0: no bounce) and its shadow
                               // (MIS); a square is stratified
  int triangle_samples = 64;   // patch samples per object triangle (its radiance for the bounce)
  int pixel_samples = 2;       // n: n×n camera rays per pixel (object coverage at its edges)
  uint64_t seed = 1;           // random streams (same seed, same bytes)
  bool check_geometry = true;  // camera inside the proxy, object intersecting it: errors
  bool shadows = true;         // false: the object pasted without its shadow and light on the proxy (a baseline)
  // The object's light on itself (CPU): one bounce, its triangles' direct radiance seen from its own pixels; the GL
  // backend leaves it out (docs/augment.md).
  bool self_light = true;
  GlOptions gl;         // the real-time backend's own
  ProgressFn progress;  // stages "object", "composite" (by rows)
};

struct CompositeStats {
  int64_t proxy_pixels = 0;     // pixels whose camera ray hits the proxy
  int64_t object_pixels = 0;    // pixels some camera ray of which hits the object
  int64_t changed_pixels = 0;   // proxy pixels with ΔE ≠ 0 (shadowed or lit by the object)
  int64_t albedo_over_one = 0;  // proxy pixels whose estimated albedo exceeds 1 in some channel
  int64_t unlit = 0;            // proxy pixels with no captured light (albedo unknown; left as photographed)
  double seconds = 0;           // wall time of composite()
};

struct CompositeResult {
  Image composite;       // RGB, the photograph with the object
  Image mask;            // 1 channel: the share of each pixel the object covers
  Image difference;      // RGB: composite − photograph (shadow < 0, interreflection > 0)
  Image albedo;          // RGB: estimated proxy albedo (0 off the proxy and where unlit)
  Image render_without;  // RGB: ρ/π E₀ on the proxy (the photograph where the albedo holds)
  Image render_with;     // RGB: ρ/π (E₀ + ΔE) on the proxy, the object's render over it
  CompositeStats stats;
  std::vector<std::string> warnings;  // e.g. albedo > 1, unlit pixels
};

// `photo` is the background (RGB, linear); cam's width and height must be its size; `proxy` the local
// scene (open or closed; its triangles face the camera's side); `object` the virtual object (world space)
// of Lambertian albedo `albedo`. Throws ibl::Error on sizes that disagree, the camera inside the proxy or
// the object intersecting it.
// The object's surface is render's Material (the shading model of `iblkit render`): its albedo, times its
// texture at the mesh's UVs (the blob's and sphere's own parameterisation) where it has one, and a glossy lobe
// of weight `specular` and exponent `exponent` (render::glossy_lobe) lit by the same patch samples. The
// object's light on the proxy carries its diffuse part (the glossy part, seen from the proxy, is left out).
CompositeResult composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                          const LocalRadiance& light, const geometry::TriMesh& object, const render::Material& material,
                          const CompositeDesc& desc = {});
// A Lambertian object of albedo `albedo`.
inline CompositeResult composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                                 const LocalRadiance& light, const geometry::TriMesh& object, Vec3 albedo,
                                 const CompositeDesc& desc = {}) {
  return composite(photo, cam, proxy, light, object, render::Material{albedo, {0, 0, 0}}, desc);
}

}  // namespace ibl::augment
