#include "iblkit/nearfield/luminaire.h"

#include <atomic>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/nearfield/basis.h"

namespace ibl::nearfield {

namespace {

constexpr double kDeg = kPi / 180;

// cos(k·φ) from c = cos φ by the Chebyshev recurrence T_{k+1} = 2c·T_k − T_{k−1}.
double chebyshev(int k, double c) {
  double t0 = 1, t1 = c;
  if (k == 0) return 1;
  for (int i = 1; i < k; ++i) {
    double t2 = 2 * c * t1 - t0;
    t0 = t1;
    t1 = t2;
  }
  return t1;
}

DiscEmitter disc(Vec3 c, double r, Vec3 radiance, Vec3 axis, double exponent) {
  DiscEmitter e;
  e.center = c;
  e.radius = r;
  e.radiance = radiance;
  e.axis = normalize(axis);
  e.exponent = exponent;
  return e;
}

}  // namespace

Vec3 Luminaire::emitted(const DiscEmitter& e, Vec3 w) const {
  const double c = dot(w, e.axis);
  if (c <= 0) return {0, 0, 0};
  const double tz = std::acos(std::clamp(w.z, -1.0, 1.0));
  const double cut = cutoff_deg * kDeg, taper = taper_deg * kDeg;
  if (tz >= cut) return {0, 0, 0};
  double housing = 1;
  if (tz > cut - taper) housing = 0.5 * (1 + std::cos(kPi * (tz - cut + taper) / taper));
  double lobe = std::pow(c, e.exponent);
  if (e.ripple != 0 && e.facets > 0) {
    Vec3 perp = w - e.axis * c;
    double pl = length(perp);
    if (pl > 1e-12) {
      Vec3 ref = normalize(e.lobe_ref - e.axis * dot(e.lobe_ref, e.axis));
      lobe *= 1 + e.ripple * chebyshev(e.facets, std::clamp(dot(perp, ref) / pl, -1.0, 1.0));
    }
  }
  return e.radiance * (lobe * housing);
}

std::vector<std::pair<Vec3, double>> Luminaire::quadrature(const DiscEmitter& e) const {
  std::vector<std::pair<Vec3, double>> pts;
  const Frame f = Frame::from_normal(normalize(e.normal));
  const double w = kPi * e.radius * e.radius / (rings * sectors);
  for (int k = 0; k < rings; ++k) {
    const double r = e.radius * std::sqrt((k + 0.5) / rings);  // equal-area rings, midpoints in r²
    for (int j = 0; j < sectors; ++j) {
      const double a = kTwoPi * (j + 0.5 * (k % 2)) / sectors;
      pts.push_back({e.center + f.from_local({r * std::cos(a), r * std::sin(a), 0}), w});
    }
  }
  return pts;
}

Vec3 Luminaire::irradiance(Vec3 x, Vec3 n, const std::function<bool(int)>& visible) const {
  Vec3 acc{0, 0, 0};
  for (size_t ei = 0; ei < emitters.size(); ++ei) {
    const auto& e = emitters[ei];
    Vec3 sum{0, 0, 0};
    for (const auto& [y, da] : quadrature(e)) {
      const Vec3 v = x - y;
      const double r2 = dot(v, v), r = std::sqrt(r2);
      const Vec3 w = v / r;
      const double ce = dot(w, e.normal), cx = -dot(w, n);
      if (ce <= 0 || cx <= 0) continue;
      sum += emitted(e, w) * (ce * cx * da / r2);
    }
    // Shadow rays only for emitters that send light here.
    if ((sum.x != 0 || sum.y != 0 || sum.z != 0) && (!visible || visible(static_cast<int>(ei)))) acc += sum;
  }
  return acc;
}

Vec3 Luminaire::intensity(Vec3 w) const {
  Vec3 acc{0, 0, 0};
  for (const auto& e : emitters) {
    const double ce = dot(w, e.normal);
    if (ce > 0) acc += emitted(e, w) * (ce * kPi * e.radius * e.radius);
  }
  return acc;
}

Vec2 Luminaire::half_size() const {
  Vec2 s{0, 0};
  for (const auto& e : emitters) {
    s.x = std::max(s.x, std::abs(e.center.x) + e.radius);
    s.y = std::max(s.y, std::abs(e.center.y) + e.radius);
  }
  return s;
}

double Luminaire::extent_at(double d) const {
  double zmax = 0;
  for (const auto& e : emitters) zmax = std::max(zmax, -e.center.z + e.radius);
  const Vec2 hs = half_size();
  return std::max(hs.x, hs.y) + (d + zmax) * std::tan(cutoff_deg * kDeg);
}

std::vector<std::string> luminaire_names() { return {"flashlight", "bikelight"}; }

Luminaire make_luminaire(const std::string& name) {
  Luminaire L;
  L.name = name;
  if (name == "flashlight") {
    // A warm bulb in the middle, 5 mm across.
    L.emitters.push_back(disc({0, 0, -0.002}, 0.0025, Vec3{1.0, 0.85, 0.6} * 5e4, {0, 0, 1}, 12));
    // The reflector: 24 narrow beams from a ring of radius 8 mm, tilted 4° inwards, six facets each.
    for (int k = 0; k < 24; ++k) {
      const double a = kTwoPi * k / 24;
      const Vec3 radial{std::cos(a), std::sin(a), 0};
      const Vec3 axis = Vec3{0, 0, std::cos(4 * kDeg)} - radial * std::sin(4 * kDeg);
      DiscEmitter e = disc(radial * 0.008 + Vec3{0, 0, -0.002}, 0.0012, Vec3{1.0, 0.97, 0.9} * 2e5, axis, 300);
      e.ripple = 0.5;
      e.facets = 6;
      e.lobe_ref = {-std::sin(a), std::cos(a), 0};
      L.emitters.push_back(e);
    }
  } else if (name == "bikelight") {
    // A row of five white LEDs 7 mm apart, the outer ones wider and tilted outwards.
    const double xs[5] = {-0.014, -0.007, 0, 0.007, 0.014}, tilt[5] = {-8, -3, 0, 3, 8}, ex[5] = {40, 80, 150, 80, 40};
    for (int k = 0; k < 5; ++k) {
      Vec3 axis{std::sin(tilt[k] * kDeg), 0, std::cos(tilt[k] * kDeg)};
      L.emitters.push_back(disc({xs[k], 0, -0.002}, 0.0015, Vec3{0.95, 0.97, 1.0} * 1.5e5, axis, ex[k]));
    }
    // Two warm LEDs above, tilted 5° up.
    for (double x : {-0.007, 0.007}) {
      Vec3 axis{0, std::sin(5 * kDeg), std::cos(5 * kDeg)};
      L.emitters.push_back(disc({x, 0.008, -0.002}, 0.0015, Vec3{1.0, 0.55, 0.25} * 1e5, axis, 20));
    }
  } else {
    fail(ErrorKind::Value, "unknown luminaire '{}' (known: flashlight, bikelight)", name);
  }
  return L;
}

Dataset simulate(const Luminaire& lum, const SimulateDesc& desc, const ProgressFn& progress) {
  if (desc.nx < 2 || desc.ny < 2 || desc.nx > 64 || desc.ny > 64)
    fail(ErrorKind::Value, "simulate: filter grid {}x{} out of range (2..64 per axis)", desc.nx, desc.ny);
  if (!(desc.spacing > 0) || !(desc.distance > 0) || desc.resolution < 2 || desc.resolution > 4096 || desc.extent < 0)
    fail(ErrorKind::Value, "simulate: spacing {} m, distance {} m, resolution {}, extent {}: need positive values",
         desc.spacing, desc.distance, desc.resolution, desc.extent);
  Dataset ds;
  ds.luminaire = lum.name;
  ds.name = lum.name + "-" + std::to_string(desc.nx) + "x" + std::to_string(desc.ny);
  ds.basis = desc.basis;
  ds.spacing = desc.spacing;
  ds.filter_width = 2 * dual_half_width(desc.basis) * desc.spacing;
  ds.nx = desc.nx;
  ds.ny = desc.ny;
  ds.distance = desc.distance;
  const double ext = desc.extent > 0 ? desc.extent : lum.extent_at(desc.distance);
  ds.m_min = {-ext, -ext};
  ds.m_max = {ext, ext};
  ds.m_basis = Basis::Bilinear;
  const int W = desc.resolution, H = desc.resolution, N = ds.count();
  ds.positive.assign(static_cast<size_t>(N), Image(W, H, 3));
  ds.negative.assign(static_cast<size_t>(N), Image(W, H, 3));

  struct Pt {
    int e;
    Vec3 y;
    double da;
  };
  std::vector<Pt> pts;
  for (size_t e = 0; e < lum.emitters.size(); ++e) {
    if (lum.emitters[e].center.z >= 0)
      fail(ErrorKind::Value, "simulate: emitter {} of '{}' is not behind S (z >= 0)", e, lum.name);
    for (auto& [y, da] : lum.quadrature(lum.emitters[e])) pts.push_back({static_cast<int>(e), y, da});
  }
  const double h = desc.spacing, half = dual_half_width(desc.basis), d = desc.distance;
  std::atomic<int> rows_done{0};
  parallel_for(0, H, [&](int64_t py) {
    for (int px = 0; px < W; ++px) {
      const Vec2 m = ds.pixel_to_m(px, static_cast<double>(py), W, H);
      const Vec3 p{m.x, m.y, d};
      for (const auto& q : pts) {
        const DiscEmitter& e = lum.emitters[static_cast<size_t>(q.e)];
        const Vec3 v = p - q.y;
        const double r2 = dot(v, v), r = std::sqrt(r2);
        const Vec3 w = v / r;
        const double ce = dot(w, e.normal), cm = w.z;
        if (ce <= 0 || cm <= 0) continue;
        const Vec3 l = lum.emitted(e, w) * (ce * cm * q.da / r2);
        if (l.x == 0 && l.y == 0 && l.z == 0) continue;
        // Where the ray crosses S, in units of h from the grid's corner position (0,0).
        const double k = -q.y.z / v.z;
        const double cu = (q.y.x + v.x * k) / h + 0.5 * (desc.nx - 1), cv = (q.y.y + v.y * k) / h + 0.5 * (desc.ny - 1);
        const int i0 = std::max(0, static_cast<int>(std::ceil(cu - half))),
                  i1 = std::min(desc.nx - 1, static_cast<int>(std::floor(cu + half)));
        const int j0 = std::max(0, static_cast<int>(std::ceil(cv - half))),
                  j1 = std::min(desc.ny - 1, static_cast<int>(std::floor(cv + half)));
        for (int j = j0; j <= j1; ++j) {
          const double fv = dual(desc.basis, cv - j);
          if (fv == 0) continue;
          for (int i = i0; i <= i1; ++i) {
            const double f = fv * dual(desc.basis, cu - i);  // transmittance h²Φ'_ij
            if (f == 0) continue;
            Image& img = f > 0 ? ds.positive[static_cast<size_t>(j * desc.nx + i)]
                               : ds.negative[static_cast<size_t>(j * desc.nx + i)];
            float* o = img.pixel(px, static_cast<int>(py));
            const double af = std::abs(f);
            o[0] += static_cast<float>(l.x * af);
            o[1] += static_cast<float>(l.y * af);
            o[2] += static_cast<float>(l.z * af);
          }
        }
      }
    }
    report(progress, "simulate", static_cast<double>(++rows_done) / H);
  });
  return ds;
}

}  // namespace ibl::nearfield
