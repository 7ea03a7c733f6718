#include "iblkit/ilf/crossval.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/core/rng.h"
#include "iblkit/ilf/build.h"

namespace ibl::ilf {

namespace {
// Streams of iblkit's RNG (core/rng.h), so that the folds are the same on every standard library.
constexpr uint64_t kFoldStream = 0x666f6c64;       // "fold": the probes' fold assignment
constexpr uint64_t kEvaluatedStream = 0x6576616c;  // "eval": the probes the error is evaluated at
}  // namespace

std::vector<uint8_t> assign_folds(int n, int folds, uint64_t seed) {
  if (folds < 2 || folds > 255) fail(ErrorKind::Value, "cross-validation: {} folds outside [2, 255]", folds);
  std::vector<int> perm(size_t(std::max(n, 0)));
  for (int i = 0; i < n; ++i) perm[i] = i;
  Rng rng(stream_key(seed, kFoldStream));
  shuffle(perm.begin(), perm.end(), rng);
  std::vector<uint8_t> fold(perm.size());
  for (int i = 0; i < n; ++i) fold[perm[i]] = uint8_t(i % folds);
  return fold;
}

CrossValidator::CrossValidator(const GridDesc& grid, const std::vector<Vec3>& origins,
                               const std::vector<uint8_t>& valid, int bands, const CrossValDesc& desc)
    : grid_(grid), desc_(desc), K_(bands * bands) {
  int P = int(origins.size());
  fold_ = assign_folds(P, desc.folds, desc.seed);
  std::vector<int> ids;
  for (int p = 0; p < P; ++p)
    if (valid.empty() || valid[p]) ids.push_back(p);
  if (int(ids.size()) > desc.max_evaluated) {
    Rng rng(stream_key(desc.seed, kEvaluatedStream));
    shuffle(ids.begin(), ids.end(), rng);
    ids.resize(size_t(std::max(desc.max_evaluated, 1)));
    std::sort(ids.begin(), ids.end());
  }
  eval_ = ids;
  E_ = int(ids.size());
  cell_.assign(size_t(P) * 3, 0);
  frac_.assign(size_t(P) * 3, 0.0f);
  Vec3 s = grid.volume.size();
  int n[3] = {grid.nx, grid.ny, grid.nz};
  for (int p = 0; p < P; ++p) {
    Vec3 x = origins[p];
    for (int a = 0; a < 3; ++a) {  // as SHGrid::coeffs_at
      double f = std::clamp((x[a] - grid.volume.min[a]) / s[a] * (n[a] - 1), 0.0, double(n[a] - 1));
      int i0 = std::min(int(f), n[a] - 2);
      cell_[3 * p + a] = i0;
      frac_[3 * p + a] = float(f - i0);
    }
  }
  for (int p : eval_) pos_.push_back(origins[p]);
  C_.assign(size_t(2) * 3 * E_ * K_, 0.0);
}

void CrossValidator::begin_block(int D) {
  // Columns are per probe (all probes: project_bucket indexes by probe); rows of the evaluated subset
  // are gathered in end_block.
  size_t P = fold_.size();
  pred_.assign(size_t(3) * P * D, 0.0f);
  own_.assign(size_t(3) * P * D, 0.0f);
}

CvBucket CrossValidator::bucket(int j) {
  CvBucket b;
  int64_t P = int64_t(fold_.size());
  b.n_folds = desc_.folds;
  b.fold = fold_.data();
  b.cell = cell_.data();
  b.frac = frac_.data();
  b.stride = P;
  b.pred = pred_.data() + size_t(j) * 3 * P;
  b.own = own_.data() + size_t(j) * 3 * P;
  return b;
}

void CrossValidator::end_block(const float* B, int D) {
  size_t P = fold_.size();
  // Gather the evaluated rows: R(c·E + e, j) from column j's pred[c·P + p].
  std::vector<float> Rp(size_t(3) * E_ * D), Ro(size_t(3) * E_ * D);
  for (int j = 0; j < D; ++j)
    for (int c = 0; c < 3; ++c)
      for (int e = 0; e < E_; ++e) {
        Rp[size_t(j) * 3 * E_ + size_t(c) * E_ + e] = pred_[size_t(j) * 3 * P + c * P + eval_[e]];
        Ro[size_t(j) * 3 * E_ + size_t(c) * E_ + e] = own_[size_t(j) * 3 * P + c * P + eval_[e]];
      }
  accumulate_block(Rp.data(), int64_t(3) * E_, D, B, K_, C_.data());
  accumulate_block(Ro.data(), int64_t(3) * E_, D, B, K_, C_.data() + size_t(3) * E_ * K_);
}

CrossValResult CrossValidator::result() const {
  CrossValResult r;
  r.folds = desc_.folds;
  r.evaluated = E_;
  r.positions = pos_;
  r.sq_error.assign(size_t(E_), 0.0);
  r.sq_norm.assign(size_t(E_), 0.0);
  int64_t rows = int64_t(3) * E_;
  const double* Cpred = C_.data();
  const double* Cown = C_.data() + size_t(rows) * K_;
  double num = 0, den = 0;
  std::vector<double> rel;
  for (int e = 0; e < E_; ++e) {
    double a = 0, b = 0;
    for (int k = 0; k < K_; ++k)
      for (int c = 0; c < 3; ++c) {
        size_t i = size_t(k) * rows + size_t(c) * E_ + e;
        double d = Cpred[i] - Cown[i];
        a += d * d;
        b += Cown[i] * Cown[i];
      }
    r.sq_error[e] = a;
    r.sq_norm[e] = b;
    num += a;
    den += b;
    if (b > 0) rel.push_back(std::sqrt(a / b));
  }
  r.rel_error = den > 0 ? std::sqrt(num / den) : 0.0;
  if (!rel.empty()) {
    std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
    r.median_probe_error = rel[rel.size() / 2];
  }
  int R = std::max(desc_.regions, 1);
  r.regions = R;
  std::vector<double> rn(size_t(R) * R * R, 0.0), rd(rn.size(), 0.0);
  r.region_probes.assign(rn.size(), 0);
  Vec3 s = grid_.volume.size();
  for (int e = 0; e < E_; ++e) {
    int idx[3];
    for (int a = 0; a < 3; ++a) idx[a] = std::clamp(int((pos_[e][a] - grid_.volume.min[a]) / s[a] * R), 0, R - 1);
    size_t i = (size_t(idx[2]) * R + idx[1]) * R + idx[0];
    rn[i] += r.sq_error[e];
    rd[i] += r.sq_norm[e];
    ++r.region_probes[i];
  }
  r.region_error.resize(rn.size());
  for (size_t i = 0; i < rn.size(); ++i)
    r.region_error[i] = rd[i] > 0 ? std::sqrt(rn[i] / rd[i]) : std::numeric_limits<double>::quiet_NaN();
  return r;
}

double focus_sigma(const Focus& f, const Box& volume, int probes) {
  Vec3 s = volume.size();
  return std::max(f.radius, std::cbrt(s.x * s.y * s.z / std::max(probes, 1)));
}

namespace {
// Σ k·e², Σ k·‖C‖², Σ k over the probes within 3σ of x, k = exp(−d²/2σ²): the error around a point.
struct WeightedError {
  double we = 0, wn = 0, w = 0;
};
WeightedError weighted_error(const CrossValResult& r, Vec3 x, double sigma) {
  double inv2s2 = 1 / (2 * sigma * sigma), cut2 = 9 * sigma * sigma;
  WeightedError s;
  for (size_t p = 0; p < r.positions.size(); ++p) {
    Vec3 d = r.positions[p] - x;
    double d2 = dot(d, d);
    if (!(d2 <= cut2)) continue;
    double k = std::exp(-d2 * inv2s2);
    s.we += k * r.sq_error[p];
    s.wn += k * r.sq_norm[p];
    s.w += k;
  }
  return s;
}
}  // namespace

double focus_error(const CrossValResult& r, const Focus& f, const Box& volume, double* weight) {
  WeightedError s = weighted_error(r, f.centre, focus_sigma(f, volume, int(r.positions.size())));
  if (weight) *weight = s.w;
  return s.wn > 0 ? std::sqrt(s.we / s.wn) : std::numeric_limits<double>::quiet_NaN();
}

SHGrid error_volume(const CrossValResult& r, const GridDesc& grid, int max_res) {
  GridDesc g{std::clamp(grid.nx, 2, max_res), std::clamp(grid.ny, 2, max_res), std::clamp(grid.nz, 2, max_res),
             grid.volume};
  SHGrid out(g, 1);
  out.set_content("cv-error");
  Vec3 s = grid.volume.size(), sp = g.spacing();
  int P = int(r.positions.size());
  double sigma = std::max({std::cbrt(s.x * s.y * s.z / std::max(P, 1)), sp.x, sp.y, sp.z});
  parallel_for(
      0, g.count(),
      [&](int64_t i) {
        auto [we, wn, w] = weighted_error(r, g.point(i), sigma);
        float* v = out.data().data() + size_t(i) * 3;
        v[0] = wn > 0 ? float(std::sqrt(we / wn)) : 0.0f;
        v[1] = w > 0 ? float(std::sqrt(we / w)) : 0.0f;
        v[2] = float(w);
      },
      64);
  return out;
}

Image error_slice(const SHGrid& g, int axis, double value, int size) {
  if (axis < 0 || axis > 2 || size < 1 || size > 16384)
    fail(ErrorKind::Value, "error slice: axis {} must be 0..2 and the width {} 1..16384 pixels", axis, size);
  if (g.content() != "cv-error")
    fail(ErrorKind::Value, "error slice: the grid holds \"{}\", not cv-error", g.content());
  const auto& v = g.grid().volume;
  int a1 = axis == 0 ? 2 : 0, a2 = axis == 1 ? 2 : 1;
  Vec3 ext = v.size();
  int w = size, h = int(std::clamp(std::lround(size * ext[a2] / ext[a1]), 1L, 16384L));
  Image img(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3 p;
      p[axis] = value;
      p[a1] = v.min[a1] + ext[a1] * (x + 0.5) / w;
      p[a2] = v.max[a2] - ext[a2] * (y + 0.5) / h;
      img.set_rgb(x, y, g.coeffs_at(p).c[0]);
    }
  return img;
}

Image error_colours(const Image& e, double max_error) {
  if (!(max_error > 0) || !std::isfinite(max_error))
    fail(ErrorKind::Value, "error colours: max_error {} must be > 0", max_error);
  static const Vec3 stops[] = {{0, 0, 0}, {0.1, 0.2, 0.9}, {0.1, 0.8, 0.3}, {0.95, 0.9, 0.1}, {0.9, 0.1, 0.1}};
  Image img(e.width(), e.height(), 3);
  const double grey = std::pow(0.45, 2.2);
  for (int y = 0; y < e.height(); ++y)
    for (int x = 0; x < e.width(); ++x) {
      if (e.channels() >= 3 && e.at(x, y, 2) < kErrorMinWeight) {  // no probe near enough: no figure, not "no error"
        img.set_rgb(x, y, {grey, grey, grey});
        continue;
      }
      double t = std::clamp(e.rgb(x, y).x / max_error, 0.0, 1.0) * 4;
      int i = std::min(int(t), 3);
      double f = t - i;
      Vec3 c = stops[i] * (1 - f) + stops[i + 1] * f;
      img.set_rgb(x, y, {std::pow(c.x, 2.2), std::pow(c.y, 2.2), std::pow(c.z, 2.2)});  // linear for the sRGB writer
    }
  return img;
}

double build_grid_bytes(int nx, int ny, int nz, int bands, int block_buckets) {
  double G = double(nx) * ny * nz, K = double(bands) * bands;
  return G * K * 3 * 4 * 2 + G * 3 * block_buckets * 4;
}

BucketRays bucket_rays(const BucketStore& store, const std::vector<uint16_t>& buf, int k, int b,
                       const std::vector<Vec3>& origins, bool use_starts, BucketRadiance& rad) {
  const DirectionTable& t = store.table();
  int P = store.probe_count();
  int nb = int(t.bucket_begin[b + 1] - t.bucket_begin[b]);
  rad.rgb.resize(size_t(P) * nb * 3);
  rad.stride = int64_t(nb) * 3;
  for (int p = 0; p < P; ++p)
    halves_to_floats(store.samples(buf, k, b, p), rad.rgb.data() + size_t(p) * nb * 3, size_t(nb) * 3);
  BucketRays rays;
  rays.dirs = t.dir.data() + t.bucket_begin[b] * 3;
  rays.weights = t.weight.data() + t.bucket_begin[b];
  if (use_starts && !t.start.empty()) rays.starts = t.start.data() + t.bucket_begin[b] * 3;
  rays.n_dirs = nb;
  rays.origins = origins.data();
  rays.valid = store.valid().data();
  rays.n_probes = P;
  rays.ctx = &rad;
  rays.radiance = [](const void* c, int p) {
    auto* x = static_cast<const BucketRadiance*>(c);
    return x->rgb.data() + p * x->stride;
  };
  return rays;
}

namespace {

// One candidate of the search.
struct Candidate {
  GridDesc grid;
  ProjectDesc project;
  std::unique_ptr<CrossValidator> cv;
};

GridDesc grid_of(const ResampleSearch& s, int n) {
  // n points along the longest axis, the others in proportion to the volume (≥ 2).
  Vec3 e = s.volume.size();
  double m = std::max({e.x, e.y, e.z});
  auto along = [&](double len) { return std::max(2, int(std::lround((n - 1) * len / m)) + 1); };
  return {along(e.x), along(e.y), along(e.z), s.volume};
}

// Buckets the sampling takes: every stride-th by global index, at most max_buckets (all when fewer).
int sample_stride(const DirectionTable& t, int max_buckets) {
  return std::max(1, (t.buckets() + max_buckets - 1) / std::max(max_buckets, 1));
}

// Cross-validated errors of the candidates on every stride-th bucket (one read of the block files),
// over this process's share of the blocks; then the partial sums of every process are added, so the
// candidates' result() is the job's. *used: the buckets the whole job evaluates.
void evaluate(const BucketStore& store, const std::vector<Vec3>& origins, std::vector<Candidate>& cands, int bands,
              int stride, bool use_starts, int* used, const CvShare& share) {
  const DirectionTable& t = store.table();
  *used = 0;
  for (int b = 0; b < t.buckets(); b += stride) ++*used;
  auto local = [&] {
    std::vector<uint16_t> buf;
    tbb::enumerable_thread_specific<ProjectScratch> scratch;
    tbb::enumerable_thread_specific<BucketRadiance> rads;
    int K = bands * bands;
    int k0 = std::max(share.block_begin, 0), k1 = std::min(share.block_end, t.blocks());
    for (int k = k0; k < k1; ++k) {
      std::vector<int> sel;
      for (int b = t.block_begin[k]; b < t.block_begin[k + 1]; ++b)
        if (b % stride == 0) sel.push_back(b);
      if (sel.empty()) continue;
      store.load_block(k, buf);
      int D = int(sel.size());
      for (auto& c : cands) c.cv->begin_block(D);
      parallel_for(0, D, [&](int64_t j) {
        BucketRays rays = bucket_rays(store, buf, k, sel[j], origins, use_starts, rads.local());
        for (auto& c : cands) {
          CvBucket cb = c.cv->bucket(int(j));
          project_bucket(c.grid, rays, c.project, nullptr, 0, scratch.local(), &cb);
        }
      });
      std::vector<float> B(size_t(D) * K);
      for (int j = 0; j < D; ++j) {
        auto row = bucket_basis(t, sel[j], sel[j] + 1, bands);
        for (int kk = 0; kk < K; ++kk) B[size_t(kk) * D + j] = row[kk];
      }
      for (auto& c : cands) c.cv->end_block(B.data(), D);
    }
  };
  if (share.agree)
    share.agree(local);
  else
    local();
  if (share.sum)
    for (auto& c : cands) {
      auto& C = c.cv->partial_sums();
      share.sum(C.data(), C.size());
    }
}

}  // namespace

CrossValResult cross_validate(const BucketStore& store, const std::vector<Vec3>& origins, const GridDesc& grid,
                              const ProjectDesc& project, int bands, const CrossValDesc& cv, int max_buckets,
                              bool use_starts, int* buckets_used, const CvShare& share) {
  int stride = sample_stride(store.table(), max_buckets);
  std::vector<Candidate> c(1);
  c[0].grid = grid;
  c[0].project = project;
  c[0].cv = std::make_unique<CrossValidator>(grid, origins, store.valid(), bands, cv);
  int used = 0;
  evaluate(store, origins, c, bands, stride, use_starts, &used, share);
  if (buckets_used) *buckets_used = used;
  return c[0].cv->result();
}

ResampleChoice choose_resampling(const BucketStore& store, const std::vector<Vec3>& origins, const ProjectDesc& project,
                                 const ResampleSearch& s, const CrossValDesc& cvd, bool use_starts,
                                 const CvShare& share) {
  auto t0 = std::chrono::steady_clock::now();
  ResampleChoice ch;
  int stride = sample_stride(store.table(), s.max_buckets);
  CrossValDesc cv = cvd;
  if (cv.folds < 2) cv.folds = 5;
  // A trial's score: the whole volume's error, or with a focus the error around it.
  auto score = [&](const ResampleTrial& t) { return s.focus ? t.focus_error : t.cv_error; };
  auto run = [&](const std::vector<std::pair<int, double>>& pairs) {  // (n, kernel); n 0 = the given resolution
    std::vector<Candidate> cands;
    for (auto [n, kern] : pairs) {
      Candidate c;
      c.grid = n > 0 ? grid_of(s, n) : GridDesc{s.nx, s.ny, s.nz, s.volume};
      c.project = project;
      c.project.kernel_cells = kern;
      c.cv = std::make_unique<CrossValidator>(c.grid, origins, store.valid(), s.bands, cv);
      cands.push_back(std::move(c));
    }
    evaluate(store, origins, cands, s.bands, stride, use_starts, &ch.buckets_used, share);
    for (size_t i = 0; i < cands.size(); ++i) {
      CrossValResult r = cands[i].cv->result();
      ResampleTrial t{std::max({cands[i].grid.nx, cands[i].grid.ny, cands[i].grid.nz}), pairs[i].second, r.rel_error,
                      std::numeric_limits<double>::quiet_NaN()};
      double w = 0;
      if (s.focus) {
        t.focus_error = focus_error(r, *s.focus, s.volume, &w);
        if (!std::isfinite(t.focus_error))
          fail(ErrorKind::Value,
               "--focus {},{},{}: no probe of the sequence lies within {:.3g} m of it (3σ); give a point inside the "
               "captured volume or a larger radius",
               s.focus->centre.x, s.focus->centre.y, s.focus->centre.z,
               3 * focus_sigma(*s.focus, s.volume, r.evaluated));
      }
      bool better = ch.trials.empty() || score(t) < score(ch.trials[ch.chosen]);
      ch.trials.push_back(t);
      if (better) {
        ch.chosen = ch.trials.size() - 1;
        ch.best = std::move(r);
        ch.focus_weight = w;
      }
    }
  };
  auto best = [&](size_t from, bool by_focus) {
    size_t b = from;
    for (size_t i = from; i < ch.trials.size(); ++i)
      if ((by_focus ? ch.trials[i].focus_error : ch.trials[i].cv_error) <
          (by_focus ? ch.trials[b].focus_error : ch.trials[b].cv_error))
        b = i;
    return ch.trials[b];
  };
  std::vector<std::pair<int, double>> pairs;
  if (s.grid) {
    std::vector<int> ns;
    for (int n : kAutoGrids) {
      GridDesc g = grid_of(s, n);
      if (build_grid_bytes(g.nx, g.ny, g.nz, s.bands, 64) <= 0.5 * double(s.memory_bytes)) ns.push_back(n);
    }
    if (ns.empty())
      fail(ErrorKind::Value, "--grid auto: not even an {}-point grid fits in half of the memory budget", kAutoGrids[0]);
    // Each resolution with two kernels, then the best resolution with every kernel.
    for (int n : ns)
      for (double kern : s.kernel ? std::vector<double>{2.0, 3.0} : std::vector<double>{s.kernel_cells})
        pairs.push_back({n, kern});
    run(pairs);
    ResampleTrial b = best(0, bool(s.focus));
    if (s.kernel) {
      pairs.clear();
      for (double kern : kAutoKernels)
        if (kern != 2.0 && kern != 3.0) pairs.push_back({b.n, kern});
      run(pairs);
    }
  } else {
    for (double kern : kAutoKernels) pairs.push_back({0, kern});
    run(pairs);
  }
  const ResampleTrial& w = ch.trials[ch.chosen];
  GridDesc g = s.grid ? grid_of(s, w.n) : GridDesc{s.nx, s.ny, s.nz, s.volume};
  ch.nx = g.nx;
  ch.ny = g.ny;
  ch.nz = g.nz;
  ch.kernel = w.kernel;
  ResampleTrial v = best(0, false);  // the whole volume's choice among the trials run
  ch.volume_kernel = v.kernel;
  ch.volume_n = v.n;
  if (s.focus) {
    ch.focus = s.focus;
    ch.focus_sigma = focus_sigma(*s.focus, s.volume, ch.best.evaluated);
  }
  ch.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return ch;
}

}  // namespace ibl::ilf
