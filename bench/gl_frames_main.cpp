// GPU time per frame of the real-time renderer (issue 8 targets, on the device machine's H100):
// SH-grid diffuse ≤ 0.5 ms and glossy ≤ 1 ms at 1024×768 for a 100k-triangle object; directional
// lights with shadow maps. Built as the lean target iblkit_glbench (no OpenImageIO/Embree/…), so it
// can be carried to a GPU machine with a handful of shared libraries. Prints one JSON object.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "iblkit/render/gl/context.h"
#include "iblkit/render/gl/renderer.h"
#include "iblkit/render/mesh.h"

using namespace ibl;
using namespace ibl::render;

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

SHGridData make_grid(int n, int bands) {
  SHGridData g;
  g.bands = bands;
  g.nx = g.ny = g.nz = n;
  g.min = {-0.6, -0.6, -0.6};
  g.max = {0.6, 0.6, 0.6};
  const int K = bands * bands;
  g.data.resize(static_cast<size_t>(n) * n * n * K * 3);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (int k = 0; k < K; ++k)
          for (int c = 0; c < 3; ++c) {
            size_t i = ((((static_cast<size_t>(z) * n + y) * n + x) * K + k) * 3 + c);
            g.data[i] = static_cast<float>((k == 0 ? 2.0 : 0.3 / (1 + k)) * (1 + 0.3 * std::sin(0.3 * x + 0.2 * y - 0.1 * z + c)));
          }
  return g;
}

}  // namespace

int main(int argc, char** argv) {
  int frames = argc > 1 ? std::atoi(argv[1]) : 50;
  int tris = argc > 2 ? std::atoi(argv[2]) : 100000;
  int width = argc > 3 ? std::atoi(argv[3]) : 1024, height = argc > 4 ? std::atoi(argv[4]) : 768;
  try {
    gl::Context ctx;
    Mesh blob = make_blob(tris, 0.8);
    std::printf("{\"renderer\": \"%s\", \"triangles\": %zu, \"size\": \"%dx%d\", \"frames\": %d", ctx.renderer().c_str(),
                blob.triangle_count(), width, height, frames);
    for (bool deferred : {false, true}) {
      gl::Renderer r({deferred});
      FrameDesc d;
      d.camera.eye = {0, 0.4, 1.6};
      d.camera.target = {0, 0, 0};
      d.camera.width = width;
      d.camera.height = height;
      d.objects.push_back({&blob, Material{{0.7, 0.7, 0.7}, {0, 0, 0}, 1}});
      const char* path = deferred ? "deferred" : "forward";
      auto run = [&](const char* name) {
        gl::GpuTiming t;
        r.render(d, frames, &t);
        std::printf(",\n \"%s_%s_ms\": %.4f", path, name, median(t.frame_ms));
      };
      for (int n : {8, 16, 32}) {
        d.lighting.grid = make_grid(n, 5);
        d.objects[0].material = Material{{0.7, 0.7, 0.7}, {0, 0, 0}, 1};
        run(("shgrid" + std::to_string(n) + "_b5_diffuse").c_str());
      }
      d.objects[0].material = Material{{0.6, 0.6, 0.6}, {0.3, 0.3, 0.3}, 30};
      run("shgrid32_b5_glossy_s30");
      d.lighting.grid.reset();
      for (int i = 0; i < 256; ++i) {
        double th = std::acos(1 - (i + 0.5) / 256.0), ph = 2.39996 * i;
        d.lighting.lights.push_back({{std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)},
                                     {0.02, 0.02, 0.02}, i < 16});
      }
      run("lights256_16_shadowed");
      d.lighting.lights.resize(16);
      run("lights16_all_shadowed");
      for (auto& l : d.lighting.lights) l.shadow = false;
      run("lights16_no_shadows");
    }
    std::printf("}\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "iblkit_glbench: %s\n", e.what());
    return 1;
  }
  return 0;
}
