// Micro-benchmarks of fusion/ (issue 6 targets on the 2-core machine): a 6×64² local cube map at a point
// from 8 lat-long probes of 512×256 on the T-corridor proxy (≤ 15 ms), and tracing the 8 probes' depth
// maps on the proxy (≤ 2 s). Probe radiance is a procedural pattern: the cost does not depend on it.
#include <benchmark/benchmark.h>

#include <cmath>

#include <tbb/global_control.h>

#include "iblkit/fusion/fuse.h"
#include "iblkit/fusion/probe_set.h"
#include "iblkit/geometry/mesh_io.h"

namespace {

using namespace ibl;

fusion::ProbeSet corridor_set(bool with_depth) {
  static const geometry::TriMesh proxy =
      geometry::read_mesh(std::string(IBLKIT_SOURCE_DIR) + "/examples/t-corridor-proxy.obj");
  static const std::vector<Vec3> pos = {{-4, 1.5, -1}, {-2, 1.5, -1}, {0, 1.5, -1}, {2, 1.5, -1},
                                        {4, 1.5, -1},  {0, 1.5, 2},   {0, 1.5, 5},  {0, 1.5, 8}};
  fusion::ProbeSet set;
  set.proxy = proxy;
  sphere::Mapping m(sphere::MappingKind::LatLong, 512, 256);
  for (Vec3 p : pos) {
    fusion::Probe pr;
    pr.position = p;
    Image img(512, 256, 3);
    for (int y = 0; y < 256; ++y)
      for (int x = 0; x < 512; ++x)
        img.set_rgb(x, y, {1 + 0.5 * std::sin(x * 0.1), 1 + 0.5 * std::cos(y * 0.13), 1 + 0.1 * p.x});
    pr.radiance = sphere::EnvMap(std::move(img), m);
    set.probes.push_back(std::move(pr));
  }
  if (with_depth) fusion::prepare(set);
  return set;
}

void BM_FusionCube64From8Probes(benchmark::State& state) {
  static const fusion::ProbeSet set = corridor_set(true);
  fusion::FuseDesc fd;
  fd.mapping = sphere::MappingKind::CubeHCross;
  fd.size = 64;
  fd.blend = static_cast<fusion::Blend>(state.range(0));
  fd.visibility = state.range(1) != 0;
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(state.range(2)));
  for (auto _ : state) {
    fusion::LocalMap m = fusion::fuse(set, {0, 1.5, 1}, fd);
    benchmark::DoNotOptimize(m.radiance.image.data());
  }
  state.SetLabel(fusion::blend_name(fd.blend) + (fd.visibility ? ", visibility, " : ", no visibility, ") +
                 std::to_string(state.range(2)) + " thread(s)");
  state.SetItemsProcessed(state.iterations() * 6 * 64 * 64);
}
BENCHMARK(BM_FusionCube64From8Probes)
    ->Args({2, 1, 2})
    ->Args({1, 1, 2})
    ->Args({0, 1, 2})
    ->Args({2, 0, 2})
    ->Args({2, 1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

void BM_FusionDepth8Probes512(benchmark::State& state) {
  fusion::ProbeSet base = corridor_set(false);
  for (auto _ : state) {
    fusion::ProbeSet set = base;  // depth maps empty: prepare() traces all 8 (plus the inside checks)
    fusion::prepare(set);
    benchmark::DoNotOptimize(set.probes[7].depth.data());
  }
  state.SetItemsProcessed(state.iterations() * 8 * 512 * 256);
}
BENCHMARK(BM_FusionDepth8Probes512)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace
