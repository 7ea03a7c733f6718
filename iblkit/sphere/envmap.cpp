#include "iblkit/sphere/envmap.h"

#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::sphere {

EnvMap::EnvMap(Image img, Mapping m) : image(std::move(img)), mapping(m) {
  if (image.width() != mapping.width() || image.height() != mapping.height())
    fail(ErrorKind::Value, "image is {}x{} but its {} mapping is {}x{}", image.width(), image.height(),
         mapping_name(mapping.kind()), mapping.width(), mapping.height());
}

EnvMap EnvMap::from_image(Image img, std::optional<MappingKind> kind, std::string_view name, double dead_angle_deg) {
  MappingKind k = kind ? *kind : detect_mapping(img.width(), img.height(), name);
  if (k == MappingKind::CubeHCross && img.width() * 4 == img.height() * 3) k = MappingKind::CubeVCross;
  Mapping m(k, img.width(), img.height(), dead_angle_deg);
  return EnvMap(std::move(img), m);
}

void EnvMap::sample(Vec3 d, float* out) const {
  double px, py;
  int nc = image.channels();
  if (!mapping.to_pixel(d, &px, &py)) {
    for (int c = 0; c < nc; ++c) out[c] = 0.0f;
    return;
  }
  ImageView v = image.view();
  switch (mapping.kind()) {
    case MappingKind::LatLong: v.bilinear(px, py, Wrap::LatLong, out); return;
    case MappingKind::CubeHCross:
    case MappingKind::CubeVCross:
    case MappingKind::CubeStrip: {
      int f = mapping.face_size();
      int cx = static_cast<int>(px) / f, cy = static_cast<int>(py) / f;
      v.sub(cx * f, cy * f, f, f).bilinear(px - cx * f, py - cy * f, Wrap::Clamp, out);
      return;
    }
    default: v.bilinear(px, py, Wrap::Clamp, out); return;
  }
}

Vec3 EnvMap::sample_rgb(Vec3 d) const {
  float buf[64];
  sample(d, buf);
  return image.channels() >= 3 ? Vec3{buf[0], buf[1], buf[2]} : Vec3{buf[0], buf[0], buf[0]};
}

std::vector<double> EnvMap::integral() const {
  int nc = image.channels();
  std::vector<double> sum(nc, 0.0);
  std::vector<std::vector<double>> rows(image.height(), std::vector<double>(nc, 0.0));
  parallel_for(0, image.height(), [&](int64_t y) {
    for (int x = 0; x < image.width(); ++x) {
      if (!mapping.valid(x, static_cast<int>(y))) continue;
      double w = mapping.solid_angle(x, static_cast<int>(y));
      const float* p = image.pixel(x, static_cast<int>(y));
      for (int c = 0; c < nc; ++c) rows[y][c] += w * p[c];
    }
  });
  for (auto& r : rows)
    for (int c = 0; c < nc; ++c) sum[c] += r[c];
  return sum;
}

Image solid_angle_image(const Mapping& m) {
  Image out(m.width(), m.height(), 1);
  parallel_for(0, m.height(), [&](int64_t y) {
    for (int x = 0; x < m.width(); ++x)
      out.at(x, static_cast<int>(y), 0) =
          m.valid(x, static_cast<int>(y)) ? static_cast<float>(m.solid_angle(x, static_cast<int>(y))) : 0.0f;
  });
  return out;
}

Image resample(const EnvMap& src, const Mapping& dst, const ResampleDesc& desc) {
  int nc = src.image.channels();
  Image out(dst.width(), dst.height(), nc);
  // Mean input pixel solid angle (discs fill π/4 of their square).
  double src_pixels = static_cast<double>(src.mapping.width()) * src.mapping.height();
  switch (src.mapping.kind()) {
    case MappingKind::MirrorBall:
    case MappingKind::Angular: src_pixels *= kPi / 4; break;
    case MappingKind::CubeHCross: src_pixels *= 0.5; break;
    case MappingKind::CubeVCross: src_pixels *= 0.5; break;
    default: break;
  }
  double src_omega = kFourPi / src_pixels;
  bool rotate = false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rotate |= std::abs(desc.rotation.m[i][j] - (i == j ? 1.0 : 0.0)) > 0;
  Mat3 inv = desc.rotation.transposed();
  parallel_for(0, dst.height(), [&](int64_t yy) {
    int y = static_cast<int>(yy);
    std::vector<float> acc(nc), tmp(nc);
    for (int x = 0; x < dst.width(); ++x) {
      float* o = out.pixel(x, y);
      double omega = dst.solid_angle(x, y);
      if (omega <= 0) continue;
      // Sub-samples per axis: one while the output pixel is at most ~1.5 input pixels (the bilinear
      // tent already spans that), then one more per input pixel across.
      int n = std::clamp(static_cast<int>(std::ceil(std::sqrt(omega / src_omega) - 0.25)), 1,
                         desc.max_supersampling);
      std::fill(acc.begin(), acc.end(), 0.0f);
      int count = 0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          Vec3 d;
          if (!dst.to_direction(x + (i + 0.5) / n, y + (j + 0.5) / n, &d)) continue;
          if (rotate) d = inv * d;
          src.sample(d, tmp.data());
          for (int c = 0; c < nc; ++c) acc[c] += tmp[c];
          ++count;
        }
      if (count == 0) continue;
      for (int c = 0; c < nc; ++c) o[c] = acc[c] / count;
    }
  });
  return out;
}

}  // namespace ibl::sphere
