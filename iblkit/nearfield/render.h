// CPU reference evaluation of near-field lighting: irradiance on receiver planes and views of a scene
// (any list of diffuse surfaces: measured, modelled, or a lab scene through lab::diffuse_surfaces), lit
// either by textured spotlights (Eq. 14 of Granier et al. 2003; one shadow ray per spotlight towards
// its filter centre) or by the virtual luminaire itself (the exact answer: every emitter disc
// integrated, one shadow ray per disc towards its centre — the discs are at most 5 mm across, so
// their visibility is constant to within a penumbra of that size).
// Surfaces are Lambertian: the outgoing radiance is albedo/π · E(x, n). Direct light only.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/raytracer.h"
#include "iblkit/geometry/surface.h"
#include "iblkit/nearfield/luminaire.h"
#include "iblkit/nearfield/spotlight.h"

namespace ibl::nearfield {

// A receiver plane perpendicular to the luminaire's forward axis at distance z from S, facing the
// luminaire, sampled at resolution² pixel centres over [−half_extent, half_extent]² of (right, up);
// row 0 is the largest up coordinate (as the dataset images).
struct PlaneDesc {
  double z = 1;              // distance from S along forward (metres)
  double half_extent = 0.5;  // metres
  int resolution = 128;      // pixels per side
};

// Irradiance (W/m², RGB) on the plane from the spotlights (no occlusion), `placement` locating the plane.
Image plane_irradiance(const std::vector<TexturedSpotlight>& lights, const Placement& placement,
                       const PlaneDesc& plane);
// The exact irradiance from the luminaire (luminaire frame, no occlusion).
Image plane_irradiance_exact(const Luminaire& lum, const PlaneDesc& plane);

// Error of an approximation against the exact image, on luminance: RMS and mean |difference| divided
// by the mean exact value, the largest |difference| divided by the largest exact value, and the
// ratio of totals (power on the plane).
struct ErrorStats {
  double rel_rms = 0, rel_mean_abs = 0, rel_max = 0, power_ratio = 1;
};
ErrorStats compare(const Image& approx, const Image& exact);

// A scene's diffuse surfaces in a ray tracer of their own. `name` is for messages.
class SceneView {
 public:
  SceneView(std::vector<geometry::DiffuseSurface> surfaces, std::string name);
  const std::string& name() const { return name_; }
  // First diffuse hit of the camera ray through the centre of pixel (x, y): position, normal (towards
  // the eye), albedo; false when the ray leaves the scene.
  bool primary(const geometry::Camera& view, int x, int y, Vec3* p, Vec3* n, Vec3* albedo) const;
  // True when the segment p → q is blocked (p is offset along its normal by the caller).
  bool blocked(Vec3 p, Vec3 q) const;

 private:
  std::string name_;
  std::vector<geometry::DiffuseSurface> surfaces_;  // the ones with triangles, in ray tracer mesh order
  geometry::RayTracer tracer_;
};

// Outgoing radiance images (RGB, W/(sr·m²)). `shadows` false drops every visibility test.
// `srgbe_group` > 0 emulates the paper's 8-bit frame buffer (§4.1–4.2): the spotlights are summed in
// passes of that many (the paper: 3), and after every pass the running irradiance sum is stored as
// sRGBE (rgbe.h) and read back, as between the paper's rendering passes.
Image render_spotlights(const SceneView& sv, const std::vector<TexturedSpotlight>& lights, const geometry::Camera& view,
                        bool shadows, const ProgressFn& progress = {}, int srgbe_group = 0);
Image render_exact(const SceneView& sv, const Luminaire& lum, const Placement& placement, const geometry::Camera& view,
                   bool shadows, const ProgressFn& progress = {});

}  // namespace ibl::nearfield
