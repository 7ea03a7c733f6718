// Benchmarks of lights/ at the paper's scale (Madsen & Laursen 2007): a 1024×512 blender-data probe,
// the 20480 normals of a level-5 icosphere. Targets (issue 3): ground truth ≤ 1.5 s, median cut of
// 64 lights ≤ 10 ms, irradiance optimisation of 64 lights ≤ 3 s, on the 2-core development machine.
#include <filesystem>

#include <benchmark/benchmark.h>

#include "iblkit/io/envmap_io.h"
#include "iblkit/lights/cut.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/lights/optimize.h"
#include "iblkit/sphere/pointset.h"

namespace {

const char* kProbe = "/usr/share/blender/datafiles/studiolights/world/forest.exr";

const ibl::sphere::EnvMap* probe() {
  static std::unique_ptr<ibl::sphere::EnvMap> env;
  if (!env && std::filesystem::exists(kProbe))
    env = std::make_unique<ibl::sphere::EnvMap>(ibl::io::read_envmap(kProbe));
  return env.get();
}

void BM_GroundTruth20480(benchmark::State& state) {
  auto* env = probe();
  if (!env) {
    state.SkipWithError("blender-data probe missing");
    return;
  }
  auto normals = ibl::sphere::icosphere_face_centres(5);
  ibl::lights::GroundTruthDesc d;
  d.cull = state.range(0) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(ibl::lights::irradiance_ground_truth(*env, normals, d));
  state.SetLabel(d.cull ? "tile culling + SIMD" : "pure brute force SIMD");
}
BENCHMARK(BM_GroundTruth20480)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

void BM_MedianCut(benchmark::State& state) {
  auto* env = probe();
  if (!env) {
    state.SkipWithError("blender-data probe missing");
    return;
  }
  ibl::lights::CutDesc d;
  d.count = static_cast<int>(state.range(0));
  d.power_of_two = true;
  for (auto _ : state) benchmark::DoNotOptimize(ibl::lights::median_cut(*env, d));
}
BENCHMARK(BM_MedianCut)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MedianCutGridOnly(benchmark::State& state) {
  auto* env = probe();
  if (!env) {
    state.SkipWithError("blender-data probe missing");
    return;
  }
  auto grid = ibl::lights::to_latlong_grid(*env);
  ibl::lights::CutDesc d;
  d.count = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(ibl::lights::median_cut(grid, d));
  state.SetLabel("lat-long grid prepared, validation excluded");
}
BENCHMARK(BM_MedianCutGridOnly)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_VarianceCut(benchmark::State& state) {
  auto* env = probe();
  if (!env) {
    state.SkipWithError("blender-data probe missing");
    return;
  }
  ibl::lights::CutDesc d;
  d.count = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(ibl::lights::variance_cut(*env, d));
}
BENCHMARK(BM_VarianceCut)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();

// Optimisation only: the 20480 normals' ground truth and the initial cut are computed outside the loop.
void BM_Optimize(benchmark::State& state) {
  auto* env = probe();
  if (!env) {
    state.SkipWithError("blender-data probe missing");
    return;
  }
  auto normals = ibl::sphere::icosphere_face_centres(5);
  auto gt = ibl::lights::irradiance_ground_truth(*env, normals);
  ibl::lights::CutDesc cd;
  cd.count = static_cast<int>(state.range(0));
  auto init = ibl::lights::variance_cut(*env, cd);
  ibl::lights::OptimizeDesc od;
  ibl::lights::OptimizeReport rep;
  for (auto _ : state)
    benchmark::DoNotOptimize(ibl::lights::optimize_lights_from(*env, normals, gt, init.lights, od, &rep));
  state.counters["iterations"] = rep.iterations;
  state.counters["final_iterations"] = rep.final_iterations;
  state.counters["converged"] = rep.converged;
  state.counters["cost_ratio"] = rep.final_cost / rep.initial_cost;
}
BENCHMARK(BM_Optimize)->Arg(16)->Arg(64)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

}  // namespace
