#include "iblkit/augment/proxy_light.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "iblkit/core/parallel.h"

namespace ibl::augment {

bool BoundingSphere::meets(Vec3 x, Vec3 w, double tfar) const {
  Vec3 v = c - x;
  double t = std::clamp(dot(v, w), 0.0, tfar), d2 = dot(v, v) - 2 * t * dot(v, w) + t * t;
  return d2 <= r * r;
}

Tracers::Tracers(const geometry::TriMesh& proxy_mesh, const geometry::TriMesh* object_mesh)
    : proxy(proxy_mesh), object(object_mesh) {
  proxy_rt.add(proxy);
  proxy_rt.commit();
  if (!object) return;
  object_rt.add(*object);
  object_rt.commit();
  both_rt.add(proxy);
  both_rt.add(*object);
  both_rt.commit();
  Vec3 lo, hi;
  object->bounds(&lo, &hi);
  bound.c = (lo + hi) * 0.5;
  for (const Vec3& p : object->positions) bound.r = std::max(bound.r, length(p - bound.c));
  bound.r *= 1 + 1e-6;
}

namespace {

// Light sample k of `count` (stratified) seen from x with normal n: its contribution over its probability, *w
// its direction; zero where it lies behind the surface or `rt` occludes it.
Vec3 light_sample(const Tracers& t, const geometry::RayTracer& rt, Vec3 x, Vec3 n, int k, int count, Rng& rng,
                  bool shadowed, Vec3* w) {
  double pmf, dist;
  size_t i = t.light->sample((k + rng.uniform()) / count, &pmf);
  Vec3 c = t.light->contribution(i, x, n, w, &dist, shadowed);
  if (max_component(c) <= 0 || rt.occluded(x, *w, kRayEpsilon, patch_tfar(dist))) return {};
  return c / pmf;
}

}  // namespace

Vec3 irradiance(const Tracers& t, const geometry::RayTracer& rt, Vec3 x, Vec3 n, int count, Rng& rng, bool shadowed) {
  Vec3 e, w;
  for (int k = 0; k < count; ++k) e += light_sample(t, rt, x, n, k, count, rng, shadowed, &w);
  return e / count;
}

Vec3 object_radiance(const Tracers& t, Vec3 z, Vec3 n, Vec3 v, Vec3 rho, const render::Material& m, int count,
                     Rng& rng) {
  const bool glossy = max_component(m.specular) > 0;
  const Vec3 r = normalize(n * (2 * dot(n, v)) - v);
  Vec3 e, g;
  for (int k = 0; k < count; ++k) {
    Vec3 w, c = light_sample(t, t.both_rt, z, n, k, count, rng, true, &w);
    if (max_component(c) <= 0) continue;
    e += c;
    if (glossy)
      g += c * (render::glossy_lobe(m, n, v, r, w) / dot(n, w));  // c / cos: the irradiance at normal incidence
  }
  return (rho * e / kPi + m.specular * g) / count;
}

Vec3 self_irradiance(const Tracers& t, const std::vector<Vec3>& tri_radiance, Vec3 z, Vec3 n, int count, Rng& rng) {
  if (!t.object || tri_radiance.empty() || count <= 0) return {};
  const Frame f = Frame::from_normal(n);
  Vec3 sum;
  for (int k = 0; k < count; ++k) {
    const double u1 = rng.uniform(), u2 = rng.uniform(), r = std::sqrt(u1), phi = 2 * kPi * u2;
    const Vec3 w = f.from_local({r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u1))});
    const geometry::Hit h = t.both_rt.intersect(z, w);
    if (!h.hit || h.mesh != 1) continue;
    if (dot(t.object->normal(h.triangle), w) >= 0) continue;  // a back face: its radiance is not the front's
    sum += tri_radiance[h.triangle];
  }
  return sum * (kPi / count);
}

Vec3 object_albedo(const geometry::TriMesh& object, const render::Material& m, uint32_t tri, double b1, double b2) {
  if (!m.texture) return m.albedo;
  Vec2 uv{0, 0};
  if (object.has_uvs()) {
    const auto& t = object.triangles[tri];
    uv = object.uvs[t[0]] * (1 - b1 - b2) + object.uvs[t[1]] * b1 + object.uvs[t[2]] * b2;
  }
  return m.albedo * render::texture_albedo(*m.texture, uv);
}

namespace {

// The cone of directions from y (normal n) that can meet the object: its bounding sphere's, or the hemisphere
// about n when y lies inside that sphere. Uniform in it: pdf 1/solid_angle.
struct Cone {
  Frame f;
  double cos_max = 0, solid_angle = 0;
  bool hemisphere = false;
  Cone(const BoundingSphere& b, Vec3 y, Vec3 n) : f(Frame::from_normal(n)) {
    Vec3 axis = b.c - y;
    double d = length(axis);
    hemisphere = d <= b.r;
    cos_max = hemisphere ? 0 : std::sqrt(std::max(0.0, 1 - (b.r / d) * (b.r / d)));
    if (!hemisphere) f = Frame::from_normal(axis / d);
    solid_angle = 2 * kPi * (1 - cos_max);
  }
  bool contains(Vec3 w) const { return dot(w, f.n) >= cos_max; }
  Vec3 direction(double u1, double u2) const {
    double ct = 1 - u1 * (1 - cos_max), st = std::sqrt(std::max(0.0, 1 - ct * ct)), phi = 2 * kPi * u2;
    return f.from_local({st * std::cos(phi), st * std::sin(phi), ct});
  }
};

// The cone samples of proxy_terms: the light the object blocks seen along directions towards it (the other
// strategy's balance-heuristic share) and the object's light on y.
void cone_terms(const Tracers& t, const std::vector<Vec3>* tri_radiance, Vec3 y, Vec3 n, int count, int cone_count,
                int table, Rng& rng, ProxyTerms* out) {
  const LightField& L = *t.light;
  const Cone cone(t.bound, y, n);
  const double n_patch = count, n_cone = cone_count, cone_pdf = 1 / cone.solid_angle;
  // A cone direction meets the object first (object_rt) and then, behind it, the proxy (proxy_rt): the proxy
  // nearer than the object hides it; otherwise that proxy hit is the patch whose light the object blocks.
  Vec3 blocked, bounce;
  auto side = static_cast<int>(std::lround(std::sqrt(n_cone)));
  for (int k = 0; k < cone_count; ++k) {
    double u1 = rng.uniform(), u2 = rng.uniform();
    if (side * side == cone_count) {  // a square count is stratified
      u1 = (k % side + u1) / side;
      u2 = (k / side + u2) / side;
    }
    Vec3 w = cone.direction(u1, u2);
    double cos_n = dot(w, n);
    if (cos_n <= 0) continue;
    geometry::Hit ho = t.object_rt.intersect(y, w, kRayEpsilon);
    if (!ho.hit) continue;
    geometry::Hit hp = t.proxy_rt.intersect(y, w, kRayEpsilon);
    if (hp.hit && hp.t < ho.t) continue;  // the proxy is in front of the object along w
    if (tri_radiance) bounce += (*tri_radiance)[ho.triangle] * cos_n;
    long i = L.patch_along(y, w, hp);
    if (i < 0) continue;
    double pp = L.pmf(static_cast<size_t>(i), table) / std::max(L.solid_angle_at(static_cast<size_t>(i), y), 1e-300);
    blocked += L.radiance(static_cast<size_t>(i)) * (cos_n / (n_patch * pp + n_cone * cone_pdf));
  }
  out->blocked += blocked;
  out->bounce = bounce / (n_cone * cone_pdf);
}

}  // namespace

ProxyTerms proxy_terms(const Tracers& t, const std::vector<Vec3>* tri_radiance, Vec3 y, Vec3 n, int count,
                       int cone_count, Rng& rng) {
  const LightField& L = *t.light;
  if (!t.object) cone_count = 0;
  const int table = L.table_for(n);
  const double n_patch = count, n_cone = cone_count;
  double cone_pdf = 0;
  std::optional<Cone> cone;
  if (cone_count > 0) {
    cone.emplace(t.bound, y, n);
    cone_pdf = 1 / cone->solid_angle;
  }
  Vec3 e0, blocked;
  // The patches are drawn a batch at a time and their records fetched ahead: each is a cache miss in a map
  // of 10⁴–10⁶ patches, and fetched together they overlap.
  constexpr int kBatch = 32;
  std::array<size_t, kBatch> drawn;
  std::array<double, kBatch> drawn_pmf;
  for (int k = 0; k < count; ++k) {
    if (k % kBatch == 0)
      for (int j = 0; j < kBatch && k + j < count; ++j) {
        drawn[static_cast<size_t>(j)] =
            L.sample((k + j + rng.uniform()) / count, &drawn_pmf[static_cast<size_t>(j)], table);
        L.prefetch(drawn[static_cast<size_t>(j)]);
      }
    const size_t i = drawn[static_cast<size_t>(k % kBatch)];
    const double pmf = drawn_pmf[static_cast<size_t>(k % kBatch)];
    Vec3 w;
    double dist;
    Vec3 c = L.contribution(i, y, n, &w, &dist);
    double tfar = patch_tfar(dist);
    if (max_component(c) <= 0 || t.proxy_rt.occluded(y, w, kRayEpsilon, tfar)) continue;
    c = c / pmf;
    e0 += c;
    if (t.object && t.bound.meets(y, w, tfar) && t.object_rt.occluded(y, w, kRayEpsilon, tfar)) {
      double weight = 1;
      if (cone_count > 0 && !L.lamp(i) && cone->contains(w)) {
        double pp = pmf / L.solid_angle_at(i, y);  // this sample's density per steradian
        weight = n_patch * pp / (n_patch * pp + n_cone * cone_pdf);
      }
      blocked += c * weight;
    }
  }
  ProxyTerms r{e0 / n_patch, blocked / n_patch, {}};
  if (cone_count > 0) cone_terms(t, tri_radiance, y, n, count, cone_count, table, rng, &r);
  return r;
}

void shadow_patches(const Tracers& t, LightField& field, int count, int cone_count, uint64_t seed) {
  constexpr double kShadowReach = 4;  // bounding radii from the object's centre
  std::vector<size_t> near;
  for (size_t i = 0; i < field.size(); ++i)
    if (field.local(i) && length(field.point(i) - t.bound.c) < kShadowReach * t.bound.r) near.push_back(i);
  std::vector<Vec3> factor(near.size(), Vec3{1, 1, 1});
  parallel_for(
      0, static_cast<int64_t>(near.size()),
      [&](int64_t k) {
        size_t i = near[static_cast<size_t>(k)];
        Vec3 n = field.normal(i);
        Rng rng(stream_key(seed, kStreamPatch, i));
        ProxyTerms terms = proxy_terms(t, nullptr, field.point(i) + n * kRayEpsilon, n, count, cone_count, rng);
        for (int c = 0; c < 3; ++c)
          if (terms.e0[c] > kUnlitIrradiance)
            factor[static_cast<size_t>(k)][c] = std::clamp(1 - terms.blocked[c] / terms.e0[c], 0.0, 1.0);
      },
      64);
  for (size_t k = 0; k < near.size(); ++k) field.set_shadow(near[k], factor[k]);
}

ProxyAlbedo proxy_albedo(Vec3 photo, Vec3 e0) {
  ProxyAlbedo a;
  for (int c = 0; c < 3; ++c) {
    if (e0[c] > kUnlitIrradiance) {
      a.rho[c] = kPi * photo[c] / e0[c];
      a.over_one = a.over_one || a.rho[c] > 1;
    } else {
      a.lit = false;
    }
  }
  return a;
}

std::vector<std::string> albedo_warnings(int64_t proxy_pixels, int64_t over_one, int64_t unlit) {
  std::vector<std::string> w;
  if (over_one > 0)
    w.push_back(fmt::format(
        "{} proxy pixels ({:.1f} %) have an estimated albedo > 1: the captured light is weaker there than the "
        "photograph says (a light the probe misses, or a wrong proxy); their change is limited to what a white "
        "surface would show",
        over_one, 100.0 * over_one / std::max<int64_t>(1, proxy_pixels)));
  if (unlit > 0)
    w.push_back(
        fmt::format("{} proxy pixels receive no captured light in some channel: their albedo is unknown and they "
                    "keep the photograph's value",
                    unlit));
  return w;
}

}  // namespace ibl::augment
