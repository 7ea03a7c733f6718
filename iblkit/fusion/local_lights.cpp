#include "iblkit/fusion/local_lights.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/lights/cut.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/lights/place.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::fusion {

lights::LightSet localize_lights(const LocalMap& map, const LocalLightsDesc& desc) {
  const sphere::Mapping& m = map.radiance.mapping;
  if (m.kind() != sphere::MappingKind::LatLong)
    fail(ErrorKind::Value, "localize_lights: the fused map must be lat-long (got {})", sphere::mapping_name(m.kind()));
  lights::LatLongGrid grid = lights::to_latlong_grid(map.radiance);
  lights::CutDesc cd;
  cd.count = desc.count;
  cd.min_separation_deg = desc.min_separation_deg;
  lights::LightSet set = lights::median_cut(grid, cd);
  lights::place_by_depth(set, grid, map.point, [&](int x, int y) { return double(map.depth.at(x, y, 0)); });
  set.method = "fusion-" + set.method;
  return set;
}

// ---- paths ------------------------------------------------------------------------------------

std::vector<PathPoint> read_path(const std::string& path) {
  const nlohmann::json j = read_json_file(path);
  const nlohmann::json* pts = &j;
  if (j.is_object()) {
    require_format(j, path, "iblkit.path/1");
    if (!j.contains("points")) fail(ErrorKind::Format, "{}: field \"points\" is missing", path);
    pts = &j["points"];
  }
  if (!pts->is_array() || pts->empty()) fail(ErrorKind::Format, "{}: the points must be a non-empty array", path);
  auto vec = [&](const nlohmann::json& a, const std::string& where) {
    if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number())
      fail(ErrorKind::Format, "{}: {} must be an array of 3 numbers", path, where);
    Vec3 v{a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      fail(ErrorKind::Format, "{}: {} is not finite", path, where);
    return v;
  };
  std::vector<PathPoint> out;
  int timed = 0;
  for (size_t k = 0; k < pts->size(); ++k) {
    const auto& p = (*pts)[k];
    std::string where = fmt::format("points[{}]", k);
    PathPoint q;
    if (p.is_object()) {
      if (!p.contains("position")) fail(ErrorKind::Format, "{}: {}: field \"position\" is missing", path, where);
      q.position = vec(p["position"], where + ".position");
      if (p.contains("time")) {
        if (!p["time"].is_number()) fail(ErrorKind::Format, "{}: {}.time must be a number", path, where);
        q.time = p["time"].get<double>();
        ++timed;
      }
    } else {
      q.position = vec(p, where);
    }
    out.push_back(q);
  }
  if (timed != 0 && timed != static_cast<int>(out.size()))
    fail(ErrorKind::Format, "{}: \"time\" must be on every point or on none ({} of {} have it)", path, timed,
         out.size());
  for (size_t k = 0; k < out.size(); ++k) {
    if (timed == 0) out[k].time = static_cast<double>(k);
    if (k > 0 && !(out[k].time > out[k - 1].time))
      fail(ErrorKind::Value, "{}: times must increase (points[{}].time = {} after {})", path, k, out[k].time,
           out[k - 1].time);
  }
  return out;
}

std::vector<int> assign_min_cost(const std::vector<double>& cost, int rows, int cols) {
  if (static_cast<int64_t>(cost.size()) != static_cast<int64_t>(rows) * cols)
    fail(ErrorKind::Internal, "assign_min_cost: {} costs for a {}×{} matrix", cost.size(), rows, cols);
  std::vector<int> result(rows, -1);
  if (rows == 0 || cols == 0) return result;
  if (rows > cols) {  // solve the transpose (every column gets a row)
    std::vector<double> t(cost.size());
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) t[static_cast<size_t>(c) * rows + r] = cost[static_cast<size_t>(r) * cols + c];
    std::vector<int> back = assign_min_cost(t, cols, rows);
    for (int c = 0; c < cols; ++c)
      if (back[c] >= 0) result[back[c]] = c;
    return result;
  }
  // Shortest augmenting paths with row/column potentials u, v (Kuhn–Munkres, O(rows²·cols)); 1-based.
  const double inf = std::numeric_limits<double>::infinity();
  int n = rows, m = cols;
  std::vector<double> u(n + 1, 0), v(m + 1, 0);
  std::vector<int> match(m + 1, 0), way(m + 1, 0);  // match[j]: the row in column j (0: none)
  auto a = [&](int i, int j) { return cost[static_cast<size_t>(i - 1) * m + (j - 1)]; };
  for (int i = 1; i <= n; ++i) {
    match[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<char> used(m + 1, 0);
    do {
      used[j0] = 1;
      int i0 = match[j0], j1 = 0;
      double delta = inf;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        double cur = a(i0, j) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[match[j]] += delta;
          v[j] -= delta;
        } else
          minv[j] -= delta;
      }
      j0 = j1;
    } while (match[j0] != 0);
    do {
      int j1 = way[j0];
      match[j0] = match[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  for (int j = 1; j <= m; ++j)
    if (match[j] > 0) result[match[j] - 1] = j - 1;
  return result;
}

lights::LightSet LightTracker::update(const lights::LightSet& raw, double dt) {
  Vec3 origin = raw.origin.value_or(Vec3{});
  int m = static_cast<int>(raw.lights.size());
  // Tracks' directions as seen from this frame's origin.
  for (Track& t : tracks_)
    if (t.position && raw.origin) t.direction = normalize(*t.position - origin);
  int n = static_cast<int>(tracks_.size());
  std::vector<double> cost(static_cast<size_t>(n) * m);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < m; ++b) {
      double ya = luminance(tracks_[a].irradiance) + 1e-12, yb = luminance(raw.lights[b].irradiance) + 1e-12;
      cost[static_cast<size_t>(a) * m + b] =
          1 - dot(tracks_[a].direction, raw.lights[b].direction) + 0.5 * std::abs(std::log(ya / yb));
    }
  std::vector<int> of_track = assign_min_cost(cost, n, m);
  std::vector<int> track_of(m, -1);
  for (int a = 0; a < n; ++a)
    if (of_track[a] >= 0) track_of[of_track[a]] = a;
  double alpha = desc_.filter ? 1 - std::exp(-std::max(dt, 0.0) / std::max(desc_.time_constant, 1e-12)) : 1.0;
  std::vector<Track> next;
  lights::LightSet out = raw;
  out.method = raw.method + "+tracked";
  ids_.assign(m, -1);
  double y_raw = 0, y_filt = 0;
  for (int b = 0; b < m; ++b) {
    const lights::Light& l = raw.lights[b];
    Track t;
    if (track_of[b] < 0) {
      t = {next_id_++, l.direction, l.irradiance, l.position, l.solid_angle};
    } else {
      t = tracks_[track_of[b]];
      if (l.position && t.position) {
        t.position = *t.position + (*l.position - *t.position) * alpha;
        t.direction =
            raw.origin ? normalize(*t.position - origin) : normalize(t.direction + (l.direction - t.direction) * alpha);
      } else {
        t.position = l.position;
        t.direction = normalize(t.direction + (l.direction - t.direction) * alpha);
      }
      t.irradiance = t.irradiance + (l.irradiance - t.irradiance) * alpha;
      t.solid_angle = l.solid_angle;
    }
    y_raw += luminance(l.irradiance);
    y_filt += luminance(t.irradiance);
    ids_[b] = t.id;
    next.push_back(t);
  }
  double scale = y_filt > 0 ? y_raw / y_filt : 1.0;
  for (int b = 0; b < m; ++b) {
    next[b].irradiance *= scale;
    out.lights[b].direction = next[b].direction;
    out.lights[b].irradiance = next[b].irradiance;
    out.lights[b].position = next[b].position;
    out.lights[b].solid_angle = next[b].solid_angle;
  }
  out.regions = {};
  tracks_ = std::move(next);
  return out;
}

namespace {

const std::vector<Vec3>& flicker_normals() {
  static const std::vector<Vec3> n = sphere::icosphere_face_centres(3);
  return n;
}

std::vector<double> lum(const std::vector<Vec3>& e) {
  std::vector<double> y(e.size());
  for (size_t i = 0; i < e.size(); ++i) y[i] = luminance(e[i]);
  return y;
}

double rel_rms(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& ref) {
  double s2 = 0, m = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    s2 += (a[i] - b[i]) * (a[i] - b[i]);
    m += ref[i];
  }
  m /= a.size();
  return m > 0 ? std::sqrt(s2 / a.size()) / m : 0.0;
}

FlickerStats flicker_of(const std::vector<std::vector<double>>& fields) {
  FlickerStats f;
  for (size_t k = 1; k < fields.size(); ++k) {
    double v = rel_rms(fields[k], fields[k - 1], fields[k]);
    f.mean += v;
    f.max = std::max(f.max, v);
  }
  if (fields.size() > 1) f.mean /= static_cast<double>(fields.size() - 1);
  return f;
}

}  // namespace

FlickerStats light_flicker(const std::vector<lights::LightSet>& frames) {
  std::vector<std::vector<double>> fields;
  for (const auto& s : frames) fields.push_back(lum(lights::irradiance_from_lights(s.lights, flicker_normals())));
  return flicker_of(fields);
}

FlickerStats map_flicker(const std::vector<sphere::EnvMap>& maps) {
  std::vector<std::vector<double>> fields;
  for (const auto& m : maps) fields.push_back(lum(lights::irradiance_ground_truth(m, flicker_normals())));
  return flicker_of(fields);
}

double excess_flicker(const std::vector<lights::LightSet>& frames, const std::vector<sphere::EnvMap>& maps) {
  if (frames.size() != maps.size())
    fail(ErrorKind::Internal, "excess_flicker: {} light sets for {} maps", frames.size(), maps.size());
  std::vector<std::vector<double>> e, m;
  for (size_t k = 0; k < frames.size(); ++k) {
    e.push_back(lum(lights::irradiance_from_lights(frames[k].lights, flicker_normals())));
    m.push_back(lum(lights::irradiance_ground_truth(maps[k], flicker_normals())));
  }
  double sum = 0;
  for (size_t k = 1; k < frames.size(); ++k) {
    std::vector<double> a(e[k].size()), b(e[k].size(), 0.0);
    for (size_t i = 0; i < a.size(); ++i) a[i] = (e[k][i] - e[k - 1][i]) - (m[k][i] - m[k - 1][i]);
    sum += rel_rms(a, b, m[k]);
  }
  return frames.size() > 1 ? sum / (frames.size() - 1) : 0.0;
}

double shadow_light_jitter(const std::vector<lights::LightSet>& frames, const std::vector<std::vector<int>>& ids,
                           int count) {
  if (frames.size() != ids.size())
    fail(ErrorKind::Internal, "shadow_light_jitter: {} light sets for {} id lists", frames.size(), ids.size());
  double sum = 0;
  int pairs = 0;
  for (size_t k = 1; k < frames.size(); ++k) {
    double a = 0, w = 0;
    for (int j = 0; j < count && j < static_cast<int>(frames[k].lights.size()); ++j) {
      for (size_t q = 0; q < ids[k - 1].size(); ++q) {
        if (ids[k - 1][q] != ids[k][j]) continue;
        double y = luminance(frames[k].lights[j].irradiance);
        double c = std::clamp(dot(frames[k].lights[j].direction, frames[k - 1].lights[q].direction), -1.0, 1.0);
        a += y * std::acos(c);
        w += y;
      }
    }
    if (w > 0) {
      sum += a / w;
      ++pairs;
    }
  }
  return pairs ? sum / pairs : 0.0;
}

double lights_vs_maps(const std::vector<lights::LightSet>& frames, const std::vector<sphere::EnvMap>& maps) {
  if (frames.size() != maps.size())
    fail(ErrorKind::Internal, "lights_vs_maps: {} light sets for {} maps", frames.size(), maps.size());
  double sum = 0;
  for (size_t k = 0; k < frames.size(); ++k) {
    auto e = lum(lights::irradiance_from_lights(frames[k].lights, flicker_normals()));
    auto g = lum(lights::irradiance_ground_truth(maps[k], flicker_normals()));
    sum += rel_rms(e, g, g);
  }
  return frames.empty() ? 0 : sum / frames.size();
}

}  // namespace ibl::fusion
