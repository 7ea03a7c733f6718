#include "iblkit/sh/project.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sh/rotate.h"

namespace ibl::sh {

namespace {

using sphere::MappingKind;

void check_bands(int bands) {
  if (bands < 1 || bands > kMaxBands) fail(ErrorKind::Value, "SH bands must be in 1..{} (got {})", kMaxBands, bands);
}

Vec3 pixel_rgb(const float* p, int channels) { return channels >= 3 ? Vec3{p[0], p[1], p[2]} : Vec3{p[0], p[0], p[0]}; }

// Partial sums of one chunk of rows: K RGB coefficients.
struct Partial {
  std::vector<double> v;  // 3K
};
Partial add(Partial a, const Partial& b) {
  if (a.v.empty()) return b;
  for (size_t i = 0; i < a.v.size(); ++i) a.v[i] += b.v[i];
  return a;
}

// ---- lat-long: separable path ------------------------------------------------------------------
//
// With the frame d' = (d.z, d.x, d.y) (a cyclic permutation, i.e. a rotation P), the lat-long
// polar axis +Y becomes the SH polar axis z' = cos θ, and for the pixel column at a = 2πu,
//   d'.x + i d'.y = sin θ (−sin a − i cos a) = sin θ · w(a),  w(a) = −i e^{−ia}.
// So Y_lm(d') = K_lm P̃_lm(cos θ) sin^m θ · {Re, Im} w(a)^m, and the integral over pixel (x, y)
//   ∫∫ Y_lm dω = [∫_{z₁}^{z₀} K_lm P̃_lm(z) (1−z²)^{m/2} dz] · [∫ {Re, Im} w^m da]
// factors into a row term G_lm(y) (4-point Gauss–Legendre over the row's z range) and a column
// term Δ sinc(mΔ/2) {Re, Im} w(a_x)^m with Δ = 2π/W (exact). Per row, the radiance is summed
// against the 2L+1 column tables (vectorised dot products), then multiplied by G. The result is
// in the d' frame; rotating by Pᵀ brings it back to world axes.

constexpr int kLanes = 8;  // floats per vector (GCC/Clang vector extension; AVX2 with -march=x86-64-v3)
typedef float v8f __attribute__((vector_size(32)));
inline v8f load8(const float* p) {
  v8f v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
inline double hsum(v8f v) {
  double s = 0;
  for (int k = 0; k < kLanes; ++k) s += v[k];
  return s;
}

// out[c * ld + j] = Σ_x ch_c[x] · t_j[x] for the 3 channels and G consecutive tables; n a multiple
// of kLanes. 3G accumulators + 4 operands fit the 16 vector registers for G ≤ 4.
template <int G>
void row_dots(const float* ch, const float* tab, int n, int ld, double* out) {
  v8f acc[3][G] = {};
  for (int x = 0; x < n; x += kLanes) {
    v8f r = load8(ch + x), g = load8(ch + n + x), b = load8(ch + 2 * n + x);
    for (int j = 0; j < G; ++j) {
      v8f t = load8(tab + static_cast<size_t>(j) * n + x);
      acc[0][j] += r * t;
      acc[1][j] += g * t;
      acc[2][j] += b * t;
    }
  }
  for (int c = 0; c < 3; ++c)
    for (int j = 0; j < G; ++j) out[c * ld + j] = hsum(acc[c][j]);
}

Coeffs project_latlong(const ImageView& img, int bands, const ProgressFn& progress) {
  const int W = img.width(), H = img.height(), C = img.channels(), K = coeff_count(bands);
  const int Wp = (W + kLanes - 1) / kLanes * kLanes;
  const int J = 2 * bands - 1;  // tables: cos 0, then (Re, Im) w^m for m = 1..L
  const int Jp = J;
  // Column tables {Re, Im} w(a_x)^m in float (unit magnitude).
  const double delta = kTwoPi / W;
  std::vector<float> tab(static_cast<size_t>(Jp) * Wp, 0.0f);
  for (int x = 0; x < W; ++x) {
    double a = kTwoPi * (x + 0.5) / W;
    double wr = -std::sin(a), wi = -std::cos(a), cr = 1.0, ci = 0.0;
    tab[x] = 1.0f;
    for (int m = 1; m < bands; ++m) {
      double nr = cr * wr - ci * wi;
      ci = cr * wi + ci * wr;
      cr = nr;
      tab[static_cast<size_t>(2 * m - 1) * Wp + x] = static_cast<float>(cr);
      tab[static_cast<size_t>(2 * m) * Wp + x] = static_cast<float>(ci);
    }
  }
  // Column factor of order m: the exact pixel integral Δ sinc(mΔ/2), applied in double.
  std::vector<double> colf(bands);
  for (int m = 0; m < bands; ++m) colf[m] = m == 0 ? delta : delta * std::sin(0.5 * m * delta) / (0.5 * m * delta);
  std::vector<double> gz, gw;
  gauss_legendre(4, &gz, &gw);
  std::vector<double> norm(bands * bands, 0.0);
  for (int l = 0; l < bands; ++l)
    for (int m = 0; m <= l; ++m) norm[l * bands + m] = norm_constant(l, m);

  std::atomic<int> rows_done{0};
  const int64_t chunk = 16;
  Partial total = parallel_reduce_fixed<Partial>(
      0, H, chunk, Partial{},
      [&](int64_t y0, int64_t y1) {
        Partial p;
        p.v.assign(3 * K, 0.0);
        std::vector<float> ch(3 * static_cast<size_t>(Wp), 0.0f);
        std::vector<double> sums(3 * static_cast<size_t>(Jp));
        std::vector<double> G(bands * bands), P(bands * bands);
        for (int64_t y = y0; y < y1; ++y) {
          // Row term G_lm = ∫ K_lm P̃_lm(z) (1−z²)^{m/2} dz over the row.
          double z0 = std::cos(kPi * y / H), z1 = std::cos(kPi * (y + 1) / H);
          std::fill(G.begin(), G.end(), 0.0);
          for (int g = 0; g < 4; ++g) {
            double z = 0.5 * (z0 + z1) + 0.5 * (z0 - z1) * gz[g], w = 0.5 * (z0 - z1) * gw[g];
            double s = std::sqrt(std::max(0.0, 1.0 - z * z));
            legendre_table(bands, z, P.data());
            double sm = 1.0;
            for (int m = 0; m < bands; ++m) {
              for (int l = m; l < bands; ++l)
                G[l * bands + m] += w * colf[m] * norm[l * bands + m] * P[l * bands + m] * sm;
              sm *= s;
            }
          }
          // De-interleave the row.
          const float* row = img.pixel(0, static_cast<int>(y));
          for (int x = 0; x < W; ++x) {
            const float* px = row + static_cast<size_t>(x) * C;
            ch[x] = px[0];
            ch[Wp + x] = C >= 3 ? px[1] : px[0];
            ch[2 * Wp + x] = C >= 3 ? px[2] : px[0];
          }
          int j = 0;
          for (; j + 4 <= J; j += 4) row_dots<4>(ch.data(), &tab[static_cast<size_t>(j) * Wp], Wp, Jp, &sums[j]);
          for (; j < J; ++j) row_dots<1>(ch.data(), &tab[static_cast<size_t>(j) * Wp], Wp, Jp, &sums[j]);
          for (int l = 0; l < bands; ++l) {
            for (int c = 0; c < 3; ++c) {
              p.v[3 * index(l, 0) + c] += G[l * bands] * sums[c * Jp];
              for (int m = 1; m <= l; ++m) {
                p.v[3 * index(l, m) + c] += G[l * bands + m] * sums[c * Jp + 2 * m - 1];
                p.v[3 * index(l, -m) + c] += G[l * bands + m] * sums[c * Jp + 2 * m];
              }
            }
          }
        }
        int done = rows_done.fetch_add(static_cast<int>(y1 - y0)) + static_cast<int>(y1 - y0);
        report(progress, "SH projection", static_cast<double>(done) / H);
        return p;
      },
      [](Partial a, const Partial& b) { return add(std::move(a), b); });

  Coeffs primed(bands);
  for (int k = 0; k < K; ++k) primed.c[k] = {total.v[3 * k], total.v[3 * k + 1], total.v[3 * k + 2]};
  // f(d) = h(P d) with h the primed function, i.e. f = h(Rᵀ d) with R = Pᵀ.
  const Mat3 P = Mat3::rows({0, 0, 1}, {1, 0, 0}, {0, 1, 0});
  return rotate(primed, P.transposed());
}

// The basis averaged over pixel (x, y). Pixels whose corners see directions less than kSpread
// apart use the centre; others (mirror-ball and angular rims, pixels cut by the disc edge) average
// n×n sub-pixel directions, n = ⌈spread / kSpread⌉ ≤ kMaxSub, over the sub-points that carry data,
// each weighted by the mapping's local Jacobian so that the average is over solid angle.
// False when no point of the pixel has a direction.
constexpr double kSpread = 0.02;  // rad: the basis of band l changes by ~l·0.02 across such a pixel
constexpr int kMaxSub = 8;
bool pixel_basis(const sphere::Mapping& m, int bands, int x, int y, double* out, double* tmp) {
  const int K = coeff_count(bands);
  Vec3 c, corner[4];
  bool centre_ok = m.to_direction(x + 0.5, y + 0.5, &c);
  bool corners_ok = true;
  double min_dot = 1.0;
  for (int i = 0; i < 4; ++i) {
    corners_ok = m.to_direction(x + (i & 1), y + (i >> 1), &corner[i]) && corners_ok;
    if (centre_ok && corners_ok) min_dot = std::min(min_dot, dot(c, corner[i]));
  }
  static const double kCosSpread = std::cos(kSpread);
  if (centre_ok && corners_ok && min_dot >= kCosSpread) {
    eval_basis(bands, c, out);
    return true;
  }
  const double spread = std::acos(std::clamp(min_dot, -1.0, 1.0));
  int n = centre_ok && corners_ok ? std::min(kMaxSub, static_cast<int>(std::ceil(spread / kSpread))) : kMaxSub;
  std::fill(out, out + K, 0.0);
  double wsum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      // Sub-point weighted by the local Jacobian |∂d/∂x × ∂d/∂y| (one-sided differences).
      const double px = x + (i + 0.5) / n, py = y + (j + 0.5) / n, e = 1e-3 / n;
      Vec3 d, dx, dy;
      if (!m.to_direction(px, py, &d)) continue;
      bool okx = m.to_direction(px + e, py, &dx) || m.to_direction(px - e, py, &dx);
      bool oky = m.to_direction(px, py + e, &dy) || m.to_direction(px, py - e, &dy);
      double w = okx && oky ? length(cross(dx - d, dy - d)) : 0.0;
      if (w <= 0) continue;
      eval_basis(bands, d, tmp);
      for (int k = 0; k < K; ++k) out[k] += w * tmp[k];
      wsum += w;
    }
  if (wsum <= 0) return false;
  for (int k = 0; k < K; ++k) out[k] /= wsum;
  return true;
}

}  // namespace

Coeffs project_generic(const ImageView& img, const sphere::Mapping& m, int bands, const ProgressFn& progress) {
  check_bands(bands);
  const int W = img.width(), H = img.height(), C = img.channels(), K = coeff_count(bands);
  std::atomic<int> rows_done{0};
  Partial total = parallel_reduce_fixed<Partial>(
      0, H, 8, Partial{},
      [&](int64_t y0, int64_t y1) {
        Partial p;
        p.v.assign(3 * K, 0.0);
        std::vector<double> yb(K), tmp(K);
        for (int64_t y = y0; y < y1; ++y) {
          for (int x = 0; x < W; ++x) {
            double w = m.solid_angle(x, static_cast<int>(y));
            if (w <= 0) continue;
            if (!pixel_basis(m, bands, x, static_cast<int>(y), yb.data(), tmp.data())) continue;
            Vec3 L = pixel_rgb(img.pixel(x, static_cast<int>(y)), C) * w;
            for (int k = 0; k < K; ++k) {
              p.v[3 * k] += L.x * yb[k];
              p.v[3 * k + 1] += L.y * yb[k];
              p.v[3 * k + 2] += L.z * yb[k];
            }
          }
        }
        int done = rows_done.fetch_add(static_cast<int>(y1 - y0)) + static_cast<int>(y1 - y0);
        report(progress, "SH projection", static_cast<double>(done) / H);
        return p;
      },
      [](Partial a, const Partial& b) { return add(std::move(a), b); });
  Coeffs out(bands);
  for (int k = 0; k < K; ++k) out.c[k] = {total.v[3 * k], total.v[3 * k + 1], total.v[3 * k + 2]};
  return out;
}

Coeffs project_generic(const sphere::EnvMap& env, int bands, const ProgressFn& progress) {
  return project_generic(env.image.view(), env.mapping, bands, progress);
}

Coeffs project(const ImageView& img, const sphere::Mapping& m, int bands, const ProgressFn& progress) {
  check_bands(bands);
  if (img.width() == 0 || img.height() == 0) fail(ErrorKind::Value, "cannot project an empty image onto SH");
  if (img.width() != m.width() || img.height() != m.height())
    fail(ErrorKind::Value, "SH projection: the image is {}x{} but its mapping {}x{}", img.width(), img.height(),
         m.width(), m.height());
  if (m.kind() == MappingKind::LatLong) return project_latlong(img, bands, progress);
  return project_generic(img, m, bands, progress);
}

Coeffs project(const sphere::EnvMap& env, int bands, const ProgressFn& progress) {
  return project(env.image.view(), env.mapping, bands, progress);
}

Coeffs project_function(const std::function<Vec3(Vec3)>& f, int bands, int degree) {
  check_bands(bands);
  const SphereQuadrature q = exact_quadrature(degree >= 0 ? degree : 2 * (bands - 1) + 8);
  Coeffs out(bands);
  std::vector<double> y(coeff_count(bands));
  for (size_t i = 0; i < q.directions.size(); ++i) {
    Vec3 v = f(q.directions[i]) * q.weights[i];
    eval_basis(bands, q.directions[i], y.data());
    for (int k = 0; k < coeff_count(bands); ++k) out.c[k] += v * y[k];
  }
  return out;
}

Image reconstruct(const Coeffs& c, const sphere::Mapping& m) {
  c.validate("SH coefficients");
  Image out(m.width(), m.height(), 3);
  const int K = coeff_count(c.bands);
  parallel_for(0, m.height(), [&](int64_t y) {
    std::vector<double> yb(K);
    for (int x = 0; x < m.width(); ++x) {
      Vec3 d;
      if (!m.to_direction(x + 0.5, y + 0.5, &d)) continue;
      eval_basis(c.bands, d, yb.data());
      Vec3 s;
      for (int k = 0; k < K; ++k) s += c.c[k] * yb[k];
      out.set_rgb(x, static_cast<int>(y), s);
    }
  });
  return out;
}

}  // namespace ibl::sh
