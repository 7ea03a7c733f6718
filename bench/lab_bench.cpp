// Micro-benchmarks of lab/: one 250×250 mirror-ball probe of low-scene1 through the physical ball
// camera, direct light only, 4 shadow rays per area-light hit (issue 4 target: 4397 such probes,
// streamed to disk, ≤ 5 minutes on the 2-core machine). The counter "s_per_4397" extrapolates the
// capture part linearly (no disk writes: bench/lab_capture.sh times the full, streamed run).
#include <benchmark/benchmark.h>

#include "iblkit/lab/capture.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/sequence.h"

namespace {

using namespace ibl;

void BM_LabMirrorBall250(benchmark::State& state) {
  static lab::Scene scene = lab::load_scene("low-scene1");
  lab::CaptureDesc cd;
  cd.mapping = sphere::MappingKind::MirrorBall;
  cd.camera = lab::Camera::MirrorBall;
  cd.size = 250;
  cd.render = scene.render;
  cd.render.area_samples = 4;
  cd.render.bounces = 0;
  auto pos = lab::random_positions(scene.volume_min, scene.volume_max, 64, 1);
  uint64_t k = 0;
  for (auto _ : state) {
    lab::Capture c = lab::capture_probe(scene, pos[k % pos.size()], cd, k);
    ++k;
    benchmark::DoNotOptimize(c.radiance.data());
  }
  state.SetItemsProcessed(state.iterations());
  // (iterations / 4397) batches per second, inverted: seconds per 4397 probes.
  state.counters["s_per_4397"] =
      benchmark::Counter(state.iterations() / 4397.0, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LabMirrorBall250)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

void BM_LabLatLong64Bounces2(benchmark::State& state) {
  static lab::Scene scene = lab::load_scene("low-scene1");
  lab::CaptureDesc cd;
  cd.size = 64;
  cd.render = scene.render;
  cd.render.bounces = 2;
  for (auto _ : state) {
    lab::Capture c = lab::capture_probe(scene, {0, 1, 0}, cd);
    benchmark::DoNotOptimize(c.radiance.data());
  }
  state.SetItemsProcessed(state.iterations() * 128 * 64);
}
BENCHMARK(BM_LabLatLong64Bounces2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
