#include "iblkit/lab/radiance.h"

#include <cmath>
#include <limits>

namespace ibl::lab {

namespace {

constexpr double kRayEpsilon = 1e-4;     // metres: start of secondary rays (float BVH, scenes ≤ 100 m)
constexpr double kShadowShorten = 1e-4;  // relative: shadow rays stop this short of the light point

bool visible(const Scene& s, Vec3 p, Vec3 w, double dist) {
  return !s.tracer().occluded(p, w, kRayEpsilon, dist * (1 - kShadowShorten));
}

// Concentric map of the unit square to the unit disc (Shirley & Chiu 1997).
Vec2 concentric(double u1, double u2) {
  double a = 2 * u1 - 1, b = 2 * u2 - 1;
  if (a == 0 && b == 0) return {0, 0};
  double r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = (kPi / 4) * (b / a);
  } else {
    r = b;
    phi = kPi / 2 - (kPi / 4) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

Vec3 cosine_direction(Vec3 n, double u1, double u2) {
  Vec2 d = concentric(u1, u2);
  double z = std::sqrt(std::max(0.0, 1 - d.x * d.x - d.y * d.y));
  return Frame::from_normal(n).from_local({d.x, d.y, z});
}

Vec3 area_irradiance(const Scene& s, const Emitter& e, Vec3 p, Vec3 n, Rng& rng, int count) {
  auto m = static_cast<int>(std::lround(std::sqrt(static_cast<double>(count))));
  bool strat = m * m == count;
  Vec3 sum;
  for (int i = 0; i < count; ++i) {
    double u1 = rng.uniform(), u2 = rng.uniform();
    if (strat) {
      u1 = (i % m + u1) / m;
      u2 = (i / m + u2) / m;
    }
    Vec3 q;
    if (e.disc) {
      Vec2 c = concentric(u1, u2);
      q = e.center + (e.edge_u * c.x + e.edge_v * c.y) * e.radius;
    } else {
      q = e.center + e.edge_u * ((u1 - 0.5) * e.size.x) + e.edge_v * ((u2 - 0.5) * e.size.y);
    }
    Vec3 w = q - p;
    double d2 = dot(w, w), dist = std::sqrt(d2);
    w = w / dist;
    double cos_p = dot(n, w), cos_l = -dot(e.normal, w);
    if (cos_p <= 0 || cos_l <= 0 || !visible(s, p, w, dist)) continue;
    sum += e.radiance * (cos_p * cos_l / d2);
  }
  return sum * (e.emit_area / count);
}

}  // namespace

Vec3 direct_irradiance(const Scene& s, Vec3 p, Vec3 n, Rng& rng, const RenderDesc& desc) {
  Vec3 e_sum;
  for (const Emitter& e : s.emitters) {
    switch (e.type) {
      case EmitterType::Point:
      case EmitterType::Spot:
      case EmitterType::Projector: {
        Vec3 w = e.position - p;
        double d2 = dot(w, w), dist = std::sqrt(d2);
        w = w / dist;
        double c = dot(n, w);
        if (c <= 0) break;
        Vec3 i = e.intensity_towards(-w);
        if (max_component(i) <= 0 || !visible(s, p, w, dist)) break;
        e_sum += i * (c / d2);
        break;
      }
      case EmitterType::Area:
        e_sum += area_irradiance(s, e, p, n, rng, desc.area_samples);
        break;
      case EmitterType::Environment: {
        Vec3 acc;
        for (int k = 0; k < desc.env_samples; ++k) {
          double u1 = rng.uniform(), u2 = rng.uniform();
          Vec3 w = cosine_direction(n, u1, u2);
          if (!s.tracer().occluded(p, w, kRayEpsilon, std::numeric_limits<double>::infinity())) acc += e.environment(w);
        }
        if (desc.env_samples > 0) e_sum += acc * (kPi / desc.env_samples);
        break;
      }
    }
  }
  return e_sum;
}

Vec3 radiance(const Scene& s, Vec3 o, Vec3 d, Rng& rng, const RenderDesc& desc, uint64_t hidden_apertures) {
  Vec3 L, beta{1, 1, 1};
  double tnear = 0;
  for (int depth = 0;; ++depth) {
    bool camera = depth == 0;
    geometry::Hit h = s.tracer().intersect(o, d, tnear);
    if (!h.hit) {
      if (camera && s.environment()) L += beta * s.environment()->environment(d);
      break;
    }
    const Surface& surf = s.surfaces[h.mesh];
    Vec3 n = surf.normals[h.triangle];
    bool front = dot(n, d) < 0;
    if (surf.role != SurfaceRole::Diffuse) {
      if (camera && front) {
        const Emitter& e = s.emitters[surf.emitter];
        if (surf.role == SurfaceRole::AreaLight) {
          L += beta * e.radiance;
        } else if (surf.emitter >= 64 || !((hidden_apertures >> surf.emitter) & 1)) {
          double cos_a = -dot(d, e.direction);  // lamp axis vs. the direction towards the viewer
          if (cos_a > 0) L += beta * e.intensity_towards(-d) / (e.emit_area * cos_a);
        }
      }
      break;
    }
    if (front) L += beta * surf.emission;
    Vec3 p = o + d * h.t;
    Vec2 uv;
    if (!surf.mesh.uvs.empty()) {
      const auto& t = surf.mesh.triangles[h.triangle];
      const auto& U = surf.mesh.uvs;
      uv = U[t[0]] * (1 - h.b1 - h.b2) + U[t[1]] * h.b1 + U[t[2]] * h.b2;
    }
    Vec3 albedo = surf.albedo.eval(uv);
    if (max_component(albedo) <= 0) break;
    Vec3 ns = front ? n : -n;
    L += beta * albedo * direct_irradiance(s, p, ns, rng, desc) * (1.0 / kPi);
    if (depth >= desc.bounces) break;
    double u1 = rng.uniform(), u2 = rng.uniform();
    d = cosine_direction(ns, u1, u2);
    o = p;
    tnear = kRayEpsilon;
    beta = beta * albedo;  // f·cos/pdf = (ρ/π)·cos / (cos/π)
  }
  return L;
}

double first_hit_distance(const Scene& s, Vec3 o, Vec3 d) {
  geometry::Hit h = s.tracer().intersect(o, d);
  return h.hit ? h.t : std::numeric_limits<double>::infinity();
}

}  // namespace ibl::lab
