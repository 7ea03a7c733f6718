// Radiance along a ray in a lab scene.
//
// L(o, d) = Le(hit, −d)                                  emission seen at the first hit
//         + ρ(hit)/π · Σ_lights E_direct(hit, n)         direct light, shadow rays
//         + ρ(hit) · L(hit, ω_cos)                       one cosine-sampled bounce, `bounces` times
//
// E_direct from a point, spot or projector lamp at q is exact: I(−ω)·cos θ / |q − x|² when
// unoccluded. An area light A of radiance L_a is sampled at N stratified points:
// E ≈ (A/N) Σ L_a cos θ cos θ_a / r². The environment is sampled with M cosine-distributed
// directions: E ≈ (π/M) Σ L_env(ω) V(ω). Light that is sampled this way (area lights, lamp
// apertures, the environment) is not counted again when a bounce ray hits it; emission of
// ordinary surfaces is not light-sampled and counts whenever it is hit (front side only).
#pragma once
#include <cstdint>

#include "iblkit/core/rng.h"
#include "iblkit/core/vec.h"
#include "iblkit/lab/scene.h"

namespace ibl::lab {

// Radiance arriving at o from direction d (unit; the ray leaves o along d). Scene must be built.
// Bit i of `hidden_apertures` makes the aperture of emitters[i] black to this (camera) ray: the
// caller adds that lamp's light by other means (capture_probe integrates small apertures per pixel).
Vec3 radiance(const Scene& scene, Vec3 o, Vec3 d, Rng& rng, const RenderDesc& desc, uint64_t hidden_apertures = 0);

// Distance to the first surface along the ray (emitters' geometry included), +inf when none.
double first_hit_distance(const Scene& scene, Vec3 o, Vec3 d);

// Direct irradiance (W/m²) at point p with unit normal n from every emitter (shadow rays included).
Vec3 direct_irradiance(const Scene& scene, Vec3 p, Vec3 n, Rng& rng, const RenderDesc& desc);

}  // namespace ibl::lab
