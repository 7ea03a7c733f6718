// Micro-benchmarks of ilf/: the two kernels of the resampling loop at the paper's scale (Löw et al.
// 2009, first scene: 4397 probes, 64³ grid, 25 coefficients). End to end: bench/ilf_e2e.sh.
#include <benchmark/benchmark.h>

#include <random>

#include "iblkit/ilf/build.h"

namespace {

using namespace ibl;
using namespace ibl::ilf;

// SH accumulation of one block: (3·64³ × D) · (D × 25). Reports GFLOP/s as "FLOPS" counter.
void BM_IlfAccumulateBlock64(benchmark::State& state) {
  int D = int(state.range(0)), K = 25;
  int64_t rows = 3 * 64 * 64 * 64;
  std::vector<float> R(size_t(rows) * D, 0.5f), B(size_t(D) * K, 0.01f);
  std::vector<double> C(size_t(rows) * K, 0.0);
  double flops = 0;
  for (auto _ : state) {
    flops += accumulate_block(R.data(), rows, D, B.data(), K, C.data());
    benchmark::DoNotOptimize(C.data());
  }
  state.counters["FLOPS"] = benchmark::Counter(flops, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_IlfAccumulateBlock64)->Arg(32)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();

// Projection of one bucket of the paper-scale case: 4397 probes × n_dirs rays onto 64³ points.
void BM_IlfProjectBucket64(benchmark::State& state) {
  int P = 4397, nd = int(state.range(0));
  GridDesc grid{64, 64, 64, {{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}}};
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-0.5, 0.5);
  std::vector<Vec3> origins(static_cast<size_t>(P));
  for (auto& o : origins) o = {U(rng), U(rng), U(rng)};
  std::vector<float> dirs, rad(size_t(P) * nd * 3, 1.0f);
  std::vector<double> w(size_t(nd), 1e-4);
  for (int q = 0; q < nd; ++q) {
    Vec3 d = normalize(Vec3{0.3, 0.5, 1.0} + Vec3{U(rng), U(rng), U(rng)} * 0.1);
    dirs.insert(dirs.end(), {float(d.x), float(d.y), float(d.z)});
  }
  struct Ctx {
    const float* r;
    int stride;
  } ctx{rad.data(), nd * 3};
  BucketRays rays;
  rays.dirs = dirs.data();
  rays.weights = w.data();
  rays.n_dirs = nd;
  rays.origins = origins.data();
  rays.n_probes = P;
  rays.ctx = &ctx;
  rays.radiance = [](const void* c, int p) {
    auto* x = static_cast<const Ctx*>(c);
    return x->r + size_t(p) * x->stride;
  };
  ProjectScratch sc;
  std::vector<float> out(size_t(grid.count()) * 3);
  int64_t n = 0;
  for (auto _ : state) {
    auto st = project_bucket(grid, rays, ProjectDesc{}, out.data(), grid.count(), sc);
    n += st.rays;
  }
  state.counters["rays/s"] = benchmark::Counter(double(n), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_IlfProjectBucket64)->Arg(1)->Arg(85)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
