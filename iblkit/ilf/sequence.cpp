#include "iblkit/ilf/sequence.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"

namespace ibl::ilf {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

Vec3 vec3_field(const json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 3) fail(ErrorKind::Format, "{}: expected an array of 3 numbers", what);
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    if (!j[i].is_number()) fail(ErrorKind::Format, "{}: element {} is not a number", what, i);
    v[i] = j[i].get<double>();
    if (!std::isfinite(v[i])) fail(ErrorKind::Value, "{}: element {} is not finite", what, i);
  }
  return v;
}

}  // namespace

Sequence read_sequence(const std::string& path, const SequenceReadDesc& desc, SequenceReport* report) {
  const json j = read_json_file(path);
  require_format(j, path, "iblkit.sequence/1");
  Sequence seq;
  seq.manifest = path;
  std::string mapping = opt_field(j, path, "mapping", "mirrorball");
  auto kind = sphere::find_mapping(mapping);
  if (!kind) fail(ErrorKind::Format, "{}: field \"mapping\": unknown mapping \"{}\"", path, mapping);
  seq.mapping = *kind;
  if (j.contains("scene") && j["scene"].is_string()) seq.scene = j["scene"].get<std::string>();
  if (j.contains("dead_angle_deg")) {
    if (!j["dead_angle_deg"].is_number()) fail(ErrorKind::Format, "{}: field \"dead_angle_deg\" is not a number", path);
    seq.dead_angle_deg = j["dead_angle_deg"].get<double>();
    if (!(seq.dead_angle_deg >= 0 && seq.dead_angle_deg < 90))
      fail(ErrorKind::Value, "{}: field \"dead_angle_deg\" = {} is outside [0, 90)", path, seq.dead_angle_deg);
  }
  for (const char* key : {"ball_radius", "ball_distance"}) {
    if (!j.contains(key)) continue;
    if (!j[key].is_number()) fail(ErrorKind::Format, "{}: field \"{}\" is not a number", path, key);
    double v = j[key].get<double>();
    if (!(v >= 0 && v <= 100)) fail(ErrorKind::Value, "{}: field \"{}\" = {} is outside [0, 100] metres", path, key, v);
    (std::string(key) == "ball_radius" ? seq.ball.radius : seq.ball.distance) = v;
  }
  if ((seq.ball.radius > 0 || seq.ball.distance > 0) && seq.mapping != sphere::MappingKind::MirrorBall)
    fail(ErrorKind::Value, "{}: fields \"ball_radius\"/\"ball_distance\" need the mirrorball mapping, not {}", path,
         mapping);
  if (seq.ball.distance > 0 && !(seq.ball.distance > seq.ball.radius && seq.ball.radius > 0))
    fail(ErrorKind::Value, "{}: field \"ball_distance\" = {} needs a \"ball_radius\" > 0 below it (got {})", path,
         seq.ball.distance, seq.ball.radius);
  if (j.contains("rotation")) {
    const auto& r = j["rotation"];
    if (!r.is_array() || r.size() != 3) fail(ErrorKind::Format, "{}: field \"rotation\" must be 3 rows of 3", path);
    seq.rotation = Mat3::rows(vec3_field(r[0], path + ": rotation[0]"), vec3_field(r[1], path + ": rotation[1]"),
                              vec3_field(r[2], path + ": rotation[2]"));
    Mat3 rr = seq.rotation * seq.rotation.transposed();
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (std::abs(rr.m[a][b] - (a == b ? 1.0 : 0.0)) > 1e-4)
          fail(ErrorKind::Value, "{}: field \"rotation\" is not a rotation matrix (R·Rᵀ ≠ I)", path);
  }
  if (!j.contains("probes") || !j["probes"].is_array())
    fail(ErrorKind::Format, "{}: field \"probes\" is missing or not an array", path);
  fs::path base = fs::path(path).parent_path();
  for (size_t i = 0; i < j["probes"].size(); ++i) {
    const auto& p = j["probes"][i];
    std::string where = fmt::format("{}: probe {}", path, i);
    if (!p.is_object()) fail(ErrorKind::Format, "{}: not an object", where);
    if (!p.contains("image") || !p["image"].is_string())
      fail(ErrorKind::Format, "{}: field \"image\" is missing", where);
    if (!p.contains("position")) fail(ErrorKind::Format, "{}: field \"position\" is missing", where);
    ProbeEntry e;
    fs::path img = p["image"].get<std::string>();
    e.image = (img.is_absolute() ? img : base / img).lexically_normal().string();
    if (p.contains("depth") && p["depth"].is_string()) {
      fs::path dep = p["depth"].get<std::string>();
      e.depth = (dep.is_absolute() ? dep : base / dep).lexically_normal().string();
    }
    try {
      e.position = vec3_field(p["position"], where + ": field \"position\"");
    } catch (const Error&) {
      if (!desc.skip_bad) throw;
      if (report) {
        ++report->skipped;
        report->reasons.push_back(where + ": bad \"position\"");
      }
      continue;
    }
    seq.probes.push_back(e);
  }
  if (seq.probes.empty()) fail(ErrorKind::Value, "{}: the sequence has no probes", path);
  if (j.contains("volume")) {
    seq.volume = {vec3_field(j["volume"].value("min", json()), path + ": volume.min"),
                  vec3_field(j["volume"].value("max", json()), path + ": volume.max")};
    seq.volume_given = true;
    for (int a = 0; a < 3; ++a)
      if (!(seq.volume.max[a] > seq.volume.min[a]))
        fail(ErrorKind::Value, "{}: field \"volume\": max must exceed min on every axis", path);
  }
  // Probes outside the volume and duplicated positions.
  std::map<std::tuple<double, double, double>, size_t> seen;
  std::vector<ProbeEntry> kept;
  for (size_t i = 0; i < seq.probes.size(); ++i) {
    const auto& e = seq.probes[i];
    std::string problem;
    if (seq.volume_given && !seq.volume.contains(e.position, desc.position_slack))
      problem = fmt::format("field \"position\" ({}, {}, {}) lies outside the volume", e.position.x, e.position.y,
                            e.position.z);
    auto key = std::make_tuple(e.position.x, e.position.y, e.position.z);
    if (problem.empty()) {
      auto it = seen.find(key);
      if (it != seen.end()) problem = fmt::format("field \"position\" duplicates probe {}", it->second);
    }
    if (!problem.empty()) {
      std::string msg = fmt::format("{}: probe {} ({}): {}", path, i, e.image, problem);
      if (!desc.skip_bad) fail(ErrorKind::Value, "{} (skip_bad drops such probes)", msg);
      if (report) {
        ++report->skipped;
        report->reasons.push_back(msg);
      }
      continue;
    }
    seen.emplace(key, i);
    kept.push_back(e);
  }
  seq.probes = std::move(kept);
  if (seq.probes.empty()) fail(ErrorKind::Value, "{}: no probes left after dropping bad ones", path);
  if (!seq.volume_given) {
    Box b{seq.probes[0].position, seq.probes[0].position};
    for (const auto& e : seq.probes)
      for (int a = 0; a < 3; ++a) {
        b.min[a] = std::min(b.min[a], e.position[a]);
        b.max[a] = std::max(b.max[a], e.position[a]);
      }
    for (int a = 0; a < 3; ++a)
      if (b.max[a] - b.min[a] <= 0)
        fail(ErrorKind::Value, "{}: the probe positions are flat on axis {}; give a \"volume\"", path, "xyz"[a]);
    seq.volume = b;
  }
  return seq;
}

void write_sequence(const std::string& path, const Sequence& seq) {
  fs::path base = fs::absolute(fs::path(path)).parent_path();
  auto relative = [&](const std::string& file) {
    fs::path f = fs::absolute(file);
    auto rel = f.lexically_relative(base);
    return (!rel.empty() && *rel.begin() != "..") ? rel.generic_string() : f.generic_string();
  };
  json probes = json::array();
  for (const auto& e : seq.probes) {
    json p = {{"image", relative(e.image)}, {"position", {e.position.x, e.position.y, e.position.z}}};
    if (!e.depth.empty()) p["depth"] = relative(e.depth);
    probes.push_back(p);
  }
  json rot = json::array();
  for (int r = 0; r < 3; ++r) rot.push_back({seq.rotation.m[r][0], seq.rotation.m[r][1], seq.rotation.m[r][2]});
  json j = {{"format", "iblkit.sequence/1"},
            {"mapping", sphere::mapping_name(seq.mapping)},
            {"dead_angle_deg", seq.dead_angle_deg},
            {"rotation", rot},
            {"volume",
             {{"min", {seq.volume.min.x, seq.volume.min.y, seq.volume.min.z}},
              {"max", {seq.volume.max.x, seq.volume.max.y, seq.volume.max.z}}}},
            {"probes", probes}};
  if (!seq.scene.empty()) j["scene"] = seq.scene;
  if (seq.ball.radius > 0) j["ball_radius"] = seq.ball.radius;
  if (seq.ball.distance > 0) j["ball_distance"] = seq.ball.distance;
  write_json_file(path, j);
}

}  // namespace ibl::ilf
