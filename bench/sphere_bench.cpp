// Micro-benchmarks of sphere/: resampling between mappings (issue 2 target: 1024×512 lat-long →
// 6×256² cube ≤ 20 ms on the 2-core development machine).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "iblkit/io/envmap_io.h"
#include "iblkit/sphere/envmap.h"

namespace {

using namespace ibl;
using namespace ibl::sphere;

EnvMap bench_probe() {
  const std::string p = "/usr/share/blender/datafiles/studiolights/world/forest.exr";
  if (std::filesystem::exists(p)) return io::read_envmap(p);
  Image img(1024, 512, 3, 1.0f);
  return EnvMap(img, Mapping(MappingKind::LatLong, 1024, 512));
}

void BM_LatLongToCube256(benchmark::State& state) {
  EnvMap src = bench_probe();
  Mapping dst(MappingKind::CubeHCross, 4 * 256, 3 * 256);
  for (auto _ : state) {
    Image out = resample(src, dst);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 6 * 256 * 256);
}
BENCHMARK(BM_LatLongToCube256)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LatLongToMirrorBall512(benchmark::State& state) {
  EnvMap src = bench_probe();
  Mapping dst(MappingKind::MirrorBall, 512, 512);
  for (auto _ : state) {
    Image out = resample(src, dst);
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_LatLongToMirrorBall512)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
