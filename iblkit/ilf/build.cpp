#include "iblkit/ilf/build.h"

#include <tbb/enumerable_thread_specific.h>
#include <Eigen/Core>

#include <atomic>
#include <chrono>
#include <mutex>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/ilf/collective.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sh/basis.h"

namespace ibl::ilf {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

double accumulate_block(const float* R, int64_t rows, int D, const float* B, int K, double* C) {
  using MatF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor>;
  using MatD = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor>;
  Eigen::Map<const MatF, 0, Eigen::OuterStride<>> Rm(R, rows, D, Eigen::OuterStride<>(rows));
  Eigen::Map<const MatF> Bm(B, D, K);
  Eigen::Map<MatD, 0, Eigen::OuterStride<>> Cm(C, rows, K, Eigen::OuterStride<>(rows));
  constexpr int64_t kChunk = 2048;  // rows per task: (2048 × D + 2048 × K) floats stay in L2
  parallel_for(0, (rows + kChunk - 1) / kChunk, [&](int64_t c) {
    int64_t r0 = c * kChunk, n = std::min(kChunk, rows - r0);
    // The block's product in float (the GEMM), its sum over blocks in double: every block's product is
    // the same bits whichever process makes it, and a sum in double does not depend on the order of
    // the blocks to float precision, so a distributed build equals the serial one (docs/ilf.md).
    MatF P = Rm.middleRows(r0, n) * Bm;
    Cm.middleRows(r0, n) += P.cast<double>();
  });
  return 2.0 * double(rows) * D * K;
}

std::vector<float> bucket_basis(const DirectionTable& t, int b0, int b1, int bands) {
  int K = bands * bands, D = b1 - b0;
  std::vector<float> B(size_t(D) * K, 0.0f);
  std::vector<double> y(static_cast<size_t>(K));
  for (int j = 0; j < D; ++j) {
    std::vector<double> acc(size_t(K), 0.0);
    for (int64_t s = t.bucket_begin[b0 + j]; s < t.bucket_begin[b0 + j + 1]; ++s) {
      Vec3 d{t.dir[3 * s], t.dir[3 * s + 1], t.dir[3 * s + 2]};
      sh::eval_basis(bands, normalize(d), y.data());
      for (int k = 0; k < K; ++k) acc[k] += t.weight[s] * y[k];
    }
    for (int k = 0; k < K; ++k) B[size_t(k) * D + j] = float(acc[k]);
  }
  return B;
}

GridDesc build_grid(const Sequence& seq, const BuildDesc& desc) {
  if (desc.bands < kMinBuildBands || desc.bands > kMaxBuildBands)
    fail(ErrorKind::Value, "bands {} outside [{}, {}]", desc.bands, kMinBuildBands, kMaxBuildBands);
  if (!(desc.project.kernel_cells > 0))
    fail(ErrorKind::Value, "kernel_cells {} must be > 0 (the kernel's support in grid cells)",
         desc.project.kernel_cells);
  if (!std::isfinite(desc.project.kernel_cells))
    fail(ErrorKind::Value, "kernel_cells {} must be a finite number of grid cells", desc.project.kernel_cells);
  GridDesc grid{desc.nx, desc.ny, desc.nz, desc.volume ? *desc.volume : seq.volume};
  SHGrid check(grid, 1);  // validates resolution and volume
  if (desc.focus) {
    const Focus& f = *desc.focus;
    if (!desc.auto_kernel && !desc.auto_grid)
      fail(ErrorKind::Value, "focus: it chooses the kernel or the grid for a neighbourhood; ask for one (kernel auto)");
    if (!std::isfinite(f.centre.x) || !std::isfinite(f.centre.y) || !std::isfinite(f.centre.z) ||
        !std::isfinite(f.radius) || f.radius < 0)
      fail(ErrorKind::Value, "focus {},{},{} radius {}: a finite point and a radius ≥ 0 (m)", f.centre.x, f.centre.y,
           f.centre.z, f.radius);
  }
  {  // project_bucket's raster per thread: the projected volume plus the kernel's support, at Δ = raster_cells·h
    Vec3 sp = grid.spacing();
    double h = std::max({sp.x, sp.y, sp.z}), R = desc.project.kernel_cells * h / 2,
           delta = std::max(desc.project.raster_cells, 0.05) * h;
    double side = (length(grid.volume.size()) + 2 * (R + delta)) / delta + 1;
    require_allocation(fmt::format("a kernel of {:g} grid cells (kernel_cells)", desc.project.kernel_cells),
                       side * side, 16, "choose a smaller kernel_cells");
  }
  return grid;
}

BucketDesc resolve_directions(const Sequence& seq, const BuildDesc& desc) {
  BucketDesc bd = desc.buckets;
  if (bd.octahedral < 0) {
    // Auto: pixel buckets for small frames, else octahedral cells (see docs/ilf.md for the trade-off).
    int64_t pixels = 0;
    for (const auto& p : seq.probes) {
      try {
        auto spec = io::read_image_spec(p.image);
        pixels = int64_t(spec.width) * spec.height;
        break;
      } catch (const Error&) {
        if (!bd.skip_bad) throw;
      }
    }
    bd.octahedral = pixels > desc.auto_pixel_buckets ? desc.auto_octahedral : 0;
  }
  return bd;
}

BlockStats project_block(const BucketStore& store, int k, const std::vector<uint16_t>& buf, const GridDesc& grid,
                         const ProjectDesc& desc, const std::vector<Vec3>& origins, float* R, BlockScratch& scratch,
                         bool ball_parallax) {
  const DirectionTable& t = store.table();
  int64_t G = grid.count(), rows = 3 * G;
  int b0 = t.block_begin[k], b1 = t.block_begin[k + 1], D = b1 - b0;
  std::atomic<int64_t> rays_n{0}, uncovered{0};
  std::mutex mu;
  BlockStats bs;
  parallel_for(0, D, [&](int64_t j) {
    auto tb = Clock::now();
    BucketRadiance rad;
    BucketRays rays = bucket_rays(store, buf, k, b0 + int(j), origins, ball_parallax, rad);
    auto st = project_bucket(grid, rays, desc, R + size_t(j) * rows, G, scratch.local());
    rays_n += st.rays;
    uncovered += st.uncovered;
    double busy = since(tb);
    std::lock_guard lk(mu);
    bs.repair_seconds += st.repair_seconds;
    bs.busy_seconds += busy;
  });
  bs.rays = rays_n;
  bs.uncovered = uncovered;
  return bs;
}

BlockWork resample_block(const BucketStore& store, int k, const GridDesc& grid, const ProjectDesc& desc,
                         const std::vector<Vec3>& origins, int bands, bool ball_parallax, std::vector<uint16_t>& buf,
                         std::vector<float>& R, BlockScratch& scratch, double* C) {
  const DirectionTable& t = store.table();
  int64_t rows = 3 * grid.count();
  int K = bands * bands;
  BlockWork w;
  auto tp = Clock::now();
  store.load_block(k, buf);
  int b0 = t.block_begin[k], b1 = t.block_begin[k + 1], D = b1 - b0;
  R.resize(size_t(rows) * D);  // no clearing: project_bucket writes every (point, channel) of its column
  w.stats = project_block(store, k, buf, grid, desc, origins, R.data(), scratch, ball_parallax);
  w.project_seconds = since(tp);
  auto ta = Clock::now();
  auto B = bucket_basis(t, b0, b1, bands);
  w.gemm_flops = accumulate_block(R.data(), rows, D, B.data(), K, C);
  w.accumulate_seconds = since(ta);
  return w;
}

void cross_validate_build(const BucketStore& store, const std::vector<Vec3>& origins, const BuildDesc& desc,
                          GridDesc& grid, ProjectDesc& pd, BuildReport& rep, const CvShare& share) {
  if (desc.auto_kernel || desc.auto_grid) {  // cross-validated choice (ilf/crossval.h)
    ResampleSearch rs{.kernel = desc.auto_kernel,
                      .grid = desc.auto_grid,
                      .volume = grid.volume,
                      .nx = grid.nx,
                      .ny = grid.ny,
                      .nz = grid.nz,
                      .kernel_cells = pd.kernel_cells,
                      .bands = desc.bands,
                      .memory_bytes = desc.buckets.memory_bytes,
                      .max_buckets = desc.auto_max_buckets,
                      .focus = desc.focus};
    rep.choice = choose_resampling(store, origins, pd, rs, desc.crossval, desc.ball_parallax, share);
    rep.t_choose = rep.choice->seconds;
    pd.kernel_cells = rep.choice->kernel;
    grid.nx = rep.choice->nx;
    grid.ny = rep.choice->ny;
    grid.nz = rep.choice->nz;
  }
  rep.nx = grid.nx;
  rep.ny = grid.ny;
  rep.nz = grid.nz;
  rep.kernel_cells = pd.kernel_cells;
  if (rep.choice && desc.crossval.folds >= 2)
    rep.crossval = rep.choice->best;  // the chosen trial's
  else if (desc.crossval.folds >= 2) {
    auto tc = Clock::now();
    rep.crossval = cross_validate(store, origins, grid, pd, desc.bands, desc.crossval, desc.auto_max_buckets,
                                  desc.ball_parallax, &rep.crossval_buckets, share);
    rep.t_crossval = since(tc);
  }
  if (rep.choice) rep.crossval_buckets = rep.choice->buckets_used;
}

void store_coefficients(const double* C, SHGrid& out) {
  // C(c·G + g, k) → data[(g·K + k)·3 + c].
  int K = out.coeff_count();
  int64_t G = out.grid().count(), rows = 3 * G;
  auto& data = out.data();
  parallel_for(
      0, G,
      [&](int64_t g) {
        for (int kk = 0; kk < K; ++kk)
          for (int c = 0; c < 3; ++c)
            data[(size_t(g) * K + kk) * 3 + c] = float(C[size_t(kk) * rows + size_t(c) * G + g]);
      },
      1024);
}

namespace {

// Step 1: the probes kept by sub-sampling, each process computing the energies of its share of the
// pairs of neighbours.
Sequence subsample_shared(const Sequence& seq_in, const BuildDesc& desc, const ProgressFn& progress, BuildReport& rep,
                          Collective& team) {
  if (!desc.subsample) return seq_in;
  auto t0 = Clock::now();
  SubsampleDesc sd = *desc.subsample;
  sd.skip_bad = sd.skip_bad || desc.buckets.skip_bad;
  team.agree([&] { check_subsample_desc(sd); });
  const int n = int(seq_in.probes.size());
  std::vector<double> e;
  if (n > 2) {
    const std::vector<int> begin = split_evenly(n - 1, team.size());
    std::vector<int> counts(size_t(team.size()));
    for (int r = 0; r < team.size(); ++r) counts[r] = begin[r + 1] - begin[r];
    std::vector<double> mine;
    const int r = team.rank();
    team.agree(
        [&] { mine = neighbour_energies(seq_in, sd, begin[r], begin[r + 1], r == 0 ? progress : ProgressFn{}); });
    e = team.gather(mine, counts);
  }
  auto keep = keep_from_energies(n, e, sd.threshold);
  Sequence seq = seq_in;
  seq.probes.clear();
  for (int i : keep) seq.probes.push_back(seq_in.probes[i]);
  rep.subsampled_out = n - int(keep.size());
  rep.t_subsample = since(t0);
  return seq;
}

}  // namespace

std::vector<DescribedValue> describe_build(const Sequence& seq, const BuildDesc& desc) {
  const BucketDesc& b = desc.buckets;
  const ProjectDesc& p = desc.project;
  std::string volume = desc.volume
                           ? fmt::format("{},{},{},{},{},{}", desc.volume->min.x, desc.volume->min.y,
                                         desc.volume->min.z, desc.volume->max.x, desc.volume->max.y, desc.volume->max.z)
                           : "the sequence's";
  std::string subsample =
      desc.subsample ? fmt::format("{} within {} m", desc.subsample->threshold, desc.subsample->max_distance) : "off";
  // The sequence: its manifest, mapping, frames (path, size, time) and positions.
  uint64_t hsh = 1469598103934665603ull;
  auto mix = [&](const std::string& s) {
    for (unsigned char c : s) hsh = (hsh ^ c) * 1099511628211ull;
  };
  mix(bucket_cache_key(seq, BucketDesc{}, 0, 0));
  for (const auto& pr : seq.probes) mix(fmt::format("{} {} {}", pr.position.x, pr.position.y, pr.position.z));
  return {{"sequence", fmt::format("{} ({} probes, fingerprint {:016x})", seq.manifest, seq.probes.size(), hsh)},
          {"grid", fmt::format("{},{},{}{}", desc.nx, desc.ny, desc.nz, desc.auto_grid ? " (auto)" : "")},
          {"volume", volume},
          {"bands", std::to_string(desc.bands)},
          {"kernel", desc.auto_kernel ? "auto" : fmt::format("{}", p.kernel_cells)},
          {"raster", fmt::format("{}", p.raster_cells)},
          {"repair", repair_name(p.repair)},
          {"directions", std::to_string(b.octahedral)},
          {"block buckets", std::to_string(b.max_block_buckets)},
          {"memory", std::to_string(b.memory_bytes)},
          {"buckets", b.dir},
          {"skip-bad", b.skip_bad ? "on" : "off"},
          {"sanitize", b.sanitize ? "on" : "off"},
          {"reuse", b.reuse ? "on" : "off"},
          {"subsample", subsample},
          {"cv-folds", std::to_string(desc.crossval.folds)},
          {"auto buckets", std::to_string(desc.auto_max_buckets)},
          {"focus", desc.focus ? fmt::format("{},{},{} r {}", desc.focus->centre.x, desc.focus->centre.y,
                                             desc.focus->centre.z, desc.focus->radius)
                               : "none"},
          {"parallax", desc.ball_parallax ? "on" : "off"}};
}

SHGrid build_shgrid(const Sequence& seq_in, const BuildDesc& desc, const ProgressFn& progress, BuildReport* report,
                    Collective* team_in) {
  Collective& team = team_in ? *team_in : serial_collective();
  auto t_all = Clock::now();
  BuildReport local;
  BuildReport& rep = report ? *report : local;
  rep = {};
  const bool root = team.rank() == 0;
  team.agree_on(describe_build(seq_in, desc));
  GridDesc grid;
  SHGrid out;
  team.agree([&] {
    grid = build_grid(seq_in, desc);
    if (root) out = SHGrid(grid, desc.bands);
  });
  ProjectDesc pd = desc.project;
  rep.probes_in = int(seq_in.probes.size());
  Sequence seq = subsample_shared(seq_in, desc, progress, rep, team);
  // Sort: each process writes its share of the blocks.
  auto t0 = Clock::now();
  BucketDesc bd;
  team.agree([&] { bd = resolve_directions(seq, desc); });
  BucketReport br;
  BucketStore store = BucketStore::sort(seq, bd, progress, &br, &team);
  rep.t_sort = since(t0);
  rep.t_read = br.read_seconds;
  rep.skipped = br.skipped;
  rep.skip_reasons = br.reasons;
  rep.buckets_reused = br.reused;
  const DirectionTable& t = store.table();
  rep.octahedral = bd.octahedral;
  rep.buckets = t.buckets();
  rep.blocks = t.blocks();
  int P = store.probe_count();
  rep.probes_used = P - br.skipped;
  std::vector<Vec3> origins(static_cast<size_t>(P));
  for (int p = 0; p < P; ++p) origins[p] = seq.probes[p].position;
  // The cross-validated choice and error: each process evaluates the sampled buckets of its blocks,
  // the partial sums meet on every process, and every process makes the same choice.
  CvShare share{store.block_begin(), store.block_end(), [&](const std::function<void()>& f) { team.agree(f); },
                [&](double* x, size_t n) { team.sum(x, int64_t(n), true); }};
  cross_validate_build(store, origins, desc, grid, pd, rep, share);
  if (root && (grid.nx != out.grid().nx || grid.ny != out.grid().ny || grid.nz != out.grid().nz))
    out = SHGrid(grid, desc.bands);
  rep.ball_radius = desc.ball_parallax && !t.start.empty() ? seq.ball.radius : 0.0;
  // Resample this process's blocks, block by block, into partial SH sums.
  int K = desc.bands * desc.bands;
  int64_t G = grid.count(), rows = 3 * G;
  std::vector<double> C;
  double repair_s = 0, busy_s = 0;
  int64_t counts[2] = {0, 0};  // rays, uncovered
  team.agree([&] {
    C.assign(size_t(rows) * K, 0.0);
    std::vector<float> R;
    std::vector<uint16_t> buf;
    BlockScratch scratch;
    const int k0 = store.block_begin(), k1 = store.block_end();
    for (int k = k0; k < k1; ++k) {
      auto w = resample_block(store, k, grid, pd, origins, desc.bands, desc.ball_parallax, buf, R, scratch, C.data());
      counts[0] += w.stats.rays;
      counts[1] += w.stats.uncovered;
      repair_s += w.stats.repair_seconds;
      busy_s += w.stats.busy_seconds;
      rep.t_project += w.project_seconds;
      rep.gemm_flops += w.gemm_flops;
      rep.t_accumulate += w.accumulate_seconds;
      if (root) ibl::report(progress, "resample", double(k - k0 + 1) / std::max(k1 - k0, 1));
    }
  });
  // The partial sums meet on process 0, which stores the grid.
  team.sum(C.data(), rows * K, false);
  if (root) store_coefficients(C.data(), out);
  std::vector<double>().swap(C);
  team.sum(counts, 2);
  team.sum_figures(&rep.gemm_flops, 1);
  rep.samples = counts[0];
  rep.uncovered = counts[1];
  rep.t_repair = busy_s > 0 ? rep.t_project * repair_s / busy_s : 0.0;
  rep.fraction_uncovered = double(rep.uncovered) / (double(G) * t.buckets());
  rep.t_total = since(t_all);
  return out;
}

}  // namespace ibl::ilf
