#include "iblkit/ilf/threejs_grid.h"

#include <bit>
#include <cstring>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"

namespace ibl::ilf {

ThreeGrid to_threejs_grid(const SHGrid& g) {
  const GridDesc& gd = g.grid();
  if (g.bands() < 1 || g.data().empty()) fail(ErrorKind::Value, "three.js grid export: the grid has no coefficients");
  if (gd.nx < 2 || gd.ny < 2 || gd.nz < 2)
    fail(ErrorKind::Value, "three.js grid export: the grid needs at least 2 points per axis");
  ThreeGrid t;
  t.nx = gd.nx;
  t.ny = gd.ny;
  t.nz = gd.nz;
  Vec3 ext = gd.volume.size();
  t.size = {ext.x * gd.nx / (gd.nx - 1), ext.y * gd.ny / (gd.ny - 1), ext.z * gd.nz / (gd.nz - 1)};
  t.center = gd.volume.centre();
  const int K = g.coeff_count(), K3 = std::min(K, 9);
  const int padded = t.nz + 2 * kThreeAtlasPadding;
  t.atlas.assign(size_t(t.nx) * t.ny * t.depth() * 4, 0.0f);
  float flat[28];
  for (int k = 0; k < t.nz; ++k)
    for (int j = 0; j < t.ny; ++j)
      for (int i = 0; i < t.nx; ++i) {
        std::memset(flat, 0, sizeof flat);
        std::memcpy(flat, g.at(i, j, k), sizeof(float) * 3 * K3);  // coefficient-major, then channel
        for (int v = 0; v < kThreeAtlasVolumes; ++v) {
          auto put = [&](int slice) {
            std::memcpy(&t.atlas[((size_t(slice) * t.ny + j) * t.nx + i) * 4], flat + 4 * v, 4 * sizeof(float));
          };
          int base = v * padded;
          put(base + kThreeAtlasPadding + k);
          if (k == 0) put(base);
          if (k == t.nz - 1) put(base + kThreeAtlasPadding + t.nz);
        }
      }
  return t;
}

nlohmann::json threejs_grid_header(const ThreeGrid& t, const SHGrid& g, const std::string& atlas_file) {
  const auto& v = g.grid().volume;
  return {
      {"format", "iblkit.threejs-grid/1"},
      {"three", "LightProbeGridWebGL (three r187): assign the atlas to .texture"},
      {"resolution", {t.nx, t.ny, t.nz}},
      {"center", {t.center.x, t.center.y, t.center.z}},
      {"size", {t.size.x, t.size.y, t.size.z}},
      {"atlas",
       {{"file", atlas_file},
        {"width", t.nx},
        {"height", t.ny},
        {"depth", t.depth()},
        {"type", "float32"},
        {"channels", 4}}},
      {"source", {{"min", {v.min.x, v.min.y, v.min.z}}, {"max", {v.max.x, v.max.y, v.max.z}}, {"bands", g.bands()}}}};
}

std::string write_threejs_grid(const SHGrid& g, const std::string& dir, const std::string& name) {
  static_assert(std::endian::native == std::endian::little, "the atlas is written as little-endian float32");
  ThreeGrid t = to_threejs_grid(g);
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) fail(ErrorKind::Io, "{}: cannot create the folder ({})", dir, ec.message());
  std::string atlas = name + "_atlas.bin";
  write_file_atomically(
      (fs::path(dir) / atlas).string(),
      std::string_view(reinterpret_cast<const char*>(t.atlas.data()), t.atlas.size() * sizeof(float)));
  std::string json = (fs::path(dir) / (name + ".json")).string();
  write_json_file(json, threejs_grid_header(t, g, atlas), 2);
  return json;
}

}  // namespace ibl::ilf
