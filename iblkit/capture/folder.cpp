#include "iblkit/capture/folder.h"

#include <cmath>
#include <filesystem>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"

namespace ibl::capture {

namespace fs = std::filesystem;

std::string CaptureFolder::at(const std::string& path) const {
  if (path.empty() || fs::path(path).is_absolute()) return path;
  return (fs::path(dir) / path).string();
}

Mat3 ball_frame(Vec3 facing) {
  const Vec3 Z = require_direction("the ball's \"facing\"", facing);
  if (std::abs(Z.y) > 0.9999) fail(ErrorKind::Value, "the ball's \"facing\" must not point straight up or down");
  const Vec3 X = normalize(cross(Vec3{0, 1, 0}, Z)), Y = cross(Z, X);
  return Mat3::rows(X, Y, Z).transposed();
}

namespace {

double positive(const nlohmann::json& j, const std::string& where, const char* key, double def, double hi) {
  const double v = opt_field<double>(j, where, key, def);
  if (!(v >= 0 && v <= hi)) fail(ErrorKind::Format, "{}: field \"{}\" = {} must lie in [0, {}]", where, key, v, hi);
  return v;
}

std::string string_field(const nlohmann::json& j, const std::string& where, const char* key) {
  return req_field<std::string>(j, where, key);
}

}  // namespace

CaptureFolder read_capture(const std::string& dir_or_manifest) {
  CaptureFolder c;
  std::error_code ec;
  if (!fs::exists(dir_or_manifest, ec))
    fail(ErrorKind::Io, "{}: no such capture folder (a folder holding capture.json, iblkit.capture/1)",
         dir_or_manifest);
  fs::path manifest =
      fs::is_directory(dir_or_manifest) ? fs::path(dir_or_manifest) / "capture.json" : fs::path(dir_or_manifest);
  const std::string where = manifest.string();
  nlohmann::json j = read_json_file(where);
  require_format(j, where, "iblkit.capture/1");
  c.dir = manifest.parent_path().empty() ? "." : manifest.parent_path().string();
  c.backplate = string_field(j, where, "backplate");
  c.response = opt_field(j, where, "response", "");
  // The backplate's camera.
  if (!j.contains("board"))
    fail(ErrorKind::Format, "{}: field \"board\" is missing (the board seen in the backplate)", where);
  const nlohmann::json& b = j["board"];
  const std::string bw = where + ": board";
  c.board_spec = string_field(b, bw, "spec");
  c.board = parse_board(c.board_spec, bw + " spec");
  Vec3 u{1, 0, 0}, v{0, 0, -1};
  if (b.contains("axes")) {
    const auto& a = b["axes"];
    if (!a.is_array() || a.size() != 6)
      fail(ErrorKind::Format, "{}: field \"axes\" must be [ux, uy, uz, vx, vy, vz]", bw);
    for (const auto& x : a)
      if (!x.is_number() || !std::isfinite(x.get<double>()))
        fail(ErrorKind::Format, "{}: field \"axes\" must hold six finite numbers", bw);
    u = {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
    v = {a[3].get<double>(), a[4].get<double>(), a[5].get<double>()};
  }
  place_board(c.board, b.contains("origin") ? json_vec3(b, bw, "origin") : Vec3{0, 0, 0}, u, v, bw);
  c.lens = opt_field(j, where, "lens", "");
  c.fov_deg = positive(j, where, "fov_deg", 0, 179);
  // The ball.
  if (!j.contains("ball"))
    fail(ErrorKind::Format, "{}: field \"ball\" is missing (the chrome ball's photographs)", where);
  const nlohmann::json& jb = j["ball"];
  const std::string ww = where + ": ball";
  c.ball_center = json_vec3(jb, ww, "center");
  c.ball_radius = req_field<double>(jb, ww, "radius");
  if (!(c.ball_radius > 0 && c.ball_radius < 100))
    fail(ErrorKind::Format, "{}: field \"radius\" = {} m must lie in (0, 100)", ww, c.ball_radius);
  if (jb.contains("facing")) c.facing = json_vec3(jb, ww, "facing");
  try {
    ball_frame(c.facing);  // checks it
  } catch (const Error& e) {
    fail(ErrorKind::Format, "{}: {}", ww, e.what());
  }
  c.fresnel = opt_field(jb, ww, "fresnel", "chrome");
  if (jb.contains("reflectance")) c.reflectance = json_vec3(jb, ww, "reflectance");
  if (!jb.contains("views") || !jb["views"].is_array() || jb["views"].empty() || jb["views"].size() > 2)
    fail(ErrorKind::Format, "{}: field \"views\" must list one or two views", ww);
  for (size_t k = 0; k < jb["views"].size(); ++k) {
    const nlohmann::json& jv = jb["views"][k];
    const std::string vw = ww + ".views[" + std::to_string(k) + "]";
    CaptureView cv;
    if (!jv.contains("frames") || !jv["frames"].is_array() || jv["frames"].empty())
      fail(ErrorKind::Format, "{}: field \"frames\" must list the bracket's photographs", vw);
    for (const auto& f : jv["frames"]) {
      if (!f.is_string()) fail(ErrorKind::Format, "{}: \"frames\" must hold file names", vw);
      cv.frames.push_back(f.get<std::string>());
    }
    cv.angle_deg = opt_field<double>(jv, vw, "angle_deg", k == 0 ? 0.0 : 90.0);
    if (!std::isfinite(cv.angle_deg)) fail(ErrorKind::Format, "{}: \"angle_deg\" is not finite", vw);
    if (jv.contains("circle")) {
      const Vec3 b3 = json_vec3(jv, vw, "circle");
      cv.ball = BallCircle{b3.x, b3.y, b3.z};
    }
    cv.distance_radii = positive(jv, vw, "distance_radii", 0, 1e6);
    cv.focal_mm = positive(jv, vw, "focal_mm", 0, 1e4);
    cv.sensor_mm = positive(jv, vw, "sensor_mm", 0, 1e4);
    if (cv.distance_radii == 0 && (cv.focal_mm == 0 || cv.sensor_mm == 0))
      fail(ErrorKind::Format,
           "{}: give \"distance_radii\" (camera to ball centre in ball radii) or \"focal_mm\" and "
           "\"sensor_mm\"",
           vw);
    c.views.push_back(std::move(cv));
  }
  // The scene and the object.
  c.proxy = string_field(j, where, "proxy");
  if (j.contains("object")) {
    const nlohmann::json& o = j["object"];
    const std::string ow = where + ": object";
    c.object = opt_field(o, ow, "mesh", "blob");
    c.object_size = positive(o, ow, "size", 0.3, 1e4);
    if (o.contains("at")) c.object_at = json_vec3(o, ow, "at");
    if (o.contains("albedo")) c.albedo = json_vec3(o, ow, "albedo");
  }
  // Points checked where they enter (docs/conventions.md, "Range of values"), naming the field.
  for (const auto& [what, p] :
       {std::pair<const char*, Vec3>{"ball.center", c.ball_center}, {"object.at", c.object_at}}) {
    try {
      require_point(what, p);
    } catch (const Error& e) {
      fail(ErrorKind::Format, "{}: {}", where, e.what());
    }
  }
  if (j.contains("truth")) {
    const nlohmann::json& t = j["truth"];
    const std::string tw = where + ": truth";
    c.truth = string_field(t, tw, "photograph");
    c.truth_mask = opt_field(t, tw, "mask", "");
    c.truth_camera = opt_field(t, tw, "camera", "");
  }
  return c;
}

nlohmann::json capture_to_json(const CaptureFolder& c) {
  auto vec = [](Vec3 p) { return nlohmann::json::array({p.x, p.y, p.z}); };
  const Board& b = c.board;
  nlohmann::json views = nlohmann::json::array();
  for (const CaptureView& v : c.views) {
    nlohmann::json jv = {{"frames", v.frames}, {"angle_deg", v.angle_deg}};
    if (v.ball) jv["circle"] = {v.ball->cx, v.ball->cy, v.ball->r};
    if (v.distance_radii > 0) jv["distance_radii"] = v.distance_radii;
    if (v.focal_mm > 0) jv["focal_mm"] = v.focal_mm;
    if (v.sensor_mm > 0) jv["sensor_mm"] = v.sensor_mm;
    views.push_back(jv);
  }
  nlohmann::json ball = {{"center", vec(c.ball_center)},
                         {"radius", c.ball_radius},
                         {"facing", vec(c.facing)},
                         {"fresnel", c.fresnel},
                         {"views", views}};
  if (c.reflectance) ball["reflectance"] = vec(*c.reflectance);
  nlohmann::json j = {
      {"format", "iblkit.capture/1"},
      {"backplate", c.backplate},
      {"board",
       {{"spec", c.board_spec}, {"origin", vec(b.origin)}, {"axes", {b.u.x, b.u.y, b.u.z, b.v.x, b.v.y, b.v.z}}}},
      {"ball", ball},
      {"proxy", c.proxy},
      {"object", {{"mesh", c.object}, {"size", c.object_size}, {"at", vec(c.object_at)}, {"albedo", vec(c.albedo)}}}};
  if (!c.response.empty()) j["response"] = c.response;
  if (!c.lens.empty()) j["lens"] = c.lens;
  if (c.fov_deg > 0) j["fov_deg"] = c.fov_deg;
  if (!c.truth.empty()) {
    j["truth"] = {{"photograph", c.truth}};
    if (!c.truth_mask.empty()) j["truth"]["mask"] = c.truth_mask;
    if (!c.truth_camera.empty()) j["truth"]["camera"] = c.truth_camera;
  }
  return j;
}

}  // namespace ibl::capture
