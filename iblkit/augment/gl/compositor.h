// Differential rendering on the GPU (OpenGL 4.5, headless EGL or a window's context): the real-time twin
// of augment/composite.h. What it computes per frame, for a photograph pixel that sees the proxy at y:
//
//   ΔE(y) = − Σ_l E_l(y) · B_l(y)                                hard lights (split_light.h) the object blocks,
//                                                               B_l from the object's shadow map (PCF) where
//                                                               the proxy's own map says the light reaches y
//           + Ω_cos(y) · (ρ_obj/π · E_face − L_soft(behind))    the soft term: the object's equivalent sphere
//                                                               (sphere_occlusion.h) hides the soft light
//                                                               behind it and reflects its own (one bounce)
//   composite = photo + min(ρ, 1)/π · ΔE,    ρ from estimate_albedo (albedo.h, computed once on the CPU)
//
// E_with − E_without is evaluated as the sum of these terms, the only inputs that differ between the two
// renders, so ΔE is exactly 0 (the pixel is the photograph, bit for bit) where no shadow-map tap sees the
// object and the sphere's cosine-weighted share is below the cut-off. The object is drawn with 4× MSAA
// against the proxy's depth (occluded where the proxy is in front), lit by the soft irradiance (the soft map's
// cosine convolution: the proxy's light as the probe saw it) and the hard lights through both maps.
//
// Interreflection kept: proxy → object as captured, times the factor that turns it into what each triangle
// receives when one is given (set_object's soft_visibility: its own occlusion, the proxy's, the floor under it
// darkened by its shadow, and the parallax from the map's centre, ray traced once per placement on the CPU), object →
// proxy through the sphere (its face towards y lit by the soft irradiance and the hard lights, unshadowed; diffuse,
// with the texture's mean albedo). Not kept: the object's light on itself.
//
// The object's material is render::Material's, as on the CPU: the albedo times the texture at the mesh's
// UVs (bilinear, repeating), and the glossy lobe (Phong or Blinn-Phong, weight `specular`): from the hard
// lights the lobe itself, from the soft map its Phong prefiltered map (render/prefilter.h, made once in
// set_object, the exponent environment_exponent()) looked up along the reflected view ray.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "iblkit/augment/composite.h"
#include "iblkit/augment/sphere_occlusion.h"
#include "iblkit/augment/split_light.h"
#include "iblkit/render/shading.h"

namespace ibl::augment::gl {

struct GlFrameTiming {
  double gpu_ms = 0;   // GL_TIME_ELAPSED over the frame (shadow maps, proxy pass, object pass, blend)
  double wall_ms = 0;  // CPU wall clock until glFinish (the figure that means something on llvmpipe)
};

// The scene that stays while the object moves. Needs a current OpenGL 4.5 context that outlives it.
class Compositor {
 public:
  static constexpr int kMaxLights = 16;  // hard lights (the shaders' MAX_LIGHTS is generated from it)
  Compositor(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy, const SplitLight& light,
             const Image& albedo, const CompositeDesc& desc = {});
  ~Compositor();
  Compositor(const Compositor&) = delete;
  Compositor& operator=(const Compositor&) = delete;

  // The object (world space, at its place) and its material (albedo, texture, glossy lobe); uploaded once.
  // soft_visibility: per triangle, the factor on the soft irradiance (augment::soft_visibility, composite.h: its
  // own occlusion and the proxy's, the floor darkened by its shadow, the parallax); none: 1.
  // Throws ibl::Error on an empty mesh, a material out of range or a visibility of the wrong size.
  void set_object(const geometry::TriMesh& object, const render::Material& material,
                  const std::vector<Vec3>* soft_visibility = nullptr);
  // A Lambertian object of albedo `albedo`.
  void set_object(const geometry::TriMesh& object, Vec3 albedo, const std::vector<Vec3>* soft_visibility = nullptr) {
    set_object(object, render::Material{albedo, {0, 0, 0}}, soft_visibility);
  }
  // One frame with the object moved by `offset` (world metres). gl_rows: the colour texture in GL's row
  // order (bottom up, for a window's Presenter) instead of the photograph's.
  void draw(Vec3 offset = {}, bool gl_rows = false, GlFrameTiming* timing = nullptr);
  // The last frame: RGBA32F, linear radiance.
  unsigned color_texture() const;
  int width() const;
  int height() const;
  // The last frame read back (photograph's rows): composite, coverage mask, difference, and the proxy's
  // composite before the object went over it.
  void read_back(Image* composite, Image* mask, Image* difference, Image* proxy_composite) const;
  const SplitLight& light() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The whole composite on the GPU (a headless context of its own): the albedo estimated on the CPU
// (estimate_albedo, desc.light_samples), the light split, one frame read back. desc.gl holds the GL
// options; the sampling counts of the CPU path other than light_samples are not used. Throws ibl::Error (kind
// Unsupported) when no GL context can be had, and as composite() does on bad input.
CompositeResult composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                          const LocalRadiance& light, const geometry::TriMesh& object, const render::Material& material,
                          const CompositeDesc& desc = {}, GlFrameTiming* timing = nullptr);
// A Lambertian object of albedo `albedo`.
inline CompositeResult composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                                 const LocalRadiance& light, const geometry::TriMesh& object, Vec3 albedo,
                                 const CompositeDesc& desc = {}, GlFrameTiming* timing = nullptr) {
  return composite(photo, cam, proxy, light, object, render::Material{albedo, {0, 0, 0}}, desc, timing);
}

}  // namespace ibl::augment::gl
