#include "iblkit/lights/light_set.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/core/parallel.h"

namespace ibl::lights {

Vec3 total_irradiance(const LightSet& set) {
  Vec3 s;
  for (const auto& l : set.lights) s += l.irradiance;
  return s;
}

Vec3 LatLongGrid::direction(double px, double py) const {
  double u = px / width, v = py / height;
  double theta = kPi * v, phi = kTwoPi * u;
  double st = std::sin(theta);
  return {-st * std::cos(phi), std::cos(theta), -st * std::sin(phi)};
}

void validate_probe(const sphere::EnvMap& env, int count) {
  const Image& img = env.image;
  if (img.empty()) fail(ErrorKind::Value, "the probe is empty (0 pixels)");
  if (count < 1) fail(ErrorKind::Value, "light count must be at least 1 (got {})", count);
  int nc = std::min(img.channels(), 3);
  bool all_valid = env.mapping.kind() == sphere::MappingKind::LatLong;
  // Per row: lit pixels, and the first bad value (x, channel) if any; rows in parallel.
  struct Row {
    int64_t lit = 0;
    int bad_x = -1, bad_c = 0;
  };
  std::vector<Row> rows(img.height());
  parallel_for(
      0, img.height(),
      [&](int64_t y) {
        Row r;
        for (int x = 0; x < img.width() && r.bad_x < 0; ++x) {
          const float* p = img.pixel(x, static_cast<int>(y));
          bool any = false;
          for (int c = 0; c < nc; ++c) {
            float v = p[c];
            if (!(v >= 0) || !std::isfinite(v)) {
              r.bad_x = x;
              r.bad_c = c;
              break;
            }
            any = any || v > 0;
          }
          if (any && (all_valid || env.mapping.valid(x, static_cast<int>(y)))) ++r.lit;
        }
        rows[y] = r;
      },
      8);
  int64_t lit = 0;
  for (int y = 0; y < img.height(); ++y) {
    const Row& r = rows[y];
    if (r.bad_x >= 0) {
      float v = img.pixel(r.bad_x, y)[r.bad_c];
      fail(ErrorKind::Value,
           "probe pixel ({}, {}) channel {} is {} (reading it with sanitize replaces such values by 0)", r.bad_x, y,
           r.bad_c, std::isfinite(v) ? fmt::format("negative ({})", v) : fmt::format("{}", v));
    }
    lit += r.lit;
  }
  if (lit == 0) fail(ErrorKind::Value, "the probe is all black: there is no light to extract");
  if (count > lit) fail(ErrorKind::Value, "light count {} is larger than the {} pixels that carry light", count, lit);
}

LatLongGrid to_latlong_grid(const sphere::EnvMap& env) {
  LatLongGrid g;
  const Image* img = &env.image;
  Image resampled;
  if (env.mapping.kind() != sphere::MappingKind::LatLong) {
    double px = 0;
    for (int y = 0; y < env.image.height(); ++y)
      for (int x = 0; x < env.image.width(); ++x) px += env.mapping.valid(x, y) ? 1 : 0;
    int h = std::max(8, static_cast<int>(std::lround(std::sqrt(px / 2))));
    resampled = sphere::resample(env, sphere::Mapping(sphere::MappingKind::LatLong, 2 * h, h));
    img = &resampled;
  }
  g.width = img->width();
  g.height = img->height();
  g.rgb.resize(static_cast<size_t>(g.width) * g.height);
  g.row_solid_angle.resize(g.height);
  for (int y = 0; y < g.height; ++y) {
    double c0 = std::cos(kPi * y / g.height), c1 = std::cos(kPi * (y + 1) / g.height);
    g.row_solid_angle[y] = kTwoPi / g.width * (c0 - c1);
  }
  parallel_for(0, g.height, [&](int64_t y) {
    for (int x = 0; x < g.width; ++x) g.rgb[y * g.width + x] = img->rgb(x, static_cast<int>(y));
  });
  return g;
}

double shadow_score(const Light& l) {
  return l.solid_angle > 0 ? luminance(l.irradiance) / l.solid_angle : luminance(l.irradiance) * 1e30;
}

namespace {
// Reorders lights by `order` (new index i takes old order[i]) and relabels the region map.
void reorder(LightSet& set, const std::vector<int>& order, const std::vector<int>& old_to_new) {
  std::vector<Light> out;
  out.reserve(order.size());
  for (int o : order) out.push_back(set.lights[o]);
  set.lights = std::move(out);
  for (auto& lab : set.regions.label)
    if (lab >= 0) lab = old_to_new[lab];
}
}  // namespace

void rank_for_shadows(LightSet& set) {
  int n = static_cast<int>(set.lights.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return shadow_score(set.lights[a]) > shadow_score(set.lights[b]); });
  std::vector<int> old_to_new(n);
  for (int i = 0; i < n; ++i) old_to_new[order[i]] = i;
  reorder(set, order, old_to_new);
}

namespace {
int merge_pass(LightSet& set, double min_separation_rad);
}  // namespace

int merge_close_lights(LightSet& set, double min_separation_rad) {
  if (min_separation_rad <= 0) return 0;
  // A merged light moves to its cluster's mean, which can bring it near another: repeat until stable.
  int total = 0;
  for (int m = merge_pass(set, min_separation_rad); m > 0; m = merge_pass(set, min_separation_rad)) total += m;
  return total;
}

namespace {
int merge_pass(LightSet& set, double min_separation_rad) {
  if (set.lights.size() < 2) return 0;
  double cos_min = std::cos(min_separation_rad);
  int n = static_cast<int>(set.lights.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return luminance(set.lights[a].irradiance) > luminance(set.lights[b].irradiance);
  });
  // Greedy: each light (brightest first) joins the first kept light within the separation.
  std::vector<int> owner(n, -1);
  std::vector<int> kept;
  std::vector<Vec3> wsum;  // Σ Y·direction of each kept cluster
  std::vector<Light> merged;
  int merges = 0;
  for (int i : order) {
    const Light& l = set.lights[i];
    int join = -1;
    for (size_t k = 0; k < kept.size(); ++k)
      if (dot(merged[k].direction, l.direction) > cos_min) {
        join = static_cast<int>(k);
        break;
      }
    double w = std::max(luminance(l.irradiance), 1e-300);
    if (join < 0) {
      owner[i] = static_cast<int>(kept.size());
      kept.push_back(i);
      merged.push_back(l);
      wsum.push_back(l.direction * w);
    } else {
      owner[i] = join;
      merged[join].irradiance += l.irradiance;
      merged[join].solid_angle += l.solid_angle;
      wsum[join] += l.direction * w;
      merged[join].direction = normalize(wsum[join]);
      ++merges;
    }
  }
  set.lights = std::move(merged);
  for (auto& lab : set.regions.label)
    if (lab >= 0) lab = owner[lab];
  return merges;
}
}  // namespace

// ---- JSON ---------------------------------------------------------------------------------------

nlohmann::json to_json(const LightSet& set) {
  nlohmann::json arr = nlohmann::json::array();
  for (const auto& l : set.lights) {
    Vec3 r = l.radiance();
    arr.push_back({{"direction", {l.direction.x, l.direction.y, l.direction.z}},
                   {"irradiance", {l.irradiance.x, l.irradiance.y, l.irradiance.z}},
                   {"solid_angle", l.solid_angle},
                   {"radiance", {r.x, r.y, r.z}}});
    if (l.position) arr.back()["position"] = {l.position->x, l.position->y, l.position->z};
  }
  nlohmann::json j = {{"format", "iblkit.lights/1"}, {"method", set.method}, {"lights", arr}};
  if (set.origin) j["origin"] = {set.origin->x, set.origin->y, set.origin->z};
  return j;
}

namespace {
Vec3 vec3_field(const nlohmann::json& l, const char* key, const std::string& where) {
  if (!l.contains(key)) fail(ErrorKind::Format, "{}: missing \"{}\"", where, key);
  const auto& a = l.at(key);
  if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number())
    fail(ErrorKind::Format, "{}: \"{}\" must be an array of 3 numbers", where, key);
  Vec3 v{a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    fail(ErrorKind::Format, "{}: \"{}\" is not finite", where, key);
  return v;
}
}  // namespace

LightSet from_json(const nlohmann::json& j, const std::string& what) {
  if (!j.is_object() || j.value("format", "") != "iblkit.lights/1")
    fail(ErrorKind::Format, "{}: not an iblkit.lights/1 file (\"format\" is missing or different)", what);
  if (!j.contains("lights") || !j["lights"].is_array())
    fail(ErrorKind::Format, "{}: \"lights\" must be an array", what);
  LightSet set;
  set.method = opt_field(j, what, "method", "file");
  int i = 0;
  for (const auto& l : j["lights"]) {
    std::string where = what + ": lights[" + std::to_string(i++) + "]";
    Light light;
    Vec3 d = vec3_field(l, "direction", where);
    if (length(d) < 1e-12) fail(ErrorKind::Format, "{}: \"direction\" is the zero vector", where);
    light.direction = normalize(d);
    light.irradiance = vec3_field(l, "irradiance", where);
    if (light.irradiance.x < 0 || light.irradiance.y < 0 || light.irradiance.z < 0)
      fail(ErrorKind::Format, "{}: \"irradiance\" is negative", where);
    light.solid_angle = opt_field(l, where, "solid_angle", 0.0);
    if (!(light.solid_angle >= 0) || light.solid_angle > kFourPi + 1e-9)
      fail(ErrorKind::Format, "{}: \"solid_angle\" must be in [0, 4π]", where);
    if (l.contains("position")) light.position = vec3_field(l, "position", where);
    set.lights.push_back(light);
  }
  if (set.lights.empty()) fail(ErrorKind::Format, "{}: \"lights\" is empty", what);
  if (j.contains("origin")) set.origin = vec3_field(j, "origin", what);
  return set;
}

void write_lights(const std::string& path, const LightSet& set) { write_json_file(path, to_json(set), 2); }

LightSet read_lights(const std::string& path) { return from_json(read_json_file(path), path); }

}  // namespace ibl::lights
