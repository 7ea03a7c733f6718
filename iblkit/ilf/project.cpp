#include "iblkit/ilf/project.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>

#include "iblkit/core/enum_names.h"
#include "iblkit/core/error.h"

namespace ibl::ilf {

namespace {
constexpr EnumName<Repair> kRepairNames[] = {
    {Repair::None, "none"}, {Repair::Mip, "mip"}, {Repair::PullPush, "pullpush"}, {Repair::PullPush, "pull-push"}};
}  // namespace

const char* repair_name(Repair r) { return name_of(kRepairNames, r); }
Repair parse_repair(const std::string& s) { return parse_enum(kRepairNames, s, "repair method"); }

namespace {

// Pull–push on a W×H raster of RGB values with binary coverage (Gortler et al. 1996, "The Lumigraph",
// §3.4): pull builds coarser levels as coverage-weighted box averages with weight min(1, Σw); push
// replaces each value by w·v + (1 − w)·(bilinear of the coarser level). Pixels with data keep theirs.
void pull_push(std::vector<float>& v, std::vector<float>& w, int W, int H, std::vector<float>& tmp) {
  struct Level {
    size_t off;
    int w, h;
  };
  std::vector<Level> lv{{0, W, H}};
  size_t total = size_t(W) * H;
  while (lv.back().w > 1 || lv.back().h > 1) {
    int nw = (lv.back().w + 1) / 2, nh = (lv.back().h + 1) / 2;
    lv.push_back({total, nw, nh});
    total += size_t(nw) * nh;
  }
  tmp.assign(total * 4, 0.0f);  // per pixel: r, g, b, w
  for (size_t i = 0; i < size_t(W) * H; ++i) {
    tmp[i * 4 + 0] = v[i * 3 + 0];
    tmp[i * 4 + 1] = v[i * 3 + 1];
    tmp[i * 4 + 2] = v[i * 3 + 2];
    tmp[i * 4 + 3] = w[i];
  }
  for (size_t l = 1; l < lv.size(); ++l) {
    const Level &f = lv[l - 1], &c = lv[l];
    for (int y = 0; y < c.h; ++y)
      for (int x = 0; x < c.w; ++x) {
        float acc[4] = {0, 0, 0, 0};
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            int fx = 2 * x + dx, fy = 2 * y + dy;
            if (fx >= f.w || fy >= f.h) continue;
            const float* p = &tmp[(f.off + size_t(fy) * f.w + fx) * 4];
            for (int ch = 0; ch < 3; ++ch) acc[ch] += p[3] * p[ch];
            acc[3] += p[3];
          }
        float* q = &tmp[(c.off + size_t(y) * c.w + x) * 4];
        for (int ch = 0; ch < 3; ++ch) q[ch] = acc[3] > 0 ? acc[ch] / acc[3] : 0.0f;
        q[3] = std::min(1.0f, acc[3]);
      }
  }
  for (size_t l = lv.size() - 1; l-- > 0;) {
    const Level &f = lv[l], &c = lv[l + 1];
    for (int y = 0; y < f.h; ++y)
      for (int x = 0; x < f.w; ++x) {
        float* p = &tmp[(f.off + size_t(y) * f.w + x) * 4];
        if (p[3] >= 1.0f) continue;
        double cx = std::clamp((x + 0.5) / 2 - 0.5, 0.0, double(c.w - 1)),
               cy = std::clamp((y + 0.5) / 2 - 0.5, 0.0, double(c.h - 1));
        int x0 = int(cx), y0 = int(cy), x1 = std::min(x0 + 1, c.w - 1), y1 = std::min(y0 + 1, c.h - 1);
        float fx = float(cx - x0), fy = float(cy - y0);
        for (int ch = 0; ch < 3; ++ch) {
          auto at = [&](int xx, int yy) { return tmp[(c.off + size_t(yy) * c.w + xx) * 4 + ch]; };
          float up =
              (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
          p[ch] = p[3] * p[ch] + (1 - p[3]) * up;
        }
        p[3] = 1.0f;
      }
  }
  for (size_t i = 0; i < size_t(W) * H; ++i)
    for (int ch = 0; ch < 3; ++ch) v[i * 3 + ch] = tmp[i * 4 + ch];
}

// The held-out estimates of one bucket (CvBucket): for each probe of fold f, the rasters' sum minus
// fold f's, read bilinearly at the projections of its cell's 8 corners (raster x = a[0] + i·a[1] +
// j·a[2] + k·a[3], y alike), the covered corners' values trilinearly weighted and renormalised —
// SHGrid::coeffs_at of the grid built without fold f, where that grid's points have data. Where none
// of the 8 has data (the build would repair them), the finest level of the complement's 2×2 box
// pyramid holding data at the probe's own projection: the pull of pull–push, the repair's stand-in.
void cross_validate(const CvBucket& cv, const BucketRays& rays, const GridDesc& grid, ProjectScratch& sc, int W, int H,
                    std::array<double, 4> a, std::array<double, 4> b) {
  size_t npx = size_t(W) * H;
  std::vector<int> pyr_of(size_t(cv.n_folds), -1);  // offset index into sc.pyr per fold, built on demand
  std::vector<std::array<int, 3>> levels;           // per level: w, h, offset (in 4-float pixels)
  int pyr_total = 0;
  {
    int w = W, h = H;
    levels.push_back({w, h, 0});
    pyr_total = w * h;
    while (w > 1 || h > 1) {
      w = (w + 1) / 2;
      h = (h + 1) / 2;
      levels.push_back({w, h, pyr_total});
      pyr_total += w * h;
    }
  }
  int built = 0;
  auto bil = [&](const float* r, int ch, int nch, size_t i00, float fx, float fy) {
    return (1 - fx) * (1 - fy) * r[i00 * nch + ch] + fx * (1 - fy) * r[(i00 + 1) * nch + ch] +
           (1 - fx) * fy * r[(i00 + W) * nch + ch] + fx * fy * r[(i00 + W + 1) * nch + ch];
  };
  for (int p = 0; p < rays.n_probes; ++p) {
    if (rays.valid && !rays.valid[p]) continue;
    int f = cv.fold[p];
    const float* fn = sc.fnum.data() + size_t(f) * npx * 3;
    const float* fd = sc.fden.data() + size_t(f) * npx;
    const int32_t* c0 = cv.cell + 3 * size_t(p);
    const float* t = cv.frac + 3 * size_t(p);
    double acc[3] = {0, 0, 0}, ws = 0;
    for (int c = 0; c < 8; ++c) {
      int ii = c0[0] + (c & 1), jj = c0[1] + ((c >> 1) & 1), kk = c0[2] + (c >> 2);
      double w = ((c & 1) ? t[0] : 1 - t[0]) * ((c & 2) ? t[1] : 1 - t[1]) * ((c & 4) ? t[2] : 1 - t[2]);
      if (w <= 0) continue;
      double px = std::clamp(a[0] + ii * a[1] + jj * a[2] + kk * a[3], 0.0, W - 1.001);
      double py = std::clamp(b[0] + ii * b[1] + jj * b[2] + kk * b[3], 0.0, H - 1.001);
      int x0 = int(px), y0 = int(py);
      float fx = float(px - x0), fy = float(py - y0);
      size_t i00 = size_t(y0) * W + x0;
      float da = bil(sc.den.data(), 0, 1, i00, fx, fy), dm = da - bil(fd, 0, 1, i00, fx, fy);
      if (!(dm > 1e-4f * da + 1e-6f)) continue;
      for (int ch = 0; ch < 3; ++ch)
        acc[ch] += w * (bil(sc.num.data(), ch, 3, i00, fx, fy) - bil(fn, ch, 3, i00, fx, fy)) / dm;
      ws += w;
    }
    if (ws > 0) {
      for (int ch = 0; ch < 3; ++ch) cv.pred[ch * cv.stride + p] = float(acc[ch] / ws);
      continue;
    }
    // Fallback: the complement's box pyramid at the probe's projection.
    if (pyr_of[f] < 0) {
      pyr_of[f] = built++;
      sc.pyr.resize(size_t(built) * pyr_total * 4);
      float* P = sc.pyr.data() + size_t(pyr_of[f]) * pyr_total * 4;
      for (size_t i = 0; i < npx; ++i) {
        for (int ch = 0; ch < 3; ++ch) P[i * 4 + ch] = sc.num[i * 3 + ch] - fn[i * 3 + ch];
        P[i * 4 + 3] = sc.den[i] - fd[i];
      }
      for (size_t l = 1; l < levels.size(); ++l) {
        auto [fw, fh, fo] = levels[l - 1];
        auto [cw, ch_, co] = levels[l];
        for (int y = 0; y < ch_; ++y)
          for (int x = 0; x < cw; ++x) {
            float* q = P + (size_t(co) + size_t(y) * cw + x) * 4;
            q[0] = q[1] = q[2] = q[3] = 0;
            for (int dy = 0; dy < 2; ++dy)
              for (int dx = 0; dx < 2; ++dx) {
                int xx = 2 * x + dx, yy = 2 * y + dy;
                if (xx >= fw || yy >= fh) continue;
                const float* s = P + (size_t(fo) + size_t(yy) * fw + xx) * 4;
                for (int k = 0; k < 4; ++k) q[k] += s[k];
              }
          }
      }
    }
    const float* P = sc.pyr.data() + size_t(pyr_of[f]) * pyr_total * 4;
    double ci = c0[0] + t[0], cj = c0[1] + t[1], ck = c0[2] + t[2];
    int x = std::clamp(int(a[0] + ci * a[1] + cj * a[2] + ck * a[3]), 0, W - 1);
    int y = std::clamp(int(b[0] + ci * b[1] + cj * b[2] + ck * b[3]), 0, H - 1);
    float v[3] = {0, 0, 0};
    for (size_t l = 0; l < levels.size(); ++l) {
      auto [lw, lh, lo] = levels[l];
      const float* q = P + (size_t(lo) + size_t(std::min(y >> l, lh - 1)) * lw + std::min(x >> l, lw - 1)) * 4;
      if (q[3] > 1e-3f) {
        for (int ch = 0; ch < 3; ++ch) v[ch] = q[ch] / q[3];
        break;
      }
    }
    for (int ch = 0; ch < 3; ++ch) cv.pred[ch * cv.stride + p] = v[ch];
  }
  (void)grid;
}

}  // namespace

namespace {

// The plane of one bucket's projection (derivation below): its frame, the raster over the projected
// volume plus the kernel's support, and the bucket's mean direction, start offset and solid angle.
struct BucketPlane {
  double R = 0, sigma = 0, delta = 0;  // kernel support radius, its σ, the raster's pixel size
  Vec3 wb, c, ob;                      // mean direction, volume centre, mean ray start offset
  Frame fr;
  double lo[2] = {0, 0};  // raster pixel (0, 0) is the plane point lo
  int W = 0, H = 0;
  size_t npx = 0;
  double wsum = 0;  // the bucket's solid angle
};

BucketPlane bucket_plane(const GridDesc& grid, const BucketRays& rays, const ProjectDesc& desc) {
  Vec3 sp = grid.spacing();
  double h = std::max({sp.x, sp.y, sp.z});
  double R = std::max(desc.kernel_cells, 1e-3) * h / 2, sigma = R / 2, delta = std::max(desc.raster_cells, 0.05) * h;
  Vec3 wb{0, 0, 0};
  for (int q = 0; q < rays.n_dirs; ++q)
    wb += Vec3(rays.dirs[3 * q], rays.dirs[3 * q + 1], rays.dirs[3 * q + 2]) * rays.weights[q];
  wb = normalize(wb);
  Frame fr = Frame::from_normal(wb);
  Vec3 c = grid.volume.centre();
  // Raster extent: the projected volume corners plus the support.
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (int k = 0; k < 8; ++k) {
    Vec3 p{(k & 1) ? grid.volume.max.x : grid.volume.min.x, (k & 2) ? grid.volume.max.y : grid.volume.min.y,
           (k & 4) ? grid.volume.max.z : grid.volume.min.z};
    double a = dot(p - c, fr.t), b = dot(p - c, fr.b);
    lo[0] = std::min(lo[0], a);
    hi[0] = std::max(hi[0], a);
    lo[1] = std::min(lo[1], b);
    hi[1] = std::max(hi[1], b);
  }
  lo[0] -= R + delta;
  lo[1] -= R + delta;
  hi[0] += R + delta;
  hi[1] += R + delta;
  int W = int(std::ceil((hi[0] - lo[0]) / delta)) + 1, H = int(std::ceil((hi[1] - lo[1]) / delta)) + 1;
  size_t npx = size_t(W) * H;
  Vec3 ob{0, 0, 0};  // the bucket's mean ray start offset (cross-validation reads there)
  double wsum = 0;
  for (int q = 0; q < rays.n_dirs; ++q) {
    if (rays.starts) ob += Vec3(rays.starts[3 * q], rays.starts[3 * q + 1], rays.starts[3 * q + 2]) * rays.weights[q];
    wsum += rays.weights[q];
  }
  if (wsum > 0) ob = ob / wsum;
  BucketPlane pl{R, sigma, delta, wb, c, ob, fr, {lo[0], lo[1]}, W, H, npx, wsum};
  return pl;
}

// Splats every valid probe's rays of the bucket into the plane rasters (num, den; with cv one pair
// per fold, summed into num, den at the end) and sets cv's own means.
void splat_rays(const BucketPlane& pl, const BucketRays& rays, const CvBucket* cv, ProjectScratch& sc,
                ProjectStats& st) {
  const double R = pl.R, sigma = pl.sigma, delta = pl.delta;
  const Vec3 wb = pl.wb, c = pl.c, ob = pl.ob;
  const Frame& fr = pl.fr;
  const double* lo = pl.lo;
  const int W = pl.W, H = pl.H;
  const size_t npx = pl.npx;
  const double wsum = pl.wsum;
  int rad_px = int(std::ceil(R / delta));
  double inv2s2 = 1.0 / (2 * sigma * sigma), R2 = R * R;
  std::vector<double> dx2(size_t(2 * rad_px + 2));
  std::vector<float> ex(size_t(2 * rad_px + 2));
  for (int p = 0; p < rays.n_probes; ++p) {
    if (rays.valid && !rays.valid[p]) {
      if (cv)
        for (int ch = 0; ch < 3; ++ch) cv->own[ch * cv->stride + p] = cv->pred[ch * cv->stride + p] = 0.0f;
      continue;
    }
    const float* L = rays.radiance(rays.ctx, p);
    Vec3 xp = rays.origins[p];
    float* num_t = cv ? sc.fnum.data() + size_t(cv->fold[p]) * npx * 3 : sc.num.data();
    float* den_t = cv ? sc.fden.data() + size_t(cv->fold[p]) * npx : sc.den.data();
    if (cv) {
      double m[3] = {0, 0, 0};
      for (int q = 0; q < rays.n_dirs; ++q)
        for (int ch = 0; ch < 3; ++ch) m[ch] += rays.weights[q] * L[3 * q + ch];
      for (int ch = 0; ch < 3; ++ch) cv->own[ch * cv->stride + p] = wsum > 0 ? float(m[ch] / wsum) : 0.0f;
    }
    for (int q = 0; q < rays.n_dirs; ++q) {
      Vec3 wq{rays.dirs[3 * q], rays.dirs[3 * q + 1], rays.dirs[3 * q + 2]};
      double cosq = dot(wq, wb);
      if (cosq < 1e-3) continue;
      Vec3 x = rays.starts ? xp + Vec3(rays.starts[3 * q], rays.starts[3 * q + 1], rays.starts[3 * q + 2]) : xp;
      Vec3 y = x + wq * (dot(c - x, wb) / cosq) - c;
      double px = (dot(y, fr.t) - lo[0]) / delta, py = (dot(y, fr.b) - lo[1]) / delta;  // raster coords
      int cx = int(std::floor(px)), cy = int(std::floor(py));
      if (cx < -rad_px || cy < -rad_px || cx >= W + rad_px || cy >= H + rad_px) continue;
      ++st.rays;
      float r = L[3 * q], g = L[3 * q + 1], b = L[3 * q + 2];
      // The Gaussian is separable: K = exp(−dx²/2σ²)·exp(−dy²/2σ²) inside the disc d² < R².
      int x0 = std::max(0, cx - rad_px), x1 = std::min(W - 1, cx + rad_px + 1);
      int y0 = std::max(0, cy - rad_px), y1 = std::min(H - 1, cy + rad_px + 1);
      for (int xx = x0; xx <= x1; ++xx) {
        double dx = (xx - px) * delta;
        dx2[xx - x0] = dx * dx;
        ex[xx - x0] = float(std::exp(-dx * dx * inv2s2));
      }
      for (int yy = y0; yy <= y1; ++yy) {
        double dy = (yy - py) * delta, dy2 = dy * dy;
        if (dy2 >= R2) continue;
        float ey = float(std::exp(-dy2 * inv2s2));
        float* nrow = num_t + (size_t(yy) * W) * 3;
        float* drow = den_t + size_t(yy) * W;
        for (int xx = x0; xx <= x1; ++xx) {
          if (dx2[xx - x0] + dy2 >= R2) continue;
          float k = ex[xx - x0] * ey;
          nrow[xx * 3] += k * r;
          nrow[xx * 3 + 1] += k * g;
          nrow[xx * 3 + 2] += k * b;
          drow[xx] += k;
        }
      }
    }
  }
  if (cv)  // the whole estimate is the sum of the folds'
    for (int f = 0; f < cv->n_folds; ++f) {
      const float* fn = sc.fnum.data() + size_t(f) * npx * 3;
      const float* fd = sc.fden.data() + size_t(f) * npx;
      for (size_t i = 0; i < npx * 3; ++i) sc.num[i] += fn[i];
      for (size_t i = 0; i < npx; ++i) sc.den[i] += fd[i];
    }
}

}  // namespace

// Derivation (radiance projection of one bucket, [1] §3.2 done on a plane):
//   A bucket holds rays R_pq(s) = x_p + s·ω_q (x_p + o_q + s·ω_q when the rays start on a mirror ball, o_q
//   the reflection point of direction q relative to the ball's centre: everything below with x_p + o_q), q over the
//   bucket's directions (one in pixel buckets), p over the probes. Let ω_b be the solid-angle-weighted mean of the ω_q
//   and Π the plane through the volume centre c perpendicular to ω_b, with orthonormal axes (t, u). Ray pq meets Π at
//     y_pq = x_p + λ·ω_q,  λ = (c − x_p)·ω_b / (ω_q·ω_b),
//   and a grid point g projects (along ω_b) to (g − c)·(t, u). For parallel rays (ω_q = ω_b) the 2D
//   distance between the two is exactly the distance from g to the ray, for either sign of s: the
//   sample is projected through the whole volume in both directions. The estimate is the normalised
//   Gaussian-weighted mean of the rays passing g within the kernel's support R = kernel·h/2:
//   ┌─────────────────────────────────────────────────────────────────────────────┐
//   │ L_b(g) = Σ_pq K(d_pq(g)) L_pq / Σ_pq K(d_pq(g)),  K(d) = exp(−d²/2σ²)·[d < R], σ = R/2 │
//   └─────────────────────────────────────────────────────────────────────────────┘
//   Numerator and denominator are splatted onto a raster of Π (pixel Δ = raster_cells·h) and read
//   back bilinearly at the projected grid points: O(rays·(2R/Δ)² + grid points) per bucket instead of
//   O(rays·grid points along the ray). For non-parallel rays of an octahedral bucket, the 2D distance
//   differs from the 3D one by at most |(g − c)·ω_b|·sin∠(ω_q, ω_b).
ProjectStats project_bucket(const GridDesc& grid, const BucketRays& rays, const ProjectDesc& desc, float* out,
                            int64_t out_stride, ProjectScratch& sc, const CvBucket* cv) {
  ProjectStats st;
  const BucketPlane pl = bucket_plane(grid, rays, desc);
  const size_t npx = pl.npx;
  const int W = pl.W, H = pl.H;
  const Frame& fr = pl.fr;
  const Vec3 c = pl.c, ob = pl.ob;
  const double delta = pl.delta;
  const double* lo = pl.lo;
  sc.num.assign(npx * 3, 0.0f);
  sc.den.assign(npx, 0.0f);
  if (cv) {
    sc.fnum.assign(npx * 3 * cv->n_folds, 0.0f);
    sc.fden.assign(npx * cv->n_folds, 0.0f);
  }
  splat_rays(pl, rays, cv, sc, st);
  // Raster pixel (xx, yy) is the plane point lo + (xx, yy)·Δ (the splat above evaluates K there).
  bool plane_fill = desc.repair == Repair::PullPush && !cv;
  if (plane_fill) {
    sc.rad.assign(npx * 3, 0.0f);
    std::vector<float> w(npx);
    for (size_t i = 0; i < npx; ++i) {
      w[i] = sc.den[i] > 0 ? 1.0f : 0.0f;
      for (int ch = 0; ch < 3; ++ch) sc.rad[i * 3 + ch] = sc.den[i] > 0 ? sc.num[i * 3 + ch] / sc.den[i] : 0.0f;
    }
    auto t0 = std::chrono::steady_clock::now();
    pull_push(sc.rad, w, W, H, sc.tmp);
    st.repair_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  int64_t G = grid.count();
  if (!cv) sc.covered.assign(size_t(G), 0);
  // Raster coordinates of grid point (i, j, k) are affine in (i, j, k): px = a0 + i·ai + j·aj + k·ak.
  Vec3 sp3 = grid.spacing(), o = grid.volume.min - c;
  double ax0 = (dot(o, fr.t) - lo[0]) / delta, ay0 = (dot(o, fr.b) - lo[1]) / delta;
  double axi = sp3.x * fr.t.x / delta, axj = sp3.y * fr.t.y / delta, axk = sp3.z * fr.t.z / delta;
  double ayi = sp3.x * fr.b.x / delta, ayj = sp3.y * fr.b.y / delta, ayk = sp3.z * fr.b.z / delta;
  const float* num = sc.num.data();
  const float* den_r = sc.den.data();
  const float* fill = plane_fill ? sc.rad.data() : nullptr;
  if (cv)
    cross_validate(*cv, rays, grid, sc, W, H, {ax0 + dot(ob, fr.t) / delta, axi, axj, axk},
                   {ay0 + dot(ob, fr.b) / delta, ayi, ayj, ayk});
  if (cv) return st;
  int64_t gi = 0;
  for (int k = 0; k < grid.nz; ++k)
    for (int j = 0; j < grid.ny; ++j) {
      double rx = ax0 + j * axj + k * axk, ry = ay0 + j * ayj + k * ayk;
      for (int i = 0; i < grid.nx; ++i, ++gi) {
        double px = std::clamp(rx + i * axi, 0.0, W - 1.001), py = std::clamp(ry + i * ayi, 0.0, H - 1.001);
        int x0 = int(px), y0 = int(py);
        float fx = float(px - x0), fy = float(py - y0);
        size_t i00 = size_t(y0) * W + x0, i10 = i00 + 1, i01 = i00 + W, i11 = i01 + 1;
        float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
        float den = w00 * den_r[i00] + w10 * den_r[i10] + w01 * den_r[i01] + w11 * den_r[i11];
        if (den > 0) {
          sc.covered[gi] = 1;
          float inv = 1.0f / den;
          for (int ch = 0; ch < 3; ++ch)
            out[ch * out_stride + gi] = (w00 * num[i00 * 3 + ch] + w10 * num[i10 * 3 + ch] + w01 * num[i01 * 3 + ch] +
                                         w11 * num[i11 * 3 + ch]) *
                                        inv;
        } else {
          ++st.uncovered;
          for (int ch = 0; ch < 3; ++ch)
            out[ch * out_stride + gi] = fill ? w00 * fill[i00 * 3 + ch] + w10 * fill[i10 * 3 + ch] +
                                                   w01 * fill[i01 * 3 + ch] + w11 * fill[i11 * 3 + ch]
                                             : 0.0f;
        }
      }
    }
  if (desc.repair == Repair::Mip && st.uncovered > 0) {
    auto t0 = std::chrono::steady_clock::now();
    repair_mip(grid, out, out_stride, sc.covered.data());
    st.repair_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return st;
}

int64_t repair_mip(const GridDesc& grid, float* values, int64_t stride, const uint8_t* covered) {
  struct Level {
    int nx, ny, nz;
    std::vector<float> v;
    std::vector<float> w;
  };  // v: rgb, w: data count
  std::vector<Level> lv;
  Level l0{grid.nx, grid.ny, grid.nz, {}, {}};
  int64_t G = grid.count(), filled = 0;
  l0.v.resize(size_t(G) * 3);
  l0.w.resize(size_t(G));
  for (int64_t g = 0; g < G; ++g) {
    l0.w[g] = covered[g] ? 1.0f : 0.0f;
    for (int ch = 0; ch < 3; ++ch) l0.v[g * 3 + ch] = covered[g] ? values[ch * stride + g] : 0.0f;
  }
  lv.push_back(std::move(l0));
  auto lookup = [&](const Level& L, double x, double y, double z, float* rgb) {
    x = std::clamp(x, 0.0, double(L.nx - 1));
    y = std::clamp(y, 0.0, double(L.ny - 1));
    z = std::clamp(z, 0.0, double(L.nz - 1));
    int x0 = int(x), y0 = int(y), z0 = int(z);
    double fx = x - x0, fy = y - y0, fz = z - z0, ws = 0, acc[3] = {0, 0, 0};
    for (int c = 0; c < 8; ++c) {
      int xi = std::min(x0 + (c & 1), L.nx - 1), yi = std::min(y0 + ((c >> 1) & 1), L.ny - 1),
          zi = std::min(z0 + (c >> 2), L.nz - 1);
      size_t i = (size_t(zi) * L.ny + yi) * L.nx + xi;
      if (L.w[i] <= 0) continue;
      double w = ((c & 1) ? fx : 1 - fx) * ((c & 2) ? fy : 1 - fy) * ((c & 4) ? fz : 1 - fz);
      ws += w;
      for (int ch = 0; ch < 3; ++ch) acc[ch] += w * L.v[i * 3 + ch];
    }
    if (ws <= 1e-12) return false;
    for (int ch = 0; ch < 3; ++ch) rgb[ch] = float(acc[ch] / ws);
    return true;
  };
  for (int64_t g = 0; g < G; ++g) {
    if (covered[g]) continue;
    int i = int(g % grid.nx), j = int((g / grid.nx) % grid.ny), k = int(g / (int64_t(grid.nx) * grid.ny));
    float rgb[3] = {0, 0, 0};
    for (size_t l = 1;; ++l) {
      if (l >= lv.size()) {
        const Level& f = lv.back();
        if (f.nx == 1 && f.ny == 1 && f.nz == 1) break;  // nothing anywhere: stays 0
        Level c{(f.nx + 1) / 2, (f.ny + 1) / 2, (f.nz + 1) / 2, {}, {}};
        c.v.assign(size_t(c.nx) * c.ny * c.nz * 3, 0.0f);
        c.w.assign(size_t(c.nx) * c.ny * c.nz, 0.0f);
        for (int z = 0; z < f.nz; ++z)
          for (int y = 0; y < f.ny; ++y)
            for (int x = 0; x < f.nx; ++x) {
              size_t fi = (size_t(z) * f.ny + y) * f.nx + x, ci = (size_t(z / 2) * c.ny + y / 2) * c.nx + x / 2;
              if (f.w[fi] <= 0) continue;
              c.w[ci] += 1.0f;
              for (int ch = 0; ch < 3; ++ch) c.v[ci * 3 + ch] += f.v[fi * 3 + ch];
            }
        for (size_t ci = 0; ci < c.w.size(); ++ci)
          if (c.w[ci] > 0)
            for (int ch = 0; ch < 3; ++ch) c.v[ci * 3 + ch] /= c.w[ci];
        lv.push_back(std::move(c));
      }
      double s = double(1 << l);
      if (lookup(lv[l], (i + 0.5) / s - 0.5, (j + 0.5) / s - 0.5, (k + 0.5) / s - 0.5, rgb)) break;
    }
    for (int ch = 0; ch < 3; ++ch) values[ch * stride + g] = rgb[ch];
    ++filled;
  }
  return filled;
}

}  // namespace ibl::ilf
