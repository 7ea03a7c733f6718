// Probes for the lights tests: analytic ones with known answers, and small copies of the real
// blender-data probes (CC0, Debian's blender-data package).
#pragma once
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "iblkit/io/envmap_io.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::lights::testing {

inline sphere::EnvMap constant_probe(int w, int h, float value = 1.0f) {
  return sphere::EnvMap(Image(w, h, 3, value), sphere::Mapping(sphere::MappingKind::LatLong, w, h));
}

// Black lat-long probe with one lit pixel (x, y) of radiance `rgb`.
inline sphere::EnvMap sun_probe(int w, int h, int x, int y, Vec3 rgb, float sky = 0.0f) {
  Image img(w, h, 3, sky);
  img.set_rgb(x, y, rgb);
  return sphere::EnvMap(std::move(img), sphere::Mapping(sphere::MappingKind::LatLong, w, h));
}

// Narrow Gaussian lobes exp((cos∠(ω, d) − 1)/s²) of the given colours on black: compact lights whose
// centroids are their directions, smooth enough to resample (rotate) accurately.
inline sphere::EnvMap lobe_probe(int w, int h, const std::vector<Vec3>& dirs, const std::vector<Vec3>& colours,
                                 double s = 0.08) {
  sphere::Mapping m(sphere::MappingKind::LatLong, w, h);
  Image img(w, h, 3, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3 d;
      m.to_direction(x + 0.5, y + 0.5, &d);
      Vec3 L;
      for (size_t i = 0; i < dirs.size(); ++i) {
        double v = std::exp((dot(d, normalize(dirs[i])) - 1) / (s * s));
        if (v > 1e-12) L += colours[i] * v;
      }
      img.set_rgb(x, y, L);
    }
  return sphere::EnvMap(std::move(img), m);
}

inline std::vector<std::string> blender_probes() {
  std::vector<std::string> out;
  const char* dir = "/usr/share/blender/datafiles/studiolights/world";
  if (!std::filesystem::exists(dir)) return out;
  for (auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".exr") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

// A real probe shrunk to w×h lat-long (resample keeps ∫ L dω).
inline sphere::EnvMap small_probe(const std::string& path, int w, int h) {
  auto env = io::read_envmap(path);
  sphere::Mapping m(sphere::MappingKind::LatLong, w, h);
  return sphere::EnvMap(sphere::resample(env, m), m);
}

}  // namespace ibl::lights::testing
