// The light at points of the proxy and of the virtual object, with and without the object: the ray-traced
// estimators that the CPU composite (composite.h), the object's soft-light factor (soft_visibility.h) and
// the proxy's albedo (albedo.h) share, so that the three compute one thing one way. Each uses the light
// field's patch samples (light.h) with visibility from Embree; the method is composite.h's.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "iblkit/augment/light.h"
#include "iblkit/augment/rays.h"
#include "iblkit/core/rng.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/geometry/raytracer.h"
#include "iblkit/render/shading.h"

namespace ibl::augment {

// The object's bounding sphere.
struct BoundingSphere {
  Vec3 c;
  double r = 0;
  // Does the segment x + t·w, t in (0, tfar), come within r of c?
  bool meets(Vec3 x, Vec3 w, double tfar) const;
};

// The ray tracers of a composite: the proxy alone, the object alone, both (proxy = mesh 0, object =
// mesh 1), and the light field their estimators sample. Without an object only the proxy's is built.
class Tracers {
 public:
  Tracers(const geometry::TriMesh& proxy, const geometry::TriMesh* object);
  Tracers(const Tracers&) = delete;
  Tracers& operator=(const Tracers&) = delete;

  const geometry::TriMesh& proxy;
  const geometry::TriMesh* object;  // null: no object (the albedo estimate)
  geometry::RayTracer proxy_rt, object_rt, both_rt;
  BoundingSphere bound;               // the object's (r = 0 without one)
  const LightField* light = nullptr;  // set once the light field is made over proxy_rt
};

// E at x (normal n) from `count` stratified patch samples, visibility against `rt`; `shadowed`: the proxy's
// patches darkened by the object's shadow on them (the light an object point receives).
Vec3 irradiance(const Tracers& t, const geometry::RayTracer& rt, Vec3 x, Vec3 n, int count, Rng& rng,
                bool shadowed = false);

// The object's outgoing radiance towards v at z (normal n, diffuse albedo rho): ρ/π E + specular·G, E and G
// from the same `count` patch samples, occluded by proxy and object, the proxy's patches near the object
// darkened by its shadow.
Vec3 object_radiance(const Tracers& t, Vec3 z, Vec3 n, Vec3 v, Vec3 rho, const render::Material& m, int count,
                     Rng& rng);

// The object's light on itself at z (normal n): the irradiance from `count` cosine-weighted directions, each
// that meets the object first (the proxy nearer hides it) on a triangle's front face taking that triangle's
// radiance (tri_radiance: the object's direct light, so one bounce of it on itself). E = π/count · Σ L.
Vec3 self_irradiance(const Tracers& t, const std::vector<Vec3>& tri_radiance, Vec3 z, Vec3 n, int count, Rng& rng);

// The diffuse albedo at a point of object triangle `tri` with barycentrics b1, b2 (the texture at its UVs).
Vec3 object_albedo(const geometry::TriMesh& object, const render::Material& m, uint32_t tri, double b1, double b2);

// What proxy point y (normal n) receives: E₀ (without the object), the part of it the object blocks, and
// (with tri_radiance, the object's radiance per triangle) the object's light on y (composite.h's ΔE terms).
// The blocked light is estimated from two strategies with the balance heuristic (Veach 1997): the `count`
// patch samples E₀ uses (good for the sun, lamps and any small bright source) and `cone_count` directions
// uniform in the cone towards the object's bounding sphere (good where the object covers a small share of a
// broad sky); lamps come from patch samples alone. Only samples that meet the object add to `blocked` and
// `bounce`. Without an object (Tracers made without one) blocked and bounce are 0 and cone_count is ignored.
struct ProxyTerms {
  Vec3 e0, blocked, bounce;
};
ProxyTerms proxy_terms(const Tracers& t, const std::vector<Vec3>* tri_radiance, Vec3 y, Vec3 n, int count,
                       int cone_count, Rng& rng);

// The object's shadow on the proxy patches near it (within 4 bounding radii of its centre), as factors
// E_with / E₀ of their radiance (LightField::set_shadow): the floor under an object does not light its underside.
void shadow_patches(const Tracers& t, LightField& field, int count, int cone_count, uint64_t seed);

// The proxy's Lambertian albedo from a photograph pixel's value and the light E₀ there: ρ = π · photo / E₀
// per channel; `lit` false where some channel receives less than kUnlitIrradiance (ρ is 0 there), `over_one`
// where ρ > 1 in some lit channel (the captured light misses some of what the photograph shows).
struct ProxyAlbedo {
  Vec3 rho;
  bool lit = true, over_one = false;
};
ProxyAlbedo proxy_albedo(Vec3 photo, Vec3 e0);

// The warnings both backends give for the albedo estimate's counts (one wording for CPU and GL).
std::vector<std::string> albedo_warnings(int64_t proxy_pixels, int64_t over_one, int64_t unlit);

// Stream keys (core/rng.h) of the estimators, one per purpose.
enum StreamKey : uint64_t {
  kStreamAlbedo = 0x616c62,      // "alb": a pixel's albedo estimate (the GL path's)
  kStreamPatch = 0x706174,       // "pat": a proxy patch's shadow factor
  kStreamTriangle = 0x747269,    // "tri": an object triangle's radiance
  kStreamObject = 0x6f626a,      // "obj": an object pixel's camera ray
  kStreamProxy = 0x707278,       // "prx": a proxy pixel's terms
  kStreamVisibility = 0x766973,  // "vis": an object triangle's soft-light factor
};

}  // namespace ibl::augment
