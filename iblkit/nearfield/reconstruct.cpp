#include "iblkit/nearfield/reconstruct.h"

#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/nearfield/basis.h"

namespace ibl::nearfield {

namespace {

// In-place solve of Σ_l β2(k − l) a_l = c_k along a line of n values with mirror boundaries: the
// causal/anticausal recursive filter with the pole z = √8 − 3 of the quadratic B-spline.
void bspline2_prefilter(double* c, int n, ptrdiff_t stride) {
  if (n < 2) return;
  const double z = std::sqrt(8.0) - 3.0, gain = (1 - z) * (1 - 1 / z);
  for (int k = 0; k < n; ++k) c[k * stride] *= gain;
  // Causal initialisation: Σ z^k c_k over the (mirrored) line, truncated where z^k < 1e-12.
  int horizon = std::min(n, static_cast<int>(std::ceil(std::log(1e-12) / std::log(std::abs(z)))));
  double zk = 1, sum = 0;
  for (int k = 0; k < horizon; ++k, zk *= z) sum += zk * c[k * stride];
  c[0] = sum;
  for (int k = 1; k < n; ++k) c[k * stride] += z * c[(k - 1) * stride];
  c[(n - 1) * stride] = (z / (z * z - 1)) * (c[(n - 1) * stride] + z * c[(n - 2) * stride]);
  for (int k = n - 2; k >= 0; --k) c[k * stride] = z * (c[(k + 1) * stride] - c[k * stride]);
}

// c_k ← ⅛ a_{k−1} + ¾ a_k + ⅛ a_{k+1} (mirror boundaries).
void bspline2_sample(double* a, int n, ptrdiff_t stride) {
  std::vector<double> t(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    double l = a[std::max(k - 1, 0) * stride], m = a[k * stride], r = a[std::min(k + 1, n - 1) * stride];
    if (k == 0) l = n > 1 ? a[stride] : m;
    if (k == n - 1) r = n > 1 ? a[(n - 2) * stride] : m;
    t[static_cast<size_t>(k)] = 0.125 * l + 0.75 * m + 0.125 * r;
  }
  for (int k = 0; k < n; ++k) a[k * stride] = t[static_cast<size_t>(k)];
}

}  // namespace

std::vector<Image> incoming_radiance(const Dataset& ds) {
  ds.validate(ds.name.empty() ? "dataset" : ds.name);
  const int W = ds.positive[0].width(), H = ds.positive[0].height(), N = ds.count();
  const double h2 = ds.spacing * ds.spacing, d = ds.distance;
  std::vector<Image> out(static_cast<size_t>(N));
  parallel_for(0, N, [&](int64_t idx) {
    const int i = static_cast<int>(idx % ds.nx), j = static_cast<int>(idx / ds.nx);
    const Vec2 c = ds.filter_center(i, j);
    Image e = ds.measurement(i, j);
    auto inv_g = [&](int x, int y) {  // 1/(h² g_mn) at pixel (x, y)
      const Vec2 m = ds.pixel_to_m(x, y, W, H);
      const double r2 = d * d + (m.x - c.x) * (m.x - c.x) + (m.y - c.y) * (m.y - c.y);
      return r2 * r2 / (d * d * h2);
    };
    if (ds.m_basis == Basis::Bilinear) {
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          const double s = inv_g(x, y);
          float* p = e.pixel(x, y);
          for (int ch = 0; ch < 3; ++ch) p[ch] = static_cast<float>(p[ch] * s);
        }
    } else {
      std::vector<double> buf(static_cast<size_t>(W) * H);
      for (int ch = 0; ch < 3; ++ch) {
        for (int y = 0; y < H; ++y)
          for (int x = 0; x < W; ++x) buf[static_cast<size_t>(y) * W + x] = e.at(x, y, ch);
        for (int y = 0; y < H; ++y) bspline2_prefilter(&buf[static_cast<size_t>(y) * W], W, 1);
        for (int x = 0; x < W; ++x) bspline2_prefilter(&buf[static_cast<size_t>(x)], H, W);
        for (int y = 0; y < H; ++y)
          for (int x = 0; x < W; ++x) buf[static_cast<size_t>(y) * W + x] *= inv_g(x, y);
        for (int y = 0; y < H; ++y) bspline2_sample(&buf[static_cast<size_t>(y) * W], W, 1);
        for (int x = 0; x < W; ++x) bspline2_sample(&buf[static_cast<size_t>(x)], H, W);
        for (int y = 0; y < H; ++y)
          for (int x = 0; x < W; ++x) e.at(x, y, ch) = static_cast<float>(buf[static_cast<size_t>(y) * W + x]);
      }
    }
    out[static_cast<size_t>(idx)] = std::move(e);
  });
  return out;
}

std::vector<TexturedSpotlight> place_spotlights(const Dataset& ds, const std::vector<Image>& eprime,
                                                const Placement& placement, bool shadow) {
  if (static_cast<int>(eprime.size()) != ds.count())
    fail(ErrorKind::Value, "place_spotlights: {} textures for {} filter positions", eprime.size(), ds.count());
  const Frame f = placement.frame();
  std::vector<TexturedSpotlight> out;
  for (int j = 0; j < ds.ny; ++j)
    for (int i = 0; i < ds.nx; ++i) {
      const Vec2 c = ds.filter_center(i, j);
      TexturedSpotlight L;
      L.position = placement.position + f.from_local({c.x, c.y, 0});
      L.frame = f;
      L.plane_distance = ds.distance;
      L.tex_min = ds.m_min - c;
      L.tex_max = ds.m_max - c;
      L.mips = std::make_shared<const std::vector<Image>>(build_mips(eprime[static_cast<size_t>(j * ds.nx + i)]));
      L.support_area = ds.spacing * ds.spacing;  // ∫ β(u/h)β(v/h) du dv = h² for both B-splines
      // The lookup footprint: the width of the box that carries Φ_mn's weight, half its support (the
      // B-spline's weight sits in its middle: the full support over-blurs narrow beams far away).
      L.support_width = primal_half_width(ds.basis) * ds.spacing;
      L.shadow = shadow;
      out.push_back(std::move(L));
    }
  return out;
}

std::vector<TexturedSpotlight> spotlights(const Dataset& ds, const Placement& placement, bool shadow) {
  return place_spotlights(ds, incoming_radiance(ds), placement, shadow);
}

TexturedSpotlight far_field_spotlight(const std::function<Vec3(Vec3)>& intensity, double d, double extent,
                                      int resolution, const Placement& placement, bool shadow) {
  if (!(d > 0) || !(extent > 0) || resolution < 1)
    fail(ErrorKind::Value, "far-field spotlight: distance {}, extent {}, resolution {} must be positive", d, extent,
         resolution);
  Image tex(resolution, resolution, 3);
  parallel_for(0, resolution, [&](int64_t y) {
    for (int x = 0; x < resolution; ++x) {
      const double s = -extent + (x + 0.5) * 2 * extent / resolution, t = extent - (y + 0.5) * 2 * extent / resolution;
      const Vec3 w = normalize(Vec3{s, t, d});
      tex.set_rgb(x, static_cast<int>(y), intensity(w) / w.z);
    }
  });
  TexturedSpotlight L;
  L.position = placement.position;
  L.frame = placement.frame();
  L.plane_distance = d;
  L.tex_min = {-extent, -extent};
  L.tex_max = {extent, extent};
  L.mips = std::make_shared<const std::vector<Image>>(build_mips(tex));
  L.support_area = 1;
  L.support_width = 0;
  L.shadow = shadow;
  return L;
}

}  // namespace ibl::nearfield
