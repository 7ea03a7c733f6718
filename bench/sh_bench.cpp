// SH projection benchmarks: the separable lat-long path at the size (1024×512 to 25
// coefficients, target ≤ 5 ms on the 2-core dev machine) and the per-pixel path any mapping takes.
#include <cmath>

#include <benchmark/benchmark.h>

#include "iblkit/sh/project.h"
#include "iblkit/sphere/envmap.h"

namespace {

using namespace ibl;

// A deterministic, non-trivial 1024×512 RGB lat-long (smooth sky plus a few bright spots).
sphere::EnvMap bench_latlong(int w, int h) {
  Image img(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double u = (x + 0.5) / w, v = (y + 0.5) / h;
      double sky = 1.0 + 0.5 * std::cos(kPi * v) + 0.2 * std::sin(6 * kPi * u);
      double spot = std::exp(-200 * ((u - 0.3) * (u - 0.3) + (v - 0.3) * (v - 0.3))) * 50;
      img.set_rgb(x, y, {sky + spot, 0.9 * sky + 0.5 * spot, 0.8 * sky});
    }
  sphere::Mapping m(sphere::MappingKind::LatLong, w, h);
  return sphere::EnvMap(std::move(img), m);
}

void BM_ShProjectLatLong1024(benchmark::State& state) {
  static const sphere::EnvMap env = bench_latlong(1024, 512);
  const int bands = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(sh::project(env, bands));
  state.SetLabel("1024x512 lat-long, " + std::to_string(bands * bands) + " coefficients");
}
BENCHMARK(BM_ShProjectLatLong1024)->Arg(5)->Arg(3)->Arg(9)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ShProjectGenericLatLong1024(benchmark::State& state) {
  static const sphere::EnvMap env = bench_latlong(1024, 512);
  for (auto _ : state) benchmark::DoNotOptimize(sh::project_generic(env, 5));
  state.SetLabel("per-pixel path, 1024x512 lat-long, 25 coefficients");
}
BENCHMARK(BM_ShProjectGenericLatLong1024)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ShProjectMirrorBall512(benchmark::State& state) {
  static const sphere::EnvMap ball = [] {
    sphere::EnvMap ll = bench_latlong(1024, 512);
    sphere::Mapping m(sphere::MappingKind::MirrorBall, 512, 512);
    return sphere::EnvMap(sphere::resample(ll, m), m);
  }();
  for (auto _ : state) benchmark::DoNotOptimize(sh::project(ball, 5));
  state.SetLabel("512x512 mirror ball, 25 coefficients");
}
BENCHMARK(BM_ShProjectMirrorBall512)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
