// The C++ side of bench/python_overhead.py (issue 17): the library calls the Python module makes for
// the paper-scale operations, on the same inputs, so that the script can put the Python call's time
// beside the C++ call's: SH projection of a 1024×512 probe, 64 median-cut lights, an ILF build of the
// sequence the script writes (IBLKIT_PYBENCH_SEQ, buckets in IBLKIT_PYBENCH_BUCKETS).
#include <cstdlib>
#include <filesystem>

#include <benchmark/benchmark.h>

#include "iblkit/ilf/build.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/lights/extract.h"
#include "iblkit/sh/project.h"

namespace {

const char* kForest = "/usr/share/blender/datafiles/studiolights/world/forest.exr";

const ibl::sphere::EnvMap* forest() {
  static std::unique_ptr<ibl::sphere::EnvMap> env;
  if (!env && std::filesystem::exists(kForest))
    env = std::make_unique<ibl::sphere::EnvMap>(ibl::io::read_envmap(kForest));
  return env.get();
}

void BM_PyRef_ShProject(benchmark::State& state) {
  auto* env = forest();
  if (!env) {
    state.SkipWithError("blender-data probe missing");
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(ibl::sh::project(*env, 3));
}
BENCHMARK(BM_PyRef_ShProject)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PyRef_MedianCut64(benchmark::State& state) {
  auto* env = forest();
  if (!env) {
    state.SkipWithError("blender-data probe missing");
    return;
  }
  ibl::lights::ExtractDesc d;
  d.method = "median-cut";
  d.count = 64;
  for (auto _ : state) benchmark::DoNotOptimize(ibl::lights::extract(*env, d));
}
BENCHMARK(BM_PyRef_MedianCut64)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PyRef_IlfBuild(benchmark::State& state) {
  const char* seq = std::getenv("IBLKIT_PYBENCH_SEQ");
  const char* buckets = std::getenv("IBLKIT_PYBENCH_BUCKETS");
  if (!seq || !buckets) {
    state.SkipWithError("IBLKIT_PYBENCH_SEQ / IBLKIT_PYBENCH_BUCKETS not set (bench/python_overhead.py sets them)");
    return;
  }
  for (auto _ : state) {
    auto s = ibl::ilf::read_sequence(seq);  // what ilf.build(path) does: read, then build (buckets reused)
    ibl::ilf::BuildDesc d;
    d.nx = d.ny = d.nz = 16;
    d.bands = 5;
    d.buckets.dir = buckets;
    benchmark::DoNotOptimize(ibl::ilf::build_shgrid(s, d));
  }
}
BENCHMARK(BM_PyRef_IlfBuild)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
