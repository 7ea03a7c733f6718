#include "iblkit/capture/merge.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/core/rng.h"

namespace ibl::capture {

double hat_weight(double z) {
  if (!(z > kBlackCode && z < kSaturatedCode)) return 0.0;
  return z <= 0.5 ? (z - kBlackCode) / (0.5 - kBlackCode) : (kSaturatedCode - z) / (kSaturatedCode - 0.5);
}

namespace {

// Frame j's code value at reference pixel (x, y) under its shift, or -1 outside the frame.
struct Shifted {
  const Frame* f;
  int dx, dy;
  float code(int x, int y, int c) const {
    const int u = x + dx, v = y + dy;
    if (u < 0 || v < 0 || u >= f->codes.width() || v >= f->codes.height()) return -1.0f;
    return f->codes.pixel(u, v)[c];
  }
};

std::vector<Shifted> shifted(const std::vector<Frame>& frames, const std::vector<std::array<int, 2>>& shifts) {
  std::vector<Shifted> s;
  for (size_t j = 0; j < frames.size(); ++j)
    s.push_back({&frames[j], shifts.empty() ? 0 : shifts[j][0], shifts.empty() ? 0 : shifts[j][1]});
  return s;
}

void check_frames(const std::vector<Frame>& frames) {
  if (frames.size() < 2)
    fail(ErrorKind::Value, "{}: one photograph only: an HDR merge needs a bracket of at least two exposures",
         frames.empty() ? std::string("(no input)") : frames[0].name);
  const Frame& f0 = frames[0];
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (const Frame& f : frames) {
    if (f.codes.empty() || f.codes.channels() != 3)
      fail(ErrorKind::Value, "{}: needs 3 channels of code values, has {}", f.name, f.codes.channels());
    if (f.codes.width() != f0.codes.width() || f.codes.height() != f0.codes.height())
      fail(ErrorKind::Value, "{}: {}x{}, but {} is {}x{}: every photograph of a bracket must have the same size",
           f.name, f.codes.width(), f.codes.height(), f0.name, f0.codes.width(), f0.codes.height());
    if (!(std::isfinite(f.exposure) && f.exposure > 0 && f.exposure < 1e12))
      fail(ErrorKind::Value, "{}: exposure {} must be a positive number (fix it with --exposures)", f.name, f.exposure);
    lo = std::min(lo, f.exposure);
    hi = std::max(hi, f.exposure);
  }
  // Less than a fifth of a stop between the extremes is no bracket.
  if (!(hi > lo * std::exp2(0.2)))
    fail(ErrorKind::Value,
         "{}: no exposure spread: every photograph has exposure {:g} (relative); shoot a bracket, or give the real "
         "exposures with --exposures",
         f0.name, lo);
}

// Makes an increasing table of ln values strictly increasing in exp, and ends it at 1 for code 1.
Response finish_curve(const char* kind, std::array<std::vector<double>, 3> lng) {
  Response r;
  r.kind = kind;
  for (int c = 0; c < 3; ++c) {
    auto& g = lng[c];
    std::vector<double> t(g.size());
    for (size_t k = 0; k < g.size(); ++k) {
      t[k] = std::exp(g[k]);
      if (k > 0) t[k] = std::max(t[k], t[k - 1] * (1 + 1e-9) + 1e-300);
    }
    const double top = t.back();
    for (double& v : t) v /= top;
    r.inverse[c] = std::move(t);
  }
  r.validate(kind);
  return r;
}

// The reference pixels the curve is recovered from: one per cell of a g × g grid, the flattest pixel
// of the cell (smallest green range in its 3 × 3 neighbourhood in the frame of middle exposure), as Debevec &
// Malik advise: edges carry misalignment, blur and JPEG's ringing and chroma subsampling.
std::vector<std::array<int, 2>> sample_pixels(const std::vector<Shifted>& fr, int w, int h, int samples) {
  // The flatness is judged in the frame of middle exposure.
  std::vector<int> order(fr.size());
  for (size_t j = 0; j < fr.size(); ++j) order[j] = static_cast<int>(j);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return fr[a].f->exposure < fr[b].f->exposure; });
  const int ref = order[order.size() / 2];
  const int g = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(samples)))));
  std::vector<std::array<int, 2>> px(static_cast<size_t>(g) * g, {-1, -1});
  parallel_for(0, g, [&](int64_t i) {
    for (int j = 0; j < g; ++j) {
      const int x0 = static_cast<int>(int64_t(j) * w / g), x1 = static_cast<int>(int64_t(j + 1) * w / g);
      const int y0 = static_cast<int>(int64_t(i) * h / g), y1 = static_cast<int>(int64_t(i + 1) * h / g);
      double best = 1e300;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          double r = 0;
          for (const Shifted& f : {fr[ref]}) {
            float lo = 2, hi = -2;
            for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
              for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u) {
                const float z = f.code(u, v, 1);
                if (z < 0) continue;
                lo = std::min(lo, z), hi = std::max(hi, z);
              }
            r += hi >= lo ? hi - lo : 1.0;
          }
          if (r < best) best = r, px[size_t(i) * g + j] = {x, y};
        }
    }
  });
  px.erase(std::remove_if(px.begin(), px.end(), [](const auto& p) { return p[0] < 0; }), px.end());
  return px;
}

// One Debevec solve; `snr`, when given (a first solve's ln curve), weights each row by the shot-noise
// SNR sqrt(exposure / max exposure) of its code value besides the hat (docs/capture.md).
std::vector<double> debevec_channel(const std::vector<Shifted>& fr, const std::vector<std::array<int, 2>>& px, int c,
                                    const RecoverDesc& d, const std::vector<double>* snr);

Response debevec(const std::vector<Shifted>& fr, int w, int h, const RecoverDesc& d) {
  const auto px = sample_pixels(fr, w, h, d.samples);
  std::array<std::vector<double>, 3> lng;
  for (int c = 0; c < 3; ++c) {
    const std::vector<double> first = debevec_channel(fr, px, c, d, nullptr);
    lng[c] = debevec_channel(fr, px, c, d, &first);
    lng[c][0] = -std::numeric_limits<double>::infinity();
  }
  return finish_curve("debevec", lng);
}

std::vector<double> debevec_channel(const std::vector<Shifted>& fr, const std::vector<std::array<int, 2>>& px, int c,
                                    const RecoverDesc& d, const std::vector<double>* snr) {
  const int B = d.bins, P = static_cast<int>(fr.size());
  {
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(B, B);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(B);
    int64_t rows = 0;
    double mass = 0;  // Σ w² over the data rows
    // One sample pixel: rows w_j (g(z_j) - e - ln Δ_j) = 0, e eliminated in closed form (Schur complement).
    std::vector<int> k0(P);
    std::vector<double> a(P), wj(P), lj(P);
    for (const auto& p : px) {
      double S = 0, cst = 0;
      int n = 0;
      for (int j = 0; j < P; ++j) {
        const double z = fr[j].code(p[0], p[1], c);
        wj[j] = z < 0 ? 0.0 : hat_weight(z);
        // A code no higher than a shorter exposure's is clipping noise (JPEG ringing in a saturated area).
        for (int q = 0; q < P && wj[j] > 0; ++q)
          if (fr[q].f->exposure < fr[j].f->exposure && fr[q].code(p[0], p[1], c) >= z) wj[j] = 0;
        if (snr && wj[j] > 0) {
          const double f = z * (B - 1);
          const int k = std::min(static_cast<int>(f), B - 2);
          const double lg = (*snr)[k] + (f - k) * ((*snr)[k + 1] - (*snr)[k]);
          wj[j] *= std::exp(0.5 * (lg - snr->back()));
        }
        if (wj[j] <= 0) continue;
        const double f = z * (B - 1);
        k0[j] = std::min(static_cast<int>(f), B - 2);
        a[j] = f - k0[j];
        lj[j] = std::log(fr[j].f->exposure);
        S += wj[j] * wj[j];
        cst += wj[j] * wj[j] * lj[j];
        ++n;
      }
      if (n < 2) continue;  // one trusted frame says nothing about the curve
      rows += n;
      mass += S;
      Eigen::VectorXd b = Eigen::VectorXd::Zero(B);
      for (int j = 0; j < P; ++j) {
        if (wj[j] <= 0) continue;
        const int k = k0[j];
        const double c0 = wj[j] * (1 - a[j]), c1 = wj[j] * a[j];
        M(k, k) += c0 * c0;
        M(k, k + 1) += c0 * c1;
        M(k + 1, k) += c0 * c1;
        M(k + 1, k + 1) += c1 * c1;
        rhs(k) += c0 * wj[j] * lj[j];
        rhs(k + 1) += c1 * wj[j] * lj[j];
        b(k) += wj[j] * c0;
        b(k + 1) += wj[j] * c1;
      }
      // - b bᵀ / S, + b cst / S: b has at most 2P non-zeros.
      std::vector<int> nz;
      for (int k = 0; k < B; ++k)
        if (b(k) != 0) nz.push_back(k);
      for (int u : nz) {
        for (int v : nz) M(u, v) -= b(u) * b(v) / S;
        rhs(u) -= b(u) * cst / S;
      }
    }
    if (rows == 0)
      fail(ErrorKind::Value,
           "{}: no pixel is trusted in two frames of the bracket, so the response cannot be recovered; shoot "
           "exposures closer together or give --response",
           fr[0].f->name);
    // Smoothness (docs/capture.md): λ w_s(k) · d²g/ds² at bin k, on the grid s = ln(code) rescaled to span
    // bins 1 … B−1, so that every power law (gamma curve) costs nothing and the ambiguity of a constant
    // exposure ratio (a wiggle periodic in ln exposure) does; λ² = κ · rows / B (data rows per bin), w_s the plain
    // triangle. Code 0 stays out of the system: its exposure is 0.
    const double lambda2 = d.smoothness * static_cast<double>(rows) / B;
    const double s1 = std::log(1.0 / (B - 1));
    auto sgrid = [&](int k) { return 1 + (std::log(static_cast<double>(k) / (B - 1)) - s1) / -s1 * (B - 2); };
    for (int k = 2; k < B - 1; ++k) {
      const double z = static_cast<double>(k) / (B - 1);
      const double ws = 1 - std::abs(2 * z - 1);
      const double h1 = sgrid(k) - sgrid(k - 1), h2 = sgrid(k + 1) - sgrid(k);
      const double co[3] = {2 / (h1 * (h1 + h2)), -2 / (h1 * h2), 2 / (h2 * (h1 + h2))};
      const double s = lambda2 * ws * ws * 0.5 * (h1 + h2);
      const int idx[3] = {k - 1, k, k + 1};
      for (int u = 0; u < 3; ++u)
        for (int v = 0; v < 3; ++v) M(idx[u], idx[v]) += s * co[u] * co[v];
    }
    M(0, 0) += 1;          // code 0: not solved (set to exposure 0 below)
    M(B / 2, B / 2) += 1;  // g(mid) = 0 fixes the free constant
    Eigen::VectorXd g = M.ldlt().solve(rhs);
    std::vector<double> out(g.data(), g.data() + B);
    out[0] = out[1] - 1;  // stands for code 0 in the next pass's weights; the curve sets it to exposure 0
    for (double v : out)
      if (!std::isfinite(v)) fail(ErrorKind::Internal, "Debevec solve gave a non-finite curve");
    return out;
  }
}

Response robertson(const std::vector<Shifted>& fr, int w, int h, const RecoverDesc& d) {
  const int B = d.bins, P = static_cast<int>(fr.size());
  // The iteration starts from Debevec's curve (docs/capture.md): on brackets of a near-constant exposure
  // ratio the fixed point is not unique, and from a straight line it lands far from the truth.
  const Response start = debevec(fr, w, h, d);
  // Every pixel of a grid of at most ~2^18 pixels.
  const int stride = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(w) * h / 262144.0))));
  std::vector<std::array<int, 2>> px;
  for (int y = stride / 2; y < h; y += stride)
    for (int x = stride / 2; x < w; x += stride) px.push_back({x, y});
  const int64_t N = static_cast<int64_t>(px.size());
  std::array<std::vector<double>, 3> lng;
  const double lo_bin = kBlackCode * (B - 1), hi_bin = kSaturatedCode * (B - 1);
  for (int c = 0; c < 3; ++c) {
    std::vector<int> bin(N * P);
    std::vector<float> wt(N * P);
    for (int64_t i = 0; i < N; ++i)
      for (int j = 0; j < P; ++j) {
        const double z = fr[j].code(px[i][0], px[i][1], c);
        bin[i * P + j] = z < 0 ? -1 : static_cast<int>(std::lround(z * (B - 1)));
        wt[i * P + j] = z < 0 ? 0.0f : static_cast<float>(hat_weight(z));
      }
    std::vector<double> g(B), E(N);
    for (int k = 0; k < B; ++k) g[k] = start.inverse[c][k] / start.inverse[c][B / 2];
    for (int iter = 0; iter < 100; ++iter) {
      for (int64_t i = 0; i < N; ++i) {
        double num = 0, den = 0;
        for (int j = 0; j < P; ++j) {
          const double wij = wt[i * P + j], t = fr[j].f->exposure;
          if (wij <= 0) continue;
          num += wij * t * g[bin[i * P + j]];
          den += wij * t * t;
        }
        E[i] = den > 0 ? num / den : -1;
      }
      std::vector<double> sum(B, 0.0);
      std::vector<int64_t> cnt(B, 0);
      for (int64_t i = 0; i < N; ++i) {
        if (E[i] < 0) continue;
        for (int j = 0; j < P; ++j) {
          const int k = bin[i * P + j];
          if (k < 0) continue;
          sum[k] += fr[j].f->exposure * E[i];
          ++cnt[k];
        }
      }
      std::vector<double> ng(B, -1.0);
      for (int k = 0; k < B; ++k)
        if (cnt[k] > 0 && k > lo_bin && k < hi_bin && sum[k] > 0) ng[k] = sum[k] / cnt[k];
      // Bins without data: interpolated (in log) between their neighbours; the untrusted ends: a line in
      // log fitted to the 8 nearest trusted bins.
      std::vector<int> have;
      for (int k = 0; k < B; ++k)
        if (ng[k] > 0) have.push_back(k);
      if (have.size() < 4)
        fail(ErrorKind::Value,
             "{}: too few code values are trusted across the bracket to recover the response; give --response",
             fr[0].f->name);
      std::vector<double> lg(B);
      for (size_t q = 0; q + 1 < have.size(); ++q)
        for (int k = have[q]; k <= have[q + 1]; ++k) {
          const double a = static_cast<double>(k - have[q]) / (have[q + 1] - have[q]);
          lg[k] = (1 - a) * std::log(ng[have[q]]) + a * std::log(ng[have[q + 1]]);
        }
      auto fit_end = [&](size_t from, size_t to, int k_lo, int k_hi) {
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        const double n = static_cast<double>(to - from);
        for (size_t q = from; q < to; ++q) {
          const double x = have[q], y = std::log(ng[have[q]]);
          sx += x, sy += y, sxx += x * x, sxy += x * y;
        }
        const double slope = (n * sxy - sx * sy) / std::max(1e-12, n * sxx - sx * sx), icpt = (sy - slope * sx) / n;
        for (int k = k_lo; k < k_hi; ++k) lg[k] = icpt + slope * k;
      };
      const size_t m = std::min<size_t>(8, have.size());
      fit_end(0, m, 0, have.front());
      fit_end(have.size() - m, have.size(), have.back() + 1, B);
      const double ref = lg[B / 2];
      double change = 0;
      for (int k = 0; k < B; ++k) {
        const double v = std::exp(lg[k] - ref);
        if (k > lo_bin && k < hi_bin) change = std::max(change, std::abs(v - g[k]) / v);
        g[k] = v;
      }
      if (change < 1e-5) break;
    }
    lng[c].resize(B);
    for (int k = 0; k < B; ++k) lng[c][k] = std::log(g[k]);
  }
  return finish_curve("robertson", lng);
}

// ---- Ward's median threshold bitmaps ----

struct Grey {
  int w = 0, h = 0;
  std::vector<float> v;
};

Grey grey_of(const Image& img) {
  Grey g{img.width(), img.height(), std::vector<float>(img.pixel_count())};
  for (size_t i = 0; i < g.v.size(); ++i) {
    const float* p = img.data() + 3 * i;
    g.v[i] = (54 * p[0] + 183 * p[1] + 19 * p[2]) / 256.0f;  // Ward's grey
  }
  return g;
}

Grey half(const Grey& g) {
  Grey o{std::max(1, g.w / 2), std::max(1, g.h / 2), {}};
  o.v.resize(static_cast<size_t>(o.w) * o.h);
  for (int y = 0; y < o.h; ++y)
    for (int x = 0; x < o.w; ++x) {
      const int x0 = std::min(2 * x, g.w - 1), x1 = std::min(2 * x + 1, g.w - 1);
      const int y0 = std::min(2 * y, g.h - 1), y1 = std::min(2 * y + 1, g.h - 1);
      o.v[size_t(y) * o.w + x] = 0.25f * (g.v[size_t(y0) * g.w + x0] + g.v[size_t(y0) * g.w + x1] +
                                          g.v[size_t(y1) * g.w + x0] + g.v[size_t(y1) * g.w + x1]);
    }
  return o;
}

struct Bitmaps {
  int w = 0, h = 0;
  std::vector<uint8_t> thr, excl;  // threshold bit, and 1 where the pixel is far enough from the threshold
};

// Ward's bitmaps at the threshold `t`: the median in [3], here the quantile both frames of a pair
// hold unsaturated (pair_quantile), which is the median when neither clips.
Bitmaps bitmaps(const Grey& g, float t) {
  constexpr float kExclusion = 4.0f / 255;  // Ward: ±4 of 255 around the threshold
  Bitmaps b{g.w, g.h, std::vector<uint8_t>(g.v.size()), std::vector<uint8_t>(g.v.size())};
  for (size_t i = 0; i < g.v.size(); ++i) {
    b.thr[i] = g.v[i] > t;
    b.excl[i] = std::abs(g.v[i] - t) > kExclusion;
  }
  return b;
}

float quantile(std::vector<float> v, double q) {
  auto it = v.begin() + static_cast<ptrdiff_t>(std::clamp(q, 0.0, 1.0) * (v.size() - 1));
  std::nth_element(v.begin(), it, v.end());
  return *it;
}

// The quantile between the fractions of pixels black and saturated in both frames: the median
// when both frames are unclipped there.
double pair_quantile(const Grey& a, const Grey& b) {
  auto frac = [](const Grey& g, bool sat) {
    int64_t n = 0;
    for (float v : g.v) n += sat ? v >= kSaturatedCode : v <= kBlackCode;
    return static_cast<double>(n) / g.v.size();
  };
  const double lo = std::max(frac(a, false), frac(b, false)), hi = 1 - std::max(frac(a, true), frac(b, true));
  return lo < 0.5 && hi > 0.5 ? 0.5 : 0.5 * (lo + hi);
}

int64_t mismatch(const Bitmaps& a, const Bitmaps& b, int dx, int dy) {
  int64_t n = 0;
  for (int y = std::max(0, -dy); y < std::min(a.h, b.h - dy); ++y) {
    const uint8_t* ta = &a.thr[size_t(y) * a.w];
    const uint8_t* ea = &a.excl[size_t(y) * a.w];
    const uint8_t* tb = &b.thr[size_t(y + dy) * b.w];
    const uint8_t* eb = &b.excl[size_t(y + dy) * b.w];
    for (int x = std::max(0, -dx); x < std::min(a.w, b.w - dx); ++x) n += (ta[x] ^ tb[x + dx]) & ea[x] & eb[x + dx];
  }
  return n;
}

// Ward's pyramid search of the shift of b relative to a. The pyramid only speeds the search up: a coarse level can
// land a step away from the truth where a bracket holds a few large flat areas (a chrome ball's dark room; seen: a
// 1,1 shift for frames shot on a tripod), and the finer levels cannot come back by more than one pixel each. So the
// search's answer is then checked at full resolution against the unshifted frame and its 8 neighbours: the smallest
// mismatch there wins (ties to the smaller shift).
std::array<int, 2> align_pair(const std::vector<Grey>& a, const std::vector<Grey>& b) {
  const int levels = static_cast<int>(a.size());
  const double q = pair_quantile(a[0], b[0]);
  int sx = 0, sy = 0;
  auto better = [](int64_t e, int x, int y, int64_t best, int bx, int by) {
    return e < best || (e == best && std::abs(x) + std::abs(y) < std::abs(bx) + std::abs(by));
  };
  for (int l = levels - 1; l >= 0; --l) {
    sx *= 2, sy *= 2;
    const Bitmaps ba = bitmaps(a[l], quantile(a[l].v, q)), bb = bitmaps(b[l], quantile(b[l].v, q));
    int64_t best = std::numeric_limits<int64_t>::max();
    int bx = sx, by = sy;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int64_t e = mismatch(ba, bb, sx + dx, sy + dy);
        if (better(e, sx + dx, sy + dy, best, bx, by)) best = e, bx = sx + dx, by = sy + dy;
      }
    if (l == 0)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int64_t e = mismatch(ba, bb, dx, dy);
          if (better(e, dx, dy, best, bx, by)) best = e, bx = dx, by = dy;
        }
    sx = bx, sy = by;
  }
  return {sx, sy};
}

}  // namespace

Response recover_debevec(const std::vector<Frame>& frames, const RecoverDesc& desc) {
  check_frames(frames);
  return debevec(shifted(frames, {}), frames[0].codes.width(), frames[0].codes.height(), desc);
}
Response recover_robertson(const std::vector<Frame>& frames, const RecoverDesc& desc) {
  check_frames(frames);
  return robertson(shifted(frames, {}), frames[0].codes.width(), frames[0].codes.height(), desc);
}

std::vector<std::array<int, 2>> align_mtb(const std::vector<Frame>& frames, int reference, int levels) {
  check_frames(frames);
  if (reference < 0 || reference >= static_cast<int>(frames.size()))
    fail(ErrorKind::Value, "alignment reference frame {} outside [0, {})", reference, frames.size());
  levels = std::clamp(levels, 1, 10);
  const int P = static_cast<int>(frames.size());
  std::vector<std::vector<Grey>> pyr(P);
  parallel_for(0, P, [&](int64_t j) {
    Grey g = grey_of(frames[j].codes);
    for (int l = 0; l < levels; ++l) {
      pyr[j].push_back(g);
      if (l + 1 < levels) g = half(g);
    }
  });
  // Frames far apart in exposure share few unclipped pixels: each frame is aligned to its neighbour
  // in exposure towards the reference, and the shifts add up along the chain.
  std::vector<int> order(P);
  for (int j = 0; j < P; ++j) order[j] = j;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return frames[a].exposure < frames[b].exposure; });
  const int rpos = static_cast<int>(std::find(order.begin(), order.end(), reference) - order.begin());
  std::vector<std::array<int, 2>> step(P, {0, 0});  // shift of order[i] relative to its neighbour towards the reference
  parallel_for(0, P, [&](int64_t i) {
    if (i == rpos) return;
    const int nb = order[i < rpos ? i + 1 : i - 1];
    step[i] = align_pair(pyr[nb], pyr[order[i]]);
  });
  std::vector<std::array<int, 2>> shifts(P, {0, 0});
  for (int i = rpos - 1; i >= 0; --i)
    shifts[order[i]] = {shifts[order[i + 1]][0] + step[i][0], shifts[order[i + 1]][1] + step[i][1]};
  for (int i = rpos + 1; i < P; ++i)
    shifts[order[i]] = {shifts[order[i - 1]][0] + step[i][0], shifts[order[i - 1]][1] + step[i][1]};
  return shifts;
}

Image merge_hdr(const std::vector<Frame>& frames, const MergeDesc& desc, MergeReport* report) {
  check_frames(frames);
  if (desc.method != "debevec" && desc.method != "robertson")
    fail(ErrorKind::Value, "response method '{}': use debevec or robertson", desc.method);
  if (!(std::isfinite(desc.scale) && desc.scale > 0)) fail(ErrorKind::Value, "--scale {} must be > 0", desc.scale);
  const int W = frames[0].codes.width(), H = frames[0].codes.height(), P = static_cast<int>(frames.size());
  MergeReport rep;
  rep.pixels = static_cast<int64_t>(W) * H;
  // The reference: the frame whose codes are nearest mid-grey on average (the middle of the bracket).
  {
    double best = 1e300;
    for (int j = 0; j < P; ++j) {
      double s = 0;
      const Image& c = frames[j].codes;
      for (size_t i = 0; i < c.size(); ++i) s += c.data()[i];
      const double d = std::abs(s / c.size() - 0.5);
      if (d < best) best = d, rep.reference = j;
    }
  }
  {
    // Every code value of every frame clipped: nothing to recover or merge.
    int64_t trusted = 0;
    for (const Frame& f : frames)
      for (size_t i = 0; i < f.codes.size() && trusted == 0; ++i) trusted += hat_weight(f.codes.data()[i]) > 0;
    if (trusted == 0) {
      int dark = 0, bright = 0;
      for (int j = 1; j < P; ++j) {
        if (frames[j].exposure < frames[dark].exposure) dark = j;
        if (frames[j].exposure > frames[bright].exposure) bright = j;
      }
      const Image& c = frames[dark].codes;
      double mean = 0;
      for (size_t i = 0; i < c.size(); ++i) mean += c.data()[i];
      if (mean / c.size() >= 0.5)
        fail(ErrorKind::Value,
             "{}: even the darkest photograph is saturated everywhere: no pixel is well exposed in any frame; add a "
             "shorter exposure",
             frames[dark].name);
      fail(ErrorKind::Value,
           "{}: even the brightest photograph is black everywhere: no pixel is well exposed in any frame; add a "
           "longer exposure",
           frames[bright].name);
    }
  }
  rep.shifts.assign(P, {0, 0});
  if (desc.align) rep.shifts = align_mtb(frames, rep.reference, desc.align_levels);
  const auto fr = shifted(frames, rep.shifts);
  if (desc.response) {
    rep.response = *desc.response;
    rep.response.validate("response");
  } else {
    rep.response = desc.method == "debevec" ? debevec(fr, W, H, desc.recover) : robertson(fr, W, H, desc.recover);
  }
  const Response& R = rep.response;

  Image out(W, H, 3);
  std::vector<uint8_t> flags(static_cast<size_t>(W) * H);  // 1 saturated everywhere, 2 black everywhere, 4 trusted
  parallel_for(
      0, H,
      [&](int64_t y64) {
        const int y = static_cast<int>(y64);
        std::vector<uint8_t> clipped(P);
        for (int x = 0; x < W; ++x) {
          uint8_t fl = 4;
          // A frame in which any channel of the pixel is saturated says nothing of its other channels either: a
          // camera clips them together (a JPEG's chroma and ringing pull a clipped highlight's other channels a few
          // codes below the top, where the hat would trust them from an exposure hundreds of times too long).
          for (int j = 0; j < P; ++j)
            clipped[j] = std::max({fr[j].code(x, y, 0), fr[j].code(x, y, 1), fr[j].code(x, y, 2)}) >= kSaturatedCode;
          for (int c = 0; c < 3; ++c) {
            double num = 0, den = 0;
            int dark = -1, bright = -1, mid = -1;
            double zdark = 0, zbright = 0, zmid = 0;
            for (int j = 0; j < P; ++j) {
              const double z = fr[j].code(x, y, c);
              if (z < 0) continue;
              const double t = frames[j].exposure, wt = clipped[j] ? 0.0 : hat_weight(z);
              num += wt * R.invert(z, c);
              den += wt * t;
              if (dark < 0 || t < frames[dark].exposure) dark = j, zdark = z;
              if (bright < 0 || t > frames[bright].exposure) bright = j, zbright = z;
              if (mid < 0 || std::abs(z - 0.5) < std::abs(zmid - 0.5)) mid = j, zmid = z;
            }
            double E;
            if (den > 0) {
              E = num / den;
            } else {
              fl &= ~4;
              if (dark < 0) {
                E = 0;  // no frame covers the pixel (unreachable: the reference frame has shift 0)
              } else if (zdark >= kSaturatedCode || clipped[dark]) {
                E = R.invert(zdark, c) / frames[dark].exposure, fl |= 1;  // the darkest exposure's bound
              } else if (zbright <= kBlackCode) {
                E = R.invert(zbright, c) / frames[bright].exposure, fl |= 2;  // the brightest exposure's bound
              } else {
                E = R.invert(zmid, c) / frames[mid].exposure;
              }
            }
            out.pixel(x, y)[c] = static_cast<float>(std::min<double>(E, std::numeric_limits<float>::max()));
          }
          flags[size_t(y) * W + x] = fl;
        }
      },
      4);
  for (uint8_t f : flags) {
    rep.saturated_everywhere += (f & 1) != 0;
    rep.black_everywhere += (f & 2) != 0;
    rep.well_exposed += (f & 4) != 0;
  }
  if (rep.well_exposed == 0) {
    int dark = 0, bright = 0;
    for (int j = 1; j < P; ++j) {
      if (frames[j].exposure < frames[dark].exposure) dark = j;
      if (frames[j].exposure > frames[bright].exposure) bright = j;
    }
    if (rep.saturated_everywhere >= rep.black_everywhere)
      fail(ErrorKind::Value,
           "{}: even the darkest photograph is saturated everywhere: no pixel is well exposed in any frame; add a "
           "shorter exposure",
           frames[dark].name);
    fail(ErrorKind::Value,
         "{}: even the brightest photograph is black everywhere: no pixel is well exposed in any frame; add a longer "
         "exposure",
         frames[bright].name);
  }

  // Absolute scale.
  Vec3 gains{1, 1, 1};
  if (desc.grey_card) {
    const auto [x0, y0, w, h] = *desc.grey_card;
    if (w <= 0 || h <= 0 || x0 < 0 || y0 < 0 || x0 + int64_t(w) > W || y0 + int64_t(h) > H)
      fail(ErrorKind::Value, "--grey-card {},{},{},{} is not a rectangle inside the {}x{} photograph", x0, y0, w, h, W,
           H);
    if (!(desc.reflectance > 0 && desc.reflectance <= 1))
      fail(ErrorKind::Value, "--reflectance {} must lie in (0, 1]", desc.reflectance);
    Vec3 m{0, 0, 0};
    int64_t bad = 0;
    for (int y = y0; y < y0 + h; ++y)
      for (int x = x0; x < x0 + w; ++x) {
        for (int c = 0; c < 3; ++c) m[c] += out.pixel(x, y)[c];
        bad += (flags[size_t(y) * W + x] & 4) == 0;
      }
    if (bad * 2 > int64_t(w) * h)
      fail(ErrorKind::Value, "--grey-card {},{},{},{}: most of the card is saturated or black in every frame", x0, y0,
           w, h);
    for (int c = 0; c < 3; ++c) {
      m[c] /= double(w) * h;
      if (!(m[c] > 0)) fail(ErrorKind::Value, "--grey-card {},{},{},{} is black in channel {}", x0, y0, w, h, "RGB"[c]);
      gains[c] = desc.reflectance / m[c];
    }
  }
  for (int c = 0; c < 3; ++c) gains[c] *= desc.scale;
  rep.gains = gains;
  if (gains.x != 1 || gains.y != 1 || gains.z != 1)
    for (size_t i = 0; i < out.pixel_count(); ++i)
      for (int c = 0; c < 3; ++c) {
        float& v = out.data()[3 * i + c];
        v = static_cast<float>(std::min<double>(v * gains[c], std::numeric_limits<float>::max()));
      }

  // Dynamic range over the trusted pixels' luminance, and the noise estimate.
  std::vector<float> lum;
  lum.reserve(rep.well_exposed);
  for (size_t i = 0; i < out.pixel_count(); ++i)
    if (flags[i] & 4) {
      const float* p = out.data() + 3 * i;
      lum.push_back(0.2125f * p[0] + 0.7154f * p[1] + 0.0721f * p[2]);
    }
  auto pct = [&](double q) {
    auto it = lum.begin() + static_cast<ptrdiff_t>(q * (lum.size() - 1));
    std::nth_element(lum.begin(), it, lum.end());
    return static_cast<double>(*it);
  };
  rep.min_luminance = pct(0.001);
  rep.max_luminance = pct(0.999);
  rep.dynamic_range_stops = rep.min_luminance > 0 ? std::log2(rep.max_luminance / rep.min_luminance) : 0;
  std::vector<float> dev;
  constexpr double kNoiseWeight = 0.25;  // frames this far inside the trusted range, at least two of them
  for (int y = 0; y < H; y += 2)
    for (int x = 0; x < W; x += 2) {
      const double E = out.pixel(x, y)[1] / gains[1];
      if (!(E > 0)) continue;
      int n = 0;
      double s = 0;
      for (int j = 0; j < P; ++j) {
        const double z = fr[j].code(x, y, 1);
        if (z < 0 || hat_weight(z) < kNoiseWeight) continue;
        s += std::abs(R.invert(z, 1) / frames[j].exposure - E) / E;
        ++n;
      }
      if (n >= 2) dev.push_back(static_cast<float>(s / n));
    }
  if (!dev.empty()) {
    std::nth_element(dev.begin(), dev.begin() + dev.size() / 2, dev.end());
    rep.noise = dev[dev.size() / 2];
  }
  if (report) *report = std::move(rep);
  return out;
}

}  // namespace ibl::capture
