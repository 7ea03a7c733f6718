#include "iblkit/fusion/probe_set.h"

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/core/parallel.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::fusion {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

Vec3 vec3_field(const json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    fail(ErrorKind::Format, "{} must be an array of 3 numbers", what);
  Vec3 v{j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    fail(ErrorKind::Format, "{} is not finite", what);
  return v;
}

Mat3 rotation_field(const json& r, const std::string& what) {
  if (!r.is_array() || r.size() != 3) fail(ErrorKind::Format, "{} must be 3 rows of 3 numbers", what);
  Mat3 m = Mat3::rows(vec3_field(r[0], what + "[0]"), vec3_field(r[1], what + "[1]"), vec3_field(r[2], what + "[2]"));
  Mat3 rr = m * m.transposed();
  constexpr double kOrthoTol = 1e-4;  // rotations written with ~6 decimals still pass
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      if (std::abs(rr.m[i][k] - (i == k ? 1.0 : 0.0)) > kOrthoTol)
        fail(ErrorKind::Value, "{} is not a rotation matrix (R·Rᵀ ≠ I)", what);
  return m;
}

// Depth maps: one channel of finite, non-negative metres.
Image read_depth(const std::string& path) {
  io::ReadDesc rd;
  rd.max_channels = 1;
  Image d = io::read_image(path, rd);
  for (int y = 0; y < d.height(); ++y)
    for (int x = 0; x < d.width(); ++x) {
      float v = d.at(x, y, 0);
      if (!std::isfinite(v) || v < 0)
        fail(ErrorKind::Value, "depth map {}: pixel ({}, {}) is {} (depths are metres ≥ 0, 0 = no surface)", path, x, y,
             v);
    }
  return d;
}

bool newer_or_same(const fs::path& a, const fs::path& b) {
  std::error_code e1, e2;
  auto ta = fs::last_write_time(a, e1), tb = fs::last_write_time(b, e2);
  return !e1 && !e2 && ta >= tb;
}

// Share of the valid solid angle of a probe whose depth is 0 (rays that leave the proxy).
double escape_share(const Probe& p) {
  const sphere::Mapping& m = p.radiance.mapping;
  double esc = 0, all = 0;
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) {
      if (!m.valid(x, y)) continue;
      double w = m.solid_angle_estimate(x, y);
      all += w;
      if (p.depth.at(x, y, 0) <= 0) esc += w;
    }
  return all > 0 ? esc / all : 0;
}

std::string probe_name(const Probe& p, size_t k) {
  return p.image.empty() ? fmt::format("probe {}", k) : fmt::format("probe {} ({})", k, p.image);
}

}  // namespace

std::string depth_cache_path(const std::string& image) {
  fs::path p(image);
  return (p.parent_path() / (p.stem().string() + "_proxydepth.exr")).string();
}

Image trace_depth(const geometry::RayTracer& tracer, const sphere::Mapping& m, Vec3 position, const Mat3& rotation) {
  Image depth(m.width(), m.height(), 1);
  parallel_for(0, m.height(), [&](int64_t y) {
    for (int x = 0; x < m.width(); ++x) {
      Vec3 d;
      if (!m.to_direction(x + 0.5, y + 0.5, &d)) continue;
      geometry::Hit h = tracer.intersect(position, rotation * d);
      if (h.hit) depth.at(x, static_cast<int>(y), 0) = static_cast<float>(h.t);
    }
  });
  return depth;
}

PointCheck check_point(const ProbeSet& set, Vec3 x, int rays) {
  if (!set.tracer) fail(ErrorKind::Internal, "check_point: the probe set is not prepared");
  require_point("the point", x);
  auto dirs = sphere::fibonacci_sphere(rays);
  int back = 0, hit = 0;
  for (Vec3 d : dirs) {
    geometry::Hit h = set.tracer->intersect(x, d);
    if (!h.hit) continue;
    ++hit;
    if (dot(set.proxy.normal(h.triangle), d) > 0) ++back;
  }
  PointCheck c;
  c.escape = 1.0 - static_cast<double>(hit) / rays;
  c.backface = hit ? static_cast<double>(back) / hit : 0.0;
  return c;
}

void prepare(ProbeSet& set, const ProgressFn& progress) {
  std::string what = set.manifest.empty() ? std::string("probe set") : set.manifest;
  if (set.probes.empty()) fail(ErrorKind::Value, "{}: no probes", what);
  if (set.proxy.triangle_count() == 0) fail(ErrorKind::Value, "{}: the proxy mesh has no triangles", what);
  set.proxy.validate(what + ": proxy");
  auto build = [&] {
    set.tracer = std::make_shared<geometry::RayTracer>();
    set.tracer->add(set.proxy);
    set.tracer->commit();
  };
  build();
  // Inside/outside first (cheap), so that an inside-out proxy is flipped before anything else.
  std::vector<PointCheck> checks;
  for (const auto& p : set.probes) checks.push_back(check_point(set, p.position));
  bool all_back = std::all_of(checks.begin(), checks.end(), [](const PointCheck& c) { return c.backface > 0.5; });
  if (all_back) {
    set.proxy.flip();
    build();
    set.warnings.push_back(fmt::format(
        "{}: every probe sees the back of the proxy's faces: the proxy was turned inside out and has been flipped "
        "(front faces must face the probes)",
        what));
    checks.clear();
    for (const auto& p : set.probes) checks.push_back(check_point(set, p.position));
  }
  for (size_t k = 0; k < set.probes.size(); ++k) {
    const Probe& p = set.probes[k];
    if (checks[k].backface > 0.5)
      fail(ErrorKind::Value,
           "{}: {} at ({}, {}, {}) is outside the proxy or inside geometry ({:.0f}% of its rays reach the back of a "
           "proxy face)",
           what, probe_name(p, k), p.position.x, p.position.y, p.position.z, 100 * checks[k].backface);
    if (checks[k].escape >= 1.0)
      fail(ErrorKind::Value, "{}: {} at ({}, {}, {}) sees no proxy geometry at all (every ray leaves it)", what,
           probe_name(p, k), p.position.x, p.position.y, p.position.z);
  }
  // Depth maps: trace the missing ones (in parallel inside each probe), check the sizes of the others.
  std::atomic<size_t> done{0};
  size_t todo = 0;
  for (const auto& p : set.probes) todo += p.depth.empty();
  for (size_t k = 0; k < set.probes.size(); ++k) {
    Probe& p = set.probes[k];
    const sphere::Mapping& m = p.radiance.mapping;
    if (p.depth.empty()) {
      p.depth = trace_depth(*set.tracer, m, p.position, p.rotation);
      p.depth_source = DepthSource::Computed;
      report(progress, "depth", static_cast<double>(++done) / todo);
    } else if (p.depth.width() != m.width() || p.depth.height() != m.height()) {
      fail(ErrorKind::Value,
           "{}: {}: its depth map {} is {}×{} but the probe is {}×{} (they must match pixel for pixel)", what,
           probe_name(p, k), p.depth_file.empty() ? std::string("(in memory)") : p.depth_file, p.depth.width(),
           p.depth.height(), m.width(), m.height());
    }
    if (p.radiance.image.channels() != 3) p.radiance.image = p.radiance.image.with_channels(3);
    p.rgbd.clear();
    if (m.kind() == sphere::MappingKind::LatLong) {
      p.rgbd.resize(p.radiance.image.pixel_count() * 4);
      const float* rgb = p.radiance.image.data();
      const float* dep = p.depth.data();
      for (size_t i = 0; i < p.radiance.image.pixel_count(); ++i) {
        p.rgbd[4 * i] = rgb[3 * i];
        p.rgbd[4 * i + 1] = rgb[3 * i + 1];
        p.rgbd[4 * i + 2] = rgb[3 * i + 2];
        p.rgbd[4 * i + 3] = dep[i];
      }
    }
    p.escape_fraction = escape_share(p);
    constexpr double kEscapeWarn = 1e-3;  // a few stray texels through shared edges are not an opening
    if (p.escape_fraction > kEscapeWarn)
      set.warnings.push_back(fmt::format(
          "{}: the proxy is not closed: {:.1f}% of {}'s directions leave it (fused rays there fall back to the "
          "distant lookup; see the coverage map)",
          what, 100 * p.escape_fraction, probe_name(p, k)));
  }
}

ProbeSet load_probe_set(const std::string& manifest, const LoadDesc& desc) {
  const json j = read_json_file(manifest);
  require_format(j, manifest, "iblkit.probes/1");
  if (!j.contains("proxy") || !j["proxy"].is_string())
    fail(ErrorKind::Format, "{}: field \"proxy\" (the proxy mesh file) is missing", manifest);
  if (!j.contains("probes") || !j["probes"].is_array() || j["probes"].empty())
    fail(ErrorKind::Format, "{}: field \"probes\" must be a non-empty array", manifest);
  fs::path base = fs::path(manifest).parent_path();
  ProbeSet set;
  set.manifest = manifest;
  fs::path proxy_path = base / j["proxy"].get<std::string>();
  set.proxy = geometry::read_mesh(proxy_path.string());
  io::EnvReadDesc rd;
  if (j.contains("mapping")) {
    if (!j["mapping"].is_string()) fail(ErrorKind::Format, "{}: field \"mapping\" must be a string", manifest);
    auto k = sphere::find_mapping(j["mapping"].get<std::string>());
    if (!k) fail(ErrorKind::Format, "{}: unknown mapping \"{}\"", manifest, j["mapping"].get<std::string>());
    rd.mapping = *k;
  }
  rd.dead_angle_deg = opt_field(j, manifest, "dead_angle_deg", 0.0);
  std::vector<bool> write_cache;
  size_t n = j["probes"].size();
  for (size_t k = 0; k < n; ++k) {
    const json& pj = j["probes"][k];
    std::string where = fmt::format("{}: probes[{}]", manifest, k);
    if (!pj.is_object() || !pj.contains("image") || !pj["image"].is_string())
      fail(ErrorKind::Format, "{}: field \"image\" is missing", where);
    if (!pj.contains("position")) fail(ErrorKind::Format, "{}: field \"position\" is missing", where);
    Probe p;
    p.image = (base / pj["image"].get<std::string>()).string();
    p.position = vec3_field(pj["position"], where + ": field \"position\"");
    require_point(where + ": field \"position\"", p.position);
    if (pj.contains("rotation")) p.rotation = rotation_field(pj["rotation"], where + ": field \"rotation\"");
    p.radiance = io::read_envmap(p.image, rd);
    bool trace = desc.force_depth;
    if (!trace && desc.use_depth_files && pj.contains("depth")) {
      if (!pj["depth"].is_string()) fail(ErrorKind::Format, "{}: field \"depth\" must be a file name", where);
      p.depth_file = (base / pj["depth"].get<std::string>()).string();
      p.depth = read_depth(p.depth_file);
      p.depth_source = DepthSource::File;
    } else if (!trace && desc.use_cache && fs::exists(depth_cache_path(p.image)) &&
               newer_or_same(depth_cache_path(p.image), proxy_path) &&
               newer_or_same(depth_cache_path(p.image), p.image) &&
               newer_or_same(depth_cache_path(p.image), manifest)) {
      p.depth_file = depth_cache_path(p.image);
      p.depth = read_depth(p.depth_file);
      p.depth_source = DepthSource::Cache;
      const auto& m = p.radiance.mapping;
      if (p.depth.width() != m.width() || p.depth.height() != m.height()) {
        set.warnings.push_back(fmt::format("{}: cached depth {} is {}×{}, the probe {}×{}: traced again", where,
                                           p.depth_file, p.depth.width(), p.depth.height(), m.width(), m.height()));
        p.depth = Image();
      }
    }
    bool traced = p.depth.empty();
    if (traced && desc.write_cache) {
      // force_depth rewrites the file the manifest names; otherwise the cache beside the probe.
      p.depth_file = desc.force_depth && pj.contains("depth") && pj["depth"].is_string()
                         ? (base / pj["depth"].get<std::string>()).string()
                         : depth_cache_path(p.image);
    }
    write_cache.push_back(traced && desc.write_cache);
    set.probes.push_back(std::move(p));
    report(desc.progress, "load", static_cast<double>(k + 1) / n);
  }
  prepare(set, desc.progress);
  for (size_t k = 0; k < set.probes.size(); ++k)
    if (write_cache[k]) io::write_image(set.probes[k].depth_file, set.probes[k].depth);
  return set;
}

}  // namespace ibl::fusion
