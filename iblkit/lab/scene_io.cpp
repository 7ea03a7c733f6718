#include "iblkit/lab/scene_io.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <fmt/ranges.h>

#include <nlohmann/json.hpp>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"

namespace ibl::lab {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Ctx {
  std::string file;   // for messages
  fs::path dir;       // relative paths start here
  std::string where;  // "surfaces[2]"
  std::string rel(const std::string& p) const { return fs::path(p).is_absolute() ? p : (dir / p).string(); }
  [[noreturn]] void bad(const std::string& field, const std::string& why) const {
    if (where.empty()) fail(ErrorKind::Format, "{}: {}: {}", file, field, why);
    fail(ErrorKind::Format, "{}: {}.{}: {}", file, where, field, why);
  }
};

double num(const json& j, const char* f, const Ctx& c, std::optional<double> def = std::nullopt) {
  if (!j.contains(f)) {
    if (def) return *def;
    c.bad(f, "missing");
  }
  if (!j[f].is_number()) c.bad(f, "expected a number");
  double v = j[f].get<double>();
  if (!std::isfinite(v)) c.bad(f, "not finite");
  return v;
}

// A whole number in [lo, hi] (a count: segments, rings, samples).
int count(const json& j, const char* f, const Ctx& c, int def, int lo, int hi) {
  double v = num(j, f, c, double(def));
  if (v != std::floor(v) || v < lo || v > hi)
    c.bad(f, fmt::format("expected a whole number from {} to {}, got {}", lo, hi, v));
  return static_cast<int>(v);
}

Vec3 vec3(const json& j, const char* f, const Ctx& c, std::optional<Vec3> def = std::nullopt) {
  if (!j.contains(f)) {
    if (def) return *def;
    c.bad(f, "missing");
  }
  const json& a = j[f];
  if (a.is_number()) return Vec3{1, 1, 1} * a.get<double>();
  if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number())
    c.bad(f, "expected [x, y, z] (or one number for a grey colour)");
  return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
}

Vec2 vec2(const json& j, const char* f, const Ctx& c, std::optional<Vec2> def = std::nullopt) {
  if (!j.contains(f)) {
    if (def) return *def;
    c.bad(f, "missing");
  }
  const json& a = j[f];
  if (a.is_number()) return {a.get<double>(), a.get<double>()};
  if (!a.is_array() || a.size() != 2 || !a[0].is_number() || !a[1].is_number()) c.bad(f, "expected [a, b]");
  return {a[0].get<double>(), a[1].get<double>()};
}

void nonneg(Vec3 v, const char* f, const Ctx& c) {
  if (v.x < 0 || v.y < 0 || v.z < 0) c.bad(f, "must not be negative");
}

// Rotation from "rotate_deg": [rx, ry, rz] (applied x, then y, then z).
Mat3 rotation_deg(const json& j, const Ctx& c) {
  Vec3 r = vec3(j, "rotate_deg", c, Vec3{});
  return Mat3::rotation({0, 0, 1}, r.z * kPi / 180) * Mat3::rotation({0, 1, 0}, r.y * kPi / 180) *
         Mat3::rotation({1, 0, 0}, r.x * kPi / 180);
}

Texture texture(const json& j, const Ctx& c) {
  Texture t;
  if (!j.contains("albedo")) return t;
  const json& a = j["albedo"];
  if (a.is_number() || a.is_array()) {
    t.constant = vec3(j, "albedo", c);
  } else if (a.is_object() && a.contains("checker")) {
    const json& ch = a["checker"];
    if (!ch.is_array() || ch.size() != 2) c.bad("albedo.checker", "expected [colour_a, colour_b]");
    json tmp = {{"a", ch[0]}, {"b", ch[1]}};
    t.checker = true;
    t.a = vec3(tmp, "a", c);
    t.b = vec3(tmp, "b", c);
    t.tiles = vec2(a, "tiles", c, Vec2{8, 8});
  } else if (a.is_object() && a.contains("texture")) {
    t.image =
        std::make_shared<Image>(io::read_image(c.rel(a["texture"].get<std::string>()), {false, 3}).with_channels(3));
    t.scale = vec2(a, "scale", c, Vec2{1, 1});
  } else {
    c.bad("albedo", "expected a number, [r,g,b], {\"texture\": file} or {\"checker\": [a, b]}");
  }
  for (Vec3 v : {t.constant, t.a, t.b})
    if (v.x < 0 || v.y < 0 || v.z < 0 || v.x > 1 || v.y > 1 || v.z > 1) c.bad("albedo", "must lie in [0, 1]");
  return t;
}

int wall_axis(const std::string& w, bool* at_max, const Ctx& c) {
  if (w.size() != 2 || (w[0] != '+' && w[0] != '-') || w[1] < 'x' || w[1] > 'z')
    c.bad("openings.wall", "expected one of -x +x -y +y -z +z, got \"" + w + "\"");
  *at_max = w[0] == '+';
  return w[1] - 'x';
}

Surface surface(const json& j, const Ctx& c) {
  Surface s;
  std::string type = opt_field(j, c.file + ": " + c.where, "type", "");
  s.name = opt_field(j, c.file + ": " + c.where, "name", type);
  s.albedo = texture(j, c);
  s.emission = vec3(j, "emission", c, Vec3{});
  nonneg(s.emission, "emission", c);
  s.proxy = opt_field(j, c.file + ": " + c.where, "proxy", true);
  if (type == "room" || type == "box") {
    geometry::RoomDesc r;
    r.lo = vec3(j, "min", c);
    r.hi = vec3(j, "max", c);
    if (j.contains("openings"))
      for (const json& o : j["openings"]) {
        geometry::Opening op;
        op.axis = wall_axis(opt_field(o, c.file + ": " + c.where, "wall", ""), &op.at_max, c);
        op.lo = vec2(o, "min", c);
        op.hi = vec2(o, "max", c);
        r.openings.push_back(op);
      }
    if (j.contains("omit"))
      for (const json& w : j["omit"]) {
        bool at_max = false;
        int k = wall_axis(w.get<std::string>(), &at_max, c);
        r.omit[2 * k + (at_max ? 1 : 0)] = true;
      }
    s.mesh = geometry::make_room(r);
    if (type == "box") s.mesh.flip();  // an obstacle: front faces outwards
  } else if (type == "quad") {
    s.mesh = geometry::make_quad(vec3(j, "center", c), vec3(j, "normal", c), vec3(j, "up", c, Vec3{0, 1, 0}),
                                 vec2(j, "size", c).x, vec2(j, "size", c).y);
  } else if (type == "disc") {
    s.mesh = geometry::make_disc(vec3(j, "center", c), vec3(j, "normal", c), num(j, "radius", c),
                                 count(j, "segments", c, 64, 3, 1000000));
  } else if (type == "sphere") {
    s.mesh = geometry::make_sphere(vec3(j, "center", c), num(j, "radius", c), count(j, "rings", c, 32, 2, 1000000),
                                   count(j, "segments", c, 64, 3, 1000000),
                                   opt_field(j, c.file + ": " + c.where, "inward", false));
  } else if (type == "cylinder") {
    s.mesh = geometry::make_cylinder(vec3(j, "base", c), vec3(j, "axis", c), num(j, "radius", c),
                                     count(j, "segments", c, 48, 3, 1000000),
                                     opt_field(j, c.file + ": " + c.where, "caps", true));
  } else if (type == "mesh") {
    if (!j.contains("file")) c.bad("file", "missing");
    s.mesh = geometry::read_mesh(c.rel(j["file"].get<std::string>()));
    s.mesh.transform(rotation_deg(j, c), num(j, "scale", c, 1.0), vec3(j, "translate", c, Vec3{}));
    if (opt_field(j, c.file + ": " + c.where, "flip", false)) s.mesh.flip();
  } else {
    c.bad("type", "unknown surface type \"" + type + "\" (room, box, quad, disc, sphere, cylinder, mesh)");
  }
  return s;
}

Pattern pattern(const std::string& p, const Ctx& c) {
  if (p == "squares") return Pattern::Squares;
  if (p == "checker") return Pattern::Checker;
  if (p == "white") return Pattern::White;
  if (p == "disc") return Pattern::Disc;
  c.bad("pattern", "unknown pattern \"" + p + "\" (squares, checker, white, disc)");
}

Emitter emitter(const json& j, const Ctx& c) {
  Emitter e;
  std::string type = opt_field(j, c.file + ": " + c.where, "type", "");
  e.name = opt_field(j, c.file + ": " + c.where, "name", type);
  if (type == "area") {
    e.type = EmitterType::Area;
    std::string shape = opt_field(j, c.file + ": " + c.where, "shape", "quad");
    if (shape != "quad" && shape != "disc") c.bad("shape", "expected quad or disc");
    e.disc = shape == "disc";
    e.center = vec3(j, "center", c);
    e.normal = vec3(j, "normal", c);
    e.up = vec3(j, "up", c, Vec3{0, 0, 1});
    if (e.disc)
      e.radius = num(j, "radius", c);
    else
      e.size = vec2(j, "size", c);
    e.radiance = vec3(j, "radiance", c);
    nonneg(e.radiance, "radiance", c);
  } else if (type == "spot" || type == "projector" || type == "point") {
    e.type = type == "spot" ? EmitterType::Spot : type == "projector" ? EmitterType::Projector : EmitterType::Point;
    e.position = vec3(j, "position", c);
    e.intensity = vec3(j, "color", c, Vec3{1, 1, 1}) * vec3(j, "intensity", c);  // W/sr: a number or [r,g,b]
    nonneg(e.intensity, "intensity", c);
    if (e.type != EmitterType::Point) {
      e.direction = vec3(j, "direction", c);
      if (length(e.direction) == 0) c.bad("direction", "must not be zero");
      e.aperture_radius = num(j, "aperture_radius", c, 0.025);
      if (e.aperture_radius < 0) c.bad("aperture_radius", "must not be negative");
    }
    if (e.type == EmitterType::Spot) {
      e.cone_deg = num(j, "cone_deg", c);
      e.falloff_deg = num(j, "falloff_deg", c, e.cone_deg);
      if (e.cone_deg <= 0 || e.cone_deg > 180 || e.falloff_deg < 0 || e.falloff_deg > e.cone_deg)
        c.bad("cone_deg", "need 0 < falloff_deg ≤ cone_deg ≤ 180");
    }
    if (e.type == EmitterType::Projector) {
      e.up = vec3(j, "up", c, Vec3{0, 1, 0});
      e.fov_deg = vec2(j, "fov_deg", c);
      if (e.fov_deg.x <= 0 || e.fov_deg.x >= 180 || e.fov_deg.y <= 0 || e.fov_deg.y >= 180)
        c.bad("fov_deg", "must lie in (0, 180)");
      if (j.contains("image")) {
        e.pattern = Pattern::Image;
        e.image =
            std::make_shared<Image>(io::read_image(c.rel(j["image"].get<std::string>()), {false, 3}).with_channels(3));
      } else {
        e.pattern = pattern(j.value("pattern", "squares"), c);
      }
    }
  } else if (type == "environment") {
    e.type = EmitterType::Environment;
    e.scale = num(j, "scale", c, 1.0);
    e.rotation = rotation_deg(j, c);
    if (j.contains("image")) {
      io::EnvReadDesc rd;
      if (j.contains("mapping")) {
        rd.mapping = sphere::find_mapping(j["mapping"].get<std::string>());
        if (!rd.mapping) c.bad("mapping", "unknown mapping");
      }
      e.env = std::make_shared<sphere::EnvMap>(io::read_envmap(c.rel(j["image"].get<std::string>()), rd));
    } else {
      e.radiance = vec3(j, "radiance", c);
      nonneg(e.radiance, "radiance", c);
    }
  } else {
    c.bad("type", "unknown emitter type \"" + type + "\" (area, spot, projector, point, environment)");
  }
  return e;
}

}  // namespace

std::string resolve_scene_path(const std::string& name) {
  if (fs::exists(name)) return name;
  fs::path builtin = fs::path(IBLKIT_SOURCE_DIR) / "examples" / (name + ".json");
  if (name.find('/') == std::string::npos && fs::exists(builtin)) return builtin.string();
  // The built-in scenes are the iblkit.scene/1 files in examples/.
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(fs::path(IBLKIT_SOURCE_DIR) / "examples", ec)) {
    if (entry.path().extension() != ".json") continue;
    std::ifstream in(entry.path());
    std::string head(256, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    if (head.find("iblkit.scene/1") != std::string::npos) names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  fail(ErrorKind::Io, "{}: no such scene file (built-in scenes: {})", name, fmt::join(names, ", "));
}

Scene load_scene(const std::string& name_or_path, bool build) {
  std::string path = resolve_scene_path(name_or_path);
  const json j = read_json_file(path);
  Ctx c{path, fs::path(path).parent_path(), ""};
  if (!j.is_object() || !j.contains("format") || j["format"] != "iblkit.scene/1")
    c.bad("format", "expected \"iblkit.scene/1\"");
  Scene s;
  s.source = path;
  s.name = opt_field(j, path, "name", fs::path(path).stem().string());
  s.description = opt_field(j, path, "description", "");
  try {
    if (j.contains("volume")) {
      c.where = "volume";
      s.volume_min = vec3(j["volume"], "min", c);
      s.volume_max = vec3(j["volume"], "max", c);
      for (int k = 0; k < 3; ++k)
        if (!(s.volume_max[k] > s.volume_min[k])) c.bad("max", "must exceed min on every axis");
      if (!in_range(s.volume_min) || !in_range(s.volume_max))
        c.bad("min", fmt::format("the corners must lie within ±{:g} m", kMaxCoordinate));
    }
    if (j.contains("settings")) {
      c.where = "settings";
      const json& st = j["settings"];
      s.render.area_samples = count(st, "area_samples", c, s.render.area_samples, 1, 1000000);
      s.render.env_samples = count(st, "env_samples", c, s.render.env_samples, 1, 1000000);
      s.render.bounces = count(st, "bounces", c, s.render.bounces, 0, 64);
      const double seed = num(st, "seed", c, static_cast<double>(s.render.seed));
      if (seed < 0 || seed > 9007199254740992.0 || seed != std::floor(seed))
        c.bad("seed", fmt::format("expected a whole number ≥ 0, got {}", seed));
      s.render.seed = static_cast<uint64_t>(seed);
      if (s.render.area_samples < 1 || s.render.env_samples < 1 || s.render.bounces < 0)
        c.bad("area_samples", "need area_samples ≥ 1, env_samples ≥ 1, bounces ≥ 0");
    }
    c.where.clear();
    if (j.contains("proxy")) {
      if (!j["proxy"].is_string()) c.bad("proxy", "expected a file name");
      s.proxy_file = c.rel(j["proxy"].get<std::string>());
    }
    if (j.contains("emitters") && !j["emitters"].is_array()) c.bad("emitters", "expected a list");
    if (!j.contains("surfaces") || !j["surfaces"].is_array()) c.bad("surfaces", "missing (a list)");
    for (size_t i = 0; i < j["surfaces"].size(); ++i) {
      c.where = fmt::format("surfaces[{}]", i);
      s.surfaces.push_back(surface(j["surfaces"][i], c));
    }
    if (j.contains("emitters"))
      for (size_t i = 0; i < j["emitters"].size(); ++i) {
        c.where = fmt::format("emitters[{}]", i);
        s.emitters.push_back(emitter(j["emitters"][i], c));
      }
  } catch (const json::exception& e) {
    fail(ErrorKind::Format, "{}: {}{}{}", path, c.where, c.where.empty() ? "" : ": ", json_error_text(e));
  } catch (const Error& e) {
    if (std::string(e.what()).find(path) != std::string::npos) throw;
    fail(e.kind(), "{}: {}{}{}", path, c.where, c.where.empty() ? "" : ": ", e.what());
  }
  if (build) s.build();
  return s;
}

}  // namespace ibl::lab
