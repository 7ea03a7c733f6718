// convolve_cube (cube_chain.h): a template, so that the kernel inlines into the inner loop.
#pragma once
#include <atomic>
#include <vector>

#include "iblkit/core/parallel.h"

namespace ibl::engine {

template <typename Kernel>
Image convolve_cube(const Image& source, int out_size, const Kernel& kernel, const ProgressFn& progress) {
  const int ns = source.height();
  const std::vector<double> omega = cube_face_solid_angles(ns);
  const size_t count = static_cast<size_t>(6) * ns * ns;
  // Source texels as flat arrays: direction, solid angle, radiance.
  std::vector<float> dx(count), dy(count), dz(count), w(count), lr(count), lg(count), lb(count);
  for (int f = 0, j = 0; f < 6; ++f)
    for (int y = 0; y < ns; ++y)
      for (int x = 0; x < ns; ++x, ++j) {
        Vec3 d = cube_texel_direction(f, x, y, ns);
        dx[j] = float(d.x), dy[j] = float(d.y), dz[j] = float(d.z);
        w[j] = float(omega[static_cast<size_t>(y) * ns + x]);
        const float* p = source.pixel(f * ns + x, y);
        lr[j] = p[0], lg[j] = p[1], lb[j] = p[2];
      }
  Image out(6 * out_size, out_size, 3);
  std::atomic<int> rows_done{0};
  parallel_for(0, 6 * out_size, [&](int64_t row) {
    const int f = static_cast<int>(row / out_size), y = static_cast<int>(row % out_size);
    for (int x = 0; x < out_size; ++x) {
      Vec3 r = cube_texel_direction(f, x, y, out_size);
      const float rx = float(r.x), ry = float(r.y), rz = float(r.z);
      double sw = 0, sr = 0, sg = 0, sb = 0;
      for (size_t j = 0; j < count; ++j) {
        const float c = rx * dx[j] + ry * dy[j] + rz * dz[j];
        if (c <= 0) continue;
        const double k = kernel(double(c)) * w[j];
        sw += k, sr += k * lr[j], sg += k * lg[j], sb += k * lb[j];
      }
      float* o = out.pixel(f * out_size + x, y);
      if (sw > 0) o[0] = float(sr / sw), o[1] = float(sg / sw), o[2] = float(sb / sw);
    }
    int done = ++rows_done;
    if (progress && done % 8 == 0) progress("convolve", double(done) / (6 * out_size));
  });
  return out;
}

}  // namespace ibl::engine
