#include "iblkit/lights/evaluate.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#define IBLKIT_GT_AVX2 1
#endif

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::lights {

namespace {

/*
 * Ground-truth irradiance, exact and fast
 * ---------------------------------------
 * For every normal n and every pixel p with radiance L_p, direction ω_p (pixel centre) and exact
 * solid angle dω_p:
 *
 *     E(n) = Σ_p L_p · max(0, n·ω_p) · dω_p                                           (Madsen & Laursen eq. 3)
 *
 * which is 20480 × 524288 ≈ 10¹⁰ terms for the paper's setting. Two exact reductions:
 *
 *  1. Pixels are grouped in tiles (tile × tile pixels, only pixels with light kept, stored SoA in float).
 *     Each tile has a bounding cone (axis a, half-angle α) of its pixel directions. Since
 *     ∠(n, ω) ≤ ∠(n, a) + ∠(a, ω) ≤ ∠(n, a) + α, all its pixels face n when n·a ≥ sin α, and none
 *     do when n·a ≤ −sin α. For a tile entirely in front, max(0, n·ω) = n·ω and
 *
 *     ┌──────────────────────────────────────────────────────────────┐
 *     │  Σ_{p ∈ tile} L_p (n·ω_p) dω_p = M_tile · n,                 │
 *     │  M_tile[c] = Σ_{p ∈ tile} L_{p,c} dω_p ω_pᵀ   (3×3, double)  │
 *     └──────────────────────────────────────────────────────────────┘
 *
 *     a 3×3 product instead of a pass over its pixels; tiles behind n are skipped.
 *  2. The tiles that straddle n's horizon (a band of width ~2α around a great circle: a few percent of
 *     the pixels for 16×16 tiles) go through an 8-wide FMA kernel over every one of their pixels.
 *
 * Nothing is approximated: with cull = false every tile takes step 2 (pure brute force), and the
 * tests check that both agree. Threads run over blocks of normals; within a block every tile is read
 * once from memory and then stays in L1 for the block's normals.
 */

struct Tiles {
  // SoA pixel data, each tile padded to a multiple of 8 with zero radiance.
  std::vector<float> wx, wy, wz, r, g, b;
  struct Tile {
    size_t begin = 0, count = 0;  // padded range in the arrays
    Vec3 axis;
    double sin_half = 2.0;  // > 1: the cone is wider than a hemisphere, never classified
    double m[3][3] = {};    // M_tile per channel (rows) and direction component (columns)
  };
  std::vector<Tile> tiles;
};

Tiles build_tiles(const sphere::EnvMap& env, int tile) {
  const Image& img = env.image;
  const auto& map = env.mapping;
  int tw = (img.width() + tile - 1) / tile, th = (img.height() + tile - 1) / tile;
  int nc = img.channels();
  struct Px {
    Vec3 d, l;
  };
  std::vector<std::vector<Px>> per(static_cast<size_t>(tw) * th);
  parallel_for(0, static_cast<int64_t>(per.size()), [&](int64_t t) {
    int tx = static_cast<int>(t % tw), ty = static_cast<int>(t / tw);
    for (int y = ty * tile; y < std::min(img.height(), (ty + 1) * tile); ++y)
      for (int x = tx * tile; x < std::min(img.width(), (tx + 1) * tile); ++x) {
        const float* p = img.pixel(x, y);
        Vec3 L = nc >= 3 ? Vec3{p[0], p[1], p[2]} : Vec3{p[0], p[0], p[0]};
        if (L.x <= 0 && L.y <= 0 && L.z <= 0) continue;
        Vec3 d;
        if (!map.valid(x, y) || !map.to_direction(x + 0.5, y + 0.5, &d)) continue;
        double dw = map.solid_angle(x, y);
        if (dw <= 0) continue;
        per[t].push_back({normalize(d), L * dw});
      }
  });
  Tiles T;
  size_t total = 0;
  for (auto& v : per) total += (v.size() + 7) / 8 * 8;
  for (auto* a : {&T.wx, &T.wy, &T.wz, &T.r, &T.g, &T.b}) a->assign(total, 0.0f);
  size_t off = 0;
  for (auto& v : per) {
    if (v.empty()) continue;
    Tiles::Tile t;
    t.begin = off;
    t.count = (v.size() + 7) / 8 * 8;
    Vec3 mean;
    for (size_t i = 0; i < v.size(); ++i) {
      const Px& p = v[i];
      T.wx[off + i] = static_cast<float>(p.d.x);
      T.wy[off + i] = static_cast<float>(p.d.y);
      T.wz[off + i] = static_cast<float>(p.d.z);
      T.r[off + i] = static_cast<float>(p.l.x);
      T.g[off + i] = static_cast<float>(p.l.y);
      T.b[off + i] = static_cast<float>(p.l.z);
      mean += p.d;
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) t.m[c][k] += p.l[c] * p.d[k];
    }
    if (length(mean) > 1e-9) {
      t.axis = normalize(mean);
      double min_cos = 1.0;
      for (const Px& p : v) min_cos = std::min(min_cos, dot(p.d, t.axis));
      if (min_cos > 0) {
        double sin_half = std::sqrt(std::max(0.0, 1 - min_cos * min_cos));
        // Margin for the float directions the kernel uses (|error| ≲ 1e−7) and rounding here.
        constexpr double kConeMargin = 1e-5;
        t.sin_half = sin_half + kConeMargin;
      }
    }
    T.tiles.push_back(t);
    off += t.count;
  }
  return T;
}

// Σ over a tile's pixels of rgb·max(0, n·ω) (float lanes, returned in double).
inline Vec3 tile_kernel(const Tiles& T, const Tiles::Tile& t, Vec3 n) {
  const float *wx = T.wx.data() + t.begin, *wy = T.wy.data() + t.begin, *wz = T.wz.data() + t.begin;
  const float *r = T.r.data() + t.begin, *g = T.g.data() + t.begin, *b = T.b.data() + t.begin;
#ifdef IBLKIT_GT_AVX2
  __m256 nx = _mm256_set1_ps(static_cast<float>(n.x)), ny = _mm256_set1_ps(static_cast<float>(n.y)),
         nz = _mm256_set1_ps(static_cast<float>(n.z)), zero = _mm256_setzero_ps();
  __m256 ar0 = zero, ag0 = zero, ab0 = zero, ar1 = zero, ag1 = zero, ab1 = zero;
  size_t i = 0;
  for (; i + 16 <= t.count; i += 16) {
    __m256 d0 =
        _mm256_fmadd_ps(nx, _mm256_loadu_ps(wx + i),
                        _mm256_fmadd_ps(ny, _mm256_loadu_ps(wy + i), _mm256_mul_ps(nz, _mm256_loadu_ps(wz + i))));
    __m256 d1 = _mm256_fmadd_ps(
        nx, _mm256_loadu_ps(wx + i + 8),
        _mm256_fmadd_ps(ny, _mm256_loadu_ps(wy + i + 8), _mm256_mul_ps(nz, _mm256_loadu_ps(wz + i + 8))));
    d0 = _mm256_max_ps(d0, zero);
    d1 = _mm256_max_ps(d1, zero);
    ar0 = _mm256_fmadd_ps(d0, _mm256_loadu_ps(r + i), ar0);
    ag0 = _mm256_fmadd_ps(d0, _mm256_loadu_ps(g + i), ag0);
    ab0 = _mm256_fmadd_ps(d0, _mm256_loadu_ps(b + i), ab0);
    ar1 = _mm256_fmadd_ps(d1, _mm256_loadu_ps(r + i + 8), ar1);
    ag1 = _mm256_fmadd_ps(d1, _mm256_loadu_ps(g + i + 8), ag1);
    ab1 = _mm256_fmadd_ps(d1, _mm256_loadu_ps(b + i + 8), ab1);
  }
  for (; i < t.count; i += 8) {
    __m256 d0 =
        _mm256_fmadd_ps(nx, _mm256_loadu_ps(wx + i),
                        _mm256_fmadd_ps(ny, _mm256_loadu_ps(wy + i), _mm256_mul_ps(nz, _mm256_loadu_ps(wz + i))));
    d0 = _mm256_max_ps(d0, zero);
    ar0 = _mm256_fmadd_ps(d0, _mm256_loadu_ps(r + i), ar0);
    ag0 = _mm256_fmadd_ps(d0, _mm256_loadu_ps(g + i), ag0);
    ab0 = _mm256_fmadd_ps(d0, _mm256_loadu_ps(b + i), ab0);
  }
  alignas(32) float s[3][8];
  _mm256_store_ps(s[0], _mm256_add_ps(ar0, ar1));
  _mm256_store_ps(s[1], _mm256_add_ps(ag0, ag1));
  _mm256_store_ps(s[2], _mm256_add_ps(ab0, ab1));
  Vec3 out;
  for (int k = 0; k < 8; ++k) out += Vec3{s[0][k], s[1][k], s[2][k]};
  return out;
#else
  float ar = 0, ag = 0, ab = 0;
  float fx = static_cast<float>(n.x), fy = static_cast<float>(n.y), fz = static_cast<float>(n.z);
  for (size_t i = 0; i < t.count; ++i) {
    float d = std::max(0.0f, fx * wx[i] + fy * wy[i] + fz * wz[i]);
    ar += d * r[i];
    ag += d * g[i];
    ab += d * b[i];
  }
  return {ar, ag, ab};
#endif
}

}  // namespace

std::vector<Vec3> irradiance_ground_truth(const sphere::EnvMap& env, const std::vector<Vec3>& normals,
                                          const GroundTruthDesc& desc) {
  if (env.image.empty()) fail(ErrorKind::Value, "the probe is empty (0 pixels)");
  if (desc.tile < 1 || desc.normal_block < 1)
    fail(ErrorKind::Value, "ground truth: tile ({}) and normal_block ({}) must be positive", desc.tile,
         desc.normal_block);
  Tiles T = build_tiles(env, desc.tile);
  std::vector<Vec3> out(normals.size());
  int64_t nblocks = (static_cast<int64_t>(normals.size()) + desc.normal_block - 1) / desc.normal_block;
  std::atomic<int64_t> done{0};
  parallel_for(0, nblocks, [&](int64_t blk) {
    size_t lo = static_cast<size_t>(blk) * desc.normal_block, hi = std::min(normals.size(), lo + desc.normal_block);
    std::vector<Vec3> acc(hi - lo);
    for (const auto& t : T.tiles) {
      for (size_t k = lo; k < hi; ++k) {
        const Vec3& n = normals[k];
        if (desc.cull) {
          double c = dot(n, t.axis);
          if (c <= -t.sin_half) continue;
          if (c >= t.sin_half) {
            acc[k - lo] += Vec3{t.m[0][0] * n.x + t.m[0][1] * n.y + t.m[0][2] * n.z,
                                t.m[1][0] * n.x + t.m[1][1] * n.y + t.m[1][2] * n.z,
                                t.m[2][0] * n.x + t.m[2][1] * n.y + t.m[2][2] * n.z};
            continue;
          }
        }
        acc[k - lo] += tile_kernel(T, t, n);
      }
    }
    for (size_t k = lo; k < hi; ++k) out[k] = acc[k - lo];
    int64_t d = ++done;
    if (desc.progress) report(desc.progress, "ground truth", static_cast<double>(d) / nblocks);
  });
  return out;
}

std::vector<Vec3> irradiance_from_lights(const std::vector<Light>& lights, const std::vector<Vec3>& normals) {
  std::vector<Vec3> out(normals.size());
  parallel_chunks(
      0, static_cast<int64_t>(normals.size()),
      [&](int64_t lo, int64_t hi) {
        for (int64_t k = lo; k < hi; ++k) {
          Vec3 e;
          for (const auto& l : lights) {
            double c = dot(normals[k], l.direction);
            if (c > 0) e += l.irradiance * c;
          }
          out[k] = e;
        }
      },
      256);
  return out;
}

namespace {
Vec3 channel_floor(const std::vector<Vec3>& gt, double fraction) {
  Vec3 mean;
  for (const auto& e : gt) mean += e;
  mean = mean / static_cast<double>(std::max<size_t>(1, gt.size()));
  constexpr double kTiny = 1e-300;  // keeps the division defined for a channel that is 0 everywhere
  return {std::max(mean.x * fraction, kTiny), std::max(mean.y * fraction, kTiny), std::max(mean.z * fraction, kTiny)};
}
}  // namespace

ErrorStats compare_irradiance(const std::vector<Vec3>& est, const std::vector<Vec3>& gt, const ErrorDesc& desc) {
  if (est.size() != gt.size() || gt.empty())
    fail(ErrorKind::Value, "compare_irradiance: {} estimates against {} ground-truth values", est.size(), gt.size());
  Vec3 floor = channel_floor(gt, desc.floor_fraction);
  double sum[3] = {}, mx[3] = {}, sq[3] = {}, sqa[3] = {};
  ErrorStats s;
  for (size_t k = 0; k < gt.size(); ++k) {
    s.mean_est += est[k];
    s.mean_gt += gt[k];
    for (int c = 0; c < 3; ++c) {
      double d = est[k][c] - gt[k][c];
      double rel = std::abs(d) / std::max(gt[k][c], floor[c]);
      sum[c] += rel;
      mx[c] = std::max(mx[c], rel);
      sq[c] += rel * rel;
      sqa[c] += d * d;
    }
  }
  double n = static_cast<double>(gt.size());
  for (int c = 0; c < 3; ++c) {
    s.mean_rel += sum[c] / n / 3;
    s.max_rel += mx[c] / 3;
    s.rms_rel += std::sqrt(sq[c] / n) / 3;
    s.rms_abs += std::sqrt(sqa[c] / n) / 3;
  }
  s.mean_est = s.mean_est / n;
  s.mean_gt = s.mean_gt / n;
  return s;
}

std::vector<double> relative_error_luminance(const std::vector<Vec3>& est, const std::vector<Vec3>& gt,
                                             const ErrorDesc& desc) {
  if (est.size() != gt.size()) fail(ErrorKind::Value, "relative_error_luminance: sizes differ");
  double mean = 0;
  for (const auto& e : gt) mean += luminance(e);
  mean /= std::max<size_t>(1, gt.size());
  double floor = std::max(mean * desc.floor_fraction, 1e-300);
  std::vector<double> out(gt.size());
  for (size_t k = 0; k < gt.size(); ++k)
    out[k] = std::abs(luminance(est[k]) - luminance(gt[k])) / std::max(luminance(gt[k]), floor);
  return out;
}

}  // namespace ibl::lights
