// The soft term of the real-time compositor's shadows (augment/gl/): the object stands for a sphere (its
// volume's, or where it is open, its surface's equivalent; centred on its bounds), and the light the sphere
// hides from a surface point is the environment's radiance behind it times the sphere's cosine-weighted
// solid angle, in closed form with the horizon clipped (the sphere-light illuminance of Lagarde & de
// Rousiers, "Moving Frostbite to PBR", SIGGRAPH 2014 course, §4.7.2, after Snyder 1996). Below a cut-off
// share of the hemisphere the term is exactly 0, so that pixels far from the object keep the photograph.
#pragma once
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::augment {

struct OccluderSphere {
  Vec3 centre;
  double radius = 0;        // the equivalent sphere's
  double bound_radius = 0;  // the bounding sphere's (about `centre`), for shadow-map frusta
};

// r = (3V/4π)^⅓ for a closed mesh (V the signed volume, > 0), else √(S/4π) (a convex body's mean shadow
// is S/4: the sphere of the same mean shadow), never above the bounding radius.
OccluderSphere equivalent_sphere(const geometry::TriMesh& object);

// ∫ over the cap of half-angle α (sin²α = sin2_alpha) around an axis at angle β (cos β = cos_beta) from
// the normal of max(0, cos θ) dω, in sr: π sin²α cos β when the cap is wholly above the horizon, 0 when
// wholly below. The GLSL twin is in augment/gl/shaders/augment_common.glsl.
double cap_cosine_integral(double cos_beta, double sin2_alpha);

// The soft irradiance of the object's side that faces each way, for the light the sphere sends back: for a
// direction d (from the object towards a proxy point), the mean over the object's triangles weighted by their
// area seen from d (A max(0, n·d)) of the soft irradiance each receives — E_c(n) from `soft_irradiance` (lat-long,
// the map centre's) times its factor (`factor`: soft_visibility, per triangle; 1 where null). With the factor,
// the floor under the object lights its underside only as far as the object's shadow leaves it lit. Lat-long,
// 2·height × height; 0 in a direction no triangle faces.
Image facing_irradiance(const geometry::TriMesh& object, const std::vector<Vec3>* factor, const Image& soft_irradiance,
                        int height = 16);

}  // namespace ibl::augment
