#include "iblkit/geometry/camera_io.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"

namespace ibl::geometry {

namespace {

Vec3 vec3_field(const nlohmann::json& j, const char* key, const std::string& what) {
  if (!j.contains(key)) fail(ErrorKind::Format, "{}: \"{}\" is missing", what, key);
  const auto& a = j[key];
  if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number())
    fail(ErrorKind::Format, "{}: \"{}\" must be [x, y, z]", what, key);
  return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
}

bool finite_point(Vec3 p) { return is_finite(p) && in_range(p); }

}  // namespace

void validate_camera(const Camera& c, const std::string& what) {
  if (!finite_point(c.eye))
    fail(ErrorKind::Value, "{}: eye ({}, {}, {}) is not a finite point within 1e6 m", what, c.eye.x, c.eye.y, c.eye.z);
  if (!finite_point(c.target))
    fail(ErrorKind::Value, "{}: target ({}, {}, {}) is not a finite point within 1e6 m", what, c.target.x, c.target.y,
         c.target.z);
  if (!finite_point(c.up) || length(c.up) == 0)
    fail(ErrorKind::Value, "{}: up ({}, {}, {}) has no direction", what, c.up.x, c.up.y, c.up.z);
  Vec3 f = c.target - c.eye;
  if (length(f) == 0) fail(ErrorKind::Value, "{}: eye and target are the same point", what);
  if (length(cross(normalize(f), normalize(c.up))) < 1e-6)
    fail(ErrorKind::Value, "{}: up is parallel to the view direction", what);
  if (!(c.fov_y_deg > 0 && c.fov_y_deg < 179))
    fail(ErrorKind::Value, "{}: fov_y_deg {} must lie in (0, 179)", what, c.fov_y_deg);
  if (c.width < 1 || c.height < 1 || c.width > 16384 || c.height > 16384)
    fail(ErrorKind::Value, "{}: frame size {}x{} must lie in 1..16384", what, c.width, c.height);
  require_lens(c, what);
}

nlohmann::json camera_to_json(const Camera& c, bool with_size) {
  auto v = [](Vec3 p) { return nlohmann::json::array({p.x, p.y, p.z}); };
  nlohmann::json j = {{"format", "iblkit.camera/1"},
                      {"eye", v(c.eye)},
                      {"target", v(c.target)},
                      {"up", v(c.up)},
                      {"fov_y_deg", c.fov_y_deg}};
  if (with_size || c.intrinsics) {
    j["width"] = c.width;
    j["height"] = c.height;
  }
  if (c.intrinsics) {
    const Intrinsics& k = *c.intrinsics;
    j["intrinsics"] = {{"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy}};
    const Distortion& d = c.distortion;
    if (d.any()) j["distortion"] = nlohmann::json::array({d.k1, d.k2, d.p1, d.p2, d.k3});
  }
  return j;
}

Camera camera_from_json(const nlohmann::json& j, const std::string& what) {
  require_format(j, what, "iblkit.camera/1");
  Camera c;
  c.eye = vec3_field(j, "eye", what);
  c.target = vec3_field(j, "target", what);
  c.up = j.contains("up") ? vec3_field(j, "up", what) : Vec3{0, 1, 0};
  c.width = c.height = 0;
  for (const char* key : {"width", "height"})
    if (j.contains(key) && !j[key].is_number_integer())
      fail(ErrorKind::Format, "{}: \"{}\" must be an integer", what, key);
  if (j.contains("width")) c.width = json_integer<int>(j["width"], what, "width");
  if (j.contains("height")) c.height = json_integer<int>(j["height"], what, "height");
  if (j.contains("intrinsics")) {
    const auto& k = j["intrinsics"];
    if (!k.is_object()) fail(ErrorKind::Format, "{}: \"intrinsics\" must be {{\"fx\", \"fy\", \"cx\", \"cy\"}}", what);
    Intrinsics in;
    double* field[] = {&in.fx, &in.fy, &in.cx, &in.cy};
    const char* names[] = {"fx", "fy", "cx", "cy"};
    for (int i = 0; i < 4; ++i) {
      if (!k.contains(names[i]) || !k[names[i]].is_number())
        fail(ErrorKind::Format, "{}: \"intrinsics\".\"{}\" (a number, pixels) is missing", what, names[i]);
      *field[i] = k[names[i]].get<double>();
    }
    if (c.width == 0 || c.height == 0)
      fail(ErrorKind::Format, "{}: \"intrinsics\" are in pixels of a frame: \"width\" and \"height\" are needed too",
           what);
    c.intrinsics = in;
  }
  if (j.contains("distortion")) {
    const auto& d = j["distortion"];
    if (!d.is_array() || d.size() != 5)
      fail(ErrorKind::Format, "{}: \"distortion\" must be [k1, k2, p1, p2, k3]", what);
    for (const auto& v : d)
      if (!v.is_number()) fail(ErrorKind::Format, "{}: \"distortion\" must be [k1, k2, p1, p2, k3] (numbers)", what);
    if (!c.intrinsics) fail(ErrorKind::Format, "{}: \"distortion\" needs \"intrinsics\"", what);
    c.distortion = {d[0].get<double>(), d[1].get<double>(), d[2].get<double>(), d[3].get<double>(), d[4].get<double>()};
  }
  if (j.contains("fov_y_deg") && j["fov_y_deg"].is_number())
    c.fov_y_deg = j["fov_y_deg"].get<double>();
  else if (c.intrinsics)
    c.fov_y_deg = 2 * std::atan(c.height / (2 * c.intrinsics->fy)) * 180 / kPi;
  else
    fail(ErrorKind::Format, "{}: \"fov_y_deg\" (a number) is missing", what);
  Camera check = c;
  if (check.width == 0) check.width = 1;
  if (check.height == 0) check.height = 1;
  validate_camera(check, what);
  return c;
}

Camera read_camera(const std::string& path) { return camera_from_json(read_json_file(path), path); }

void write_camera(const std::string& path, const Camera& cam, bool with_size) {
  write_json_file(path, camera_to_json(cam, with_size));
}

}  // namespace ibl::geometry
