#include "iblkit/render/shading.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sh/convolve.h"

namespace ibl::render {

double glossy_lobe(const Material& m, Vec3 n, Vec3 v, Vec3 r, Vec3 l) {
  double ndl = dot(n, l);
  if (ndl <= 0) return 0;
  if (m.lobe == Lobe::BlinnPhong) {
    double ndh = dot(n, normalize(l + v));
    return ndh > 0 ? (m.exponent + 8) / (8 * kPi) * std::pow(ndh, m.exponent) * ndl : 0;
  }
  double rdl = dot(r, l);
  return rdl > 0 ? (m.exponent + 1) / kTwoPi * std::pow(rdl, m.exponent) : 0;
}

Vec3 shade(const Lighting& lighting, const Material& m, Vec3 p, Vec3 n, Vec3 v, const VisibilityFn& visible) {
  Vec3 r = normalize(n * (2 * dot(n, v)) - v);
  Vec3 E, G;
  const sh::Coeffs* c = nullptr;
  sh::Coeffs local;
  if (lighting.grid) {
    local = lighting.grid->coeffs_at(p);
    c = &local;
  } else if (lighting.environment) {
    c = &*lighting.environment;
  }
  const double s_env = m.environment_exponent();
  const GlossyMap* gmap = lighting.grid ? nullptr : lighting.glossy_map(s_env);
  if (gmap) G += lookup(*gmap, r);
  if (c && c->bands > 0) {
    int bands = c->bands;
    auto diffuse = sh::clamped_cosine_zh(bands);
    auto glossy = sh::phong_zh(bands, s_env);
    std::vector<double> yn(bands * bands), yr(bands * bands);
    sh::eval_basis(bands, n, yn.data());
    sh::eval_basis(bands, r, yr.data());
    for (int l = 0; l < bands; ++l)
      for (int mm = -l; mm <= l; ++mm) {
        int k = l * (l + 1) + mm;
        E += c->c[k] * (diffuse[l] * yn[k]);
        if (!gmap) G += c->c[k] * (glossy[l] * yr[k]);
      }
  }
  auto add_light = [&](Vec3 l, Vec3 irradiance, bool shadow, double distance) {
    double ndl = dot(n, l);
    if (ndl <= 0) return;
    if (irradiance.x == 0 && irradiance.y == 0 && irradiance.z == 0) return;  // no shadow ray for no light
    if (shadow && visible && !visible(p, l, distance)) return;
    E += irradiance * ndl;
    G += irradiance * glossy_lobe(m, n, v, r, l);
  };
  for (const DirectionalLight& L : lighting.lights)
    add_light(L.direction, L.irradiance, L.shadow, std::numeric_limits<double>::infinity());
  for (const PointLight& L : lighting.point_lights) {
    Vec3 to = L.position - p;
    double d2 = dot(to, to);
    if (!(d2 > 0)) continue;
    double d = std::sqrt(d2);
    add_light(to / d, L.intensity / d2, L.shadow, d);
  }
  for (const nearfield::TexturedSpotlight& L : lighting.spotlights) {
    Vec3 to = L.position - p;
    double d = length(to);
    if (!(d > 0)) continue;
    Vec3 l = to / d;
    double ndl = dot(n, l);
    if (ndl <= 0) continue;
    add_light(l, nearfield::irradiance(L, p, n) / ndl, L.shadow, d);
  }
  Vec3 out = m.albedo * E * (1.0 / kPi) + m.specular * G;
  // SH ringing can make a few values negative; light is never negative.
  return {std::max(0.0, out.x), std::max(0.0, out.y), std::max(0.0, out.z)};
}

void check_material(const Material& m, const std::string& who) {
  const Vec3 a = m.albedo, k = m.specular;
  for (int c = 0; c < 3; ++c)
    if (!(a[c] >= 0 && a[c] <= 1 && k[c] >= 0 && k[c] <= 1))
      fail(ErrorKind::Value, "{}: albedo ({}, {}, {}) and gloss ({}, {}, {}) must lie in [0, 1] per channel", who, a.x,
           a.y, a.z, k.x, k.y, k.z);
  if (!(m.exponent >= 1 && m.exponent <= 1e4))
    fail(ErrorKind::Value, "{}: glossy exponent {} must lie in 1..10000", who, m.exponent);
  if (m.texture && (m.texture->empty() || m.texture->channels() < 3))
    fail(ErrorKind::Value, "{}: the texture must be an RGB image", who);
}

Vec3 texture_albedo(const Image& texture, Vec2 uv) {
  return texture.view().sample_rgb_uv(uv.x, 1.0 - uv.y, Wrap::Repeat);
}

}  // namespace ibl::render
