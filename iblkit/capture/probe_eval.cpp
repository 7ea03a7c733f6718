#include "iblkit/capture/probe_eval.h"

#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::capture {

std::vector<Vec3> probe_irradiance(const sphere::EnvMap& probe, const std::vector<Vec3>& normals) {
  std::vector<Vec3> dirs, vals;
  const Image& img = probe.image;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      Vec3 d;
      const double s = probe.mapping.solid_angle(x, y);
      if (s <= 0 || !probe.mapping.to_direction(x + 0.5, y + 0.5, &d)) continue;
      const double a = img.channels() == 4 ? img.at(x, y, 3) : 1.0;
      dirs.push_back(d);
      vals.push_back(img.rgb(x, y) * (a * s));
    }
  std::vector<Vec3> e(normals.size());
  parallel_for(0, static_cast<int64_t>(normals.size()), [&](int64_t i) {
    Vec3 sum;
    for (size_t p = 0; p < dirs.size(); ++p) {
      const double c = dot(normals[static_cast<size_t>(i)], dirs[p]);
      if (c > 0) sum += vals[p] * c;
    }
    e[static_cast<size_t>(i)] = sum;
  });
  return e;
}

double mean_relative_luminance_error(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  if (a.size() != b.size() || a.empty())
    fail(ErrorKind::Value, "irradiance sets of {} and {} normals: they must be the same, non-empty", a.size(),
         b.size());
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double ref = luminance(b[i]);
    if (!(ref > 0))
      fail(ErrorKind::Value, "the reference irradiance at normal {} is {}: no light to compare with", i, ref);
    s += std::abs(luminance(a[i]) - ref) / ref;
  }
  return s / static_cast<double>(a.size());
}

}  // namespace ibl::capture
