#include "iblkit/render/prefilter.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::render {

int glossy_map_height(double exponent) {
  double want = 3 * kPi * std::sqrt(std::max(exponent, 0.0));
  int h = 16;
  while (h < want && h < 256) h *= 2;
  return h;
}

GlossyMap prefilter_phong(const sphere::EnvMap& probe, double s, int height, const ProgressFn& progress) {
  if (!(s >= 0) || !std::isfinite(s)) fail(ErrorKind::Value, "Phong exponent {} must be a finite number ≥ 0", s);
  const int H = height > 0 ? height : glossy_map_height(s);
  if (H < 2 || H > 4096) fail(ErrorKind::Value, "glossy map height {} is out of range 2..4096", H);
  // The probe on a lat-long of 2H rows, area-preserving.
  const int Hi = H, Wi = 2 * Hi;  // input: the map's own resolution
  sphere::Mapping in_map(sphere::MappingKind::LatLong, Wi, Hi);
  Image in = sphere::resample(probe, in_map);
  // Per input pixel: direction and L·dω.
  std::vector<Vec3> dir(static_cast<size_t>(Wi) * Hi), ldw(dir.size());
  std::vector<double> row_theta0(Hi), row_theta1(Hi);
  for (int y = 0; y < Hi; ++y) {
    double t0 = kPi * y / Hi, t1 = kPi * (y + 1) / Hi;
    row_theta0[y] = t0;
    row_theta1[y] = t1;
    double dw = (kTwoPi / Wi) * (std::cos(t0) - std::cos(t1));
    for (int x = 0; x < Wi; ++x) {
      size_t i = static_cast<size_t>(y) * Wi + x;
      in_map.to_direction(x + 0.5, y + 0.5, &dir[i]);
      ldw[i] = in.rgb(x, y) * dw;
    }
  }
  // The lobe's support: (r·ω)^s ≥ 1e-6 ⇔ r·ω ≥ 1e-6^(1/s).
  const double cos_min = s > 0 ? std::pow(1e-6, 1.0 / s) : 0.0;
  const double half_angle = std::acos(std::clamp(cos_min, -1.0, 1.0));
  const double norm = (s + 1) / kTwoPi;
  GlossyMap out{s, Image(2 * H, H, 3)};
  sphere::Mapping out_map(sphere::MappingKind::LatLong, 2 * H, H);
  std::atomic<int> rows_done{0};
  parallel_for(0, H, [&](int64_t yy) {
    int y = static_cast<int>(yy);
    const double theta = kPi * (y + 0.5) / H, ct = std::cos(theta), st = std::sin(theta);
    int r0 = 0, r1 = Hi;
    if (cos_min > 0) {  // rows whose θ-band meets [θ − α, θ + α]
      while (r0 < Hi && row_theta1[r0] < theta - half_angle) ++r0;
      while (r1 > r0 && row_theta0[r1 - 1] > theta + half_angle) --r1;
    }
    // Per input row: the azimuth half-width Δφ of the support around the output column, from
    // cos γ = cos θ cos θ' + sin θ sin θ' cos Δφ ≥ cos_min, widened by one pixel for the pixels'
    // own extent (the exact test r·ω ≥ cos_min follows per pixel).
    std::vector<int> half_cols(Hi, Wi);
    for (int row = r0; row < r1; ++row) {
      double t = 0.5 * (row_theta0[row] + row_theta1[row]);
      double denom = st * std::sin(t);
      if (cos_min <= 0 || denom < 1e-9) continue;
      // The widest azimuth over the row's θ-band: test its edges too.
      double widest = 0;
      bool all = false;
      for (double tt : {row_theta0[row], t, row_theta1[row]}) {
        double dn = st * std::sin(tt);
        if (dn < 1e-9) {
          all = true;
          break;
        }
        double c = (cos_min - ct * std::cos(tt)) / dn;
        if (c <= -1) {
          all = true;
          break;
        }
        if (c < 1) widest = std::max(widest, std::acos(c));
      }
      if (all) continue;
      half_cols[row] = std::min(Wi, static_cast<int>(std::ceil(widest / (kTwoPi / Wi))) + 2);
    }
    for (int x = 0; x < 2 * H; ++x) {
      Vec3 r;
      out_map.to_direction(x + 0.5, y + 0.5, &r);
      // Column of the input whose centre is nearest r's azimuth.
      const int cx = static_cast<int>(std::floor((x + 0.5) / (2 * H) * Wi));
      Vec3 g;
      for (int row = r0; row < r1; ++row) {
        const size_t base = static_cast<size_t>(row) * Wi;
        const int hc = half_cols[row];
        const int c0 = hc >= Wi / 2 ? 0 : cx - hc, c1 = hc >= Wi / 2 ? Wi : cx + hc + 1;
        for (int cc = c0; cc < c1; ++cc) {
          const int c = ((cc % Wi) + Wi) % Wi;
          double d = dot(r, dir[base + c]);
          if (d < cos_min || d <= 0) continue;
          g += ldw[base + c] * std::pow(d, s);
        }
      }
      out.latlong.set_rgb(x, y, g * norm);
    }
    report(progress, "prefilter", static_cast<double>(++rows_done) / H);
  });
  return out;
}

Vec3 lookup(const GlossyMap& map, Vec3 r) {
  double u = std::atan2(r.z, r.x) / kTwoPi + 0.5;
  double v = std::acos(std::clamp(r.y, -1.0, 1.0)) / kPi;
  return map.latlong.view().sample_rgb_uv(u, v, Wrap::LatLong);
}

}  // namespace ibl::render
