#include "iblkit/engine/cube_chain.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::engine {

Vec3 cube_texel_direction(int face, int x, int y, int size) {
  const double s = 2.0 * (x + 0.5) / size - 1.0, t = 2.0 * (y + 0.5) / size - 1.0;
  return normalize(sphere::cube_face_point(face, s, t));
}

std::vector<double> cube_face_solid_angles(int size) {
  sphere::Mapping m(sphere::MappingKind::CubeStrip, 6 * size, size);
  std::vector<double> out(static_cast<size_t>(size) * size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) out[static_cast<size_t>(y) * size + x] = m.solid_angle(x, y);
  return out;
}

namespace {
// Bilinear RGB of face f of a level strip (n × n faces, 3 channels) at face coordinates (s, t) ∈
// [−1, 1]², texel centres at (i + ½)/n, clamped at the face's edges: ImageView::bilinear with
// Wrap::Clamp on the face, written out for the importance sampler's inner loop.
Vec3 face_bilinear(const Image& strip, int f, double s, double t) {
  const int n = strip.height();
  const double fx = (s + 1) * 0.5 * n - 0.5, fy = (t + 1) * 0.5 * n - 0.5;
  const double x0f = std::floor(fx), y0f = std::floor(fy);
  const float tx = static_cast<float>(fx - x0f), ty = static_cast<float>(fy - y0f);
  const int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
  const int xa = std::clamp(x0, 0, n - 1) + f * n, xb = std::clamp(x0 + 1, 0, n - 1) + f * n;
  const int ya = std::clamp(y0, 0, n - 1), yb = std::clamp(y0 + 1, 0, n - 1);
  const float w00 = (1 - tx) * (1 - ty), w10 = tx * (1 - ty), w01 = (1 - tx) * ty, w11 = tx * ty;
  const float *p00 = strip.pixel(xa, ya), *p10 = strip.pixel(xb, ya), *p01 = strip.pixel(xa, yb),
              *p11 = strip.pixel(xb, yb);
  float c[3];
  for (int k = 0; k < 3; ++k) c[k] = w00 * p00[k] + w10 * p10[k] + w01 * p01[k] + w11 * p11[k];
  return {c[0], c[1], c[2]};
}
}  // namespace

Vec3 CubeChain::sample(Vec3 d, int level) const {
  const Image& im = levels[static_cast<size_t>(std::clamp(level, 0, count() - 1))];
  double s = 0, t = 0;
  const int f = sphere::cube_face_of(d, &s, &t);
  return face_bilinear(im, f, s, t);
}

Vec3 CubeChain::sample(Vec3 d, double lod) const {
  lod = std::clamp(lod, 0.0, double(count() - 1));
  const int l0 = static_cast<int>(lod);
  const double a = lod - l0;
  double s = 0, t = 0;
  const int f = sphere::cube_face_of(d, &s, &t);  // the same face and (s, t) on every level
  Vec3 c0 = face_bilinear(levels[static_cast<size_t>(l0)], f, s, t);
  if (a <= 0 || l0 + 1 >= count()) return c0;
  return c0 * (1 - a) + face_bilinear(levels[static_cast<size_t>(l0 + 1)], f, s, t) * a;
}

namespace {
// A cube-map probe of face `size` whose texel centres the rotation (a signed permutation of the
// axes: a mirror, quarter turns) takes onto texel centres: its texels, moved, without resampling
// (resampling would blur them a little). Empty where that is not the case.
Image texel_copy(const sphere::EnvMap& probe, int size, const Mat3& rotation) {
  const sphere::Mapping& m = probe.mapping;
  if (m.face_size() != size) return {};
  const Mat3 back = rotation.transposed();
  Image out(6 * size, size, 3);
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        double px = 0, py = 0;
        if (!m.to_pixel(back * cube_texel_direction(f, x, y, size), &px, &py)) return {};
        const int ix = static_cast<int>(std::floor(px)), iy = static_cast<int>(std::floor(py));
        if (std::abs(px - ix - 0.5) > 1e-6 || std::abs(py - iy - 0.5) > 1e-6 || !m.valid(ix, iy)) return {};
        out.set_rgb(f * size + x, y, probe.image.rgb(ix, iy));
      }
  return out;
}
}  // namespace

CubeChain build_cube_chain(const sphere::EnvMap& probe, int size, const Mat3& rotation, int levels) {
  if (size < 1 || size > 8192) fail(ErrorKind::Value, "cube size {} outside 1..8192", size);
  sphere::ResampleDesc rd;
  rd.rotation = rotation;
  CubeChain chain;
  Image base = texel_copy(probe, size, rotation);
  if (base.empty())
    base =
        sphere::resample(probe, sphere::Mapping(sphere::MappingKind::CubeStrip, 6 * size, size), rd).with_channels(3);
  chain.levels.push_back(std::move(base));
  while (chain.size(chain.count() - 1) > 1 && (levels <= 0 || chain.count() < levels)) {
    const Image& fine = chain.levels.back();
    const int n = fine.height(), h = n / 2;
    if (n % 2) break;  // a face size that is not a power of two ends the chain where it turns odd
    const std::vector<double> om = cube_face_solid_angles(n);
    Image coarse(6 * h, h, 3);
    for (int f = 0; f < 6; ++f)
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < h; ++x) {
          double sw = 0;
          Vec3 acc;
          for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
              const int fx = 2 * x + i, fy = 2 * y + j;
              const double w = om[static_cast<size_t>(fy) * n + fx];
              acc += fine.rgb(f * n + fx, fy) * w;
              sw += w;
            }
          coarse.set_rgb(f * h + x, y, acc / sw);
        }
    chain.levels.push_back(std::move(coarse));
  }
  return chain;
}

}  // namespace ibl::engine
