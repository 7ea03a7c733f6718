#include "iblkit/lab/scene.h"

#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/geometry/mesh_io.h"

namespace ibl::lab {

Vec3 Texture::eval(Vec2 uv) const {
  if (checker) {
    auto iu = static_cast<long>(std::floor(uv.x * tiles.x)), iv = static_cast<long>(std::floor(uv.y * tiles.y));
    return ((iu + iv) & 1) ? b : a;
  }
  if (image) return image->view().sample_rgb_uv(uv.x * scale.x, 1.0 - uv.y * scale.y, Wrap::Repeat);
  return constant;
}

Frame Emitter::beam_frame() const {
  Vec3 f = normalize(direction);
  Vec3 r = cross(f, up);
  if (length(r) < 1e-9) r = Frame::from_normal(f).t;
  r = normalize(r);
  return {r, cross(r, f), f};  // t = right, b = up, n = forward
}

namespace {
double smoothstep(double a, double b, double x) {
  if (b <= a) return x >= b ? 1.0 : 0.0;
  double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// The built-in patterns on [−1,1]² (x right, y up).
Vec3 builtin_pattern(Pattern p, double x, double y) {
  switch (p) {
    case Pattern::White:
      return {1, 1, 1};
    case Pattern::Disc:
      return x * x + y * y <= 1 ? Vec3{1, 1, 1} : Vec3{0, 0, 0};
    case Pattern::Checker: {
      auto ix = static_cast<int>(std::floor((x + 1) * 4)), iy = static_cast<int>(std::floor((y + 1) * 4));
      return ((ix + iy) & 1) ? Vec3{0.05, 0.05, 0.05} : Vec3{1, 1, 1};
    }
    case Pattern::Squares: {
      // Four squares of side 0.7 centred at (±0.5, ±0.5): red, green / blue, yellow; dark between.
      constexpr double kHalf = 0.35;
      double cx = x < 0 ? -0.5 : 0.5, cy = y < 0 ? -0.5 : 0.5;
      if (std::abs(x - cx) > kHalf || std::abs(y - cy) > kHalf) return {0, 0, 0};
      if (y >= 0) return x < 0 ? Vec3{1, 0.05, 0.05} : Vec3{0.05, 1, 0.05};
      return x < 0 ? Vec3{0.05, 0.05, 1} : Vec3{1, 1, 0.05};
    }
    case Pattern::Image:
      break;
  }
  return {0, 0, 0};
}
}  // namespace

void Emitter::prepare() {
  direction = normalize(direction);
  normal = normalize(normal);
  frame = beam_frame();
  cos_cone = std::cos(cone_deg * kPi / 180);
  cos_falloff = std::cos(falloff_deg * kPi / 180);
  tan_x = std::tan(fov_deg.x * kPi / 360);
  tan_y = std::tan(fov_deg.y * kPi / 360);
  Vec3 v = up - normal * dot(up, normal);
  if (length(v) < 1e-9) v = Frame::from_normal(normal).b;
  edge_v = normalize(v);
  edge_u = cross(edge_v, normal);  // the same frame as geometry::make_quad
  if (disc) {
    Frame f = Frame::from_normal(normal);
    edge_u = f.t;
    edge_v = f.b;
  }
}

Vec3 Emitter::intensity_towards(Vec3 w) const {
  switch (type) {
    case EmitterType::Point:
      return intensity;
    case EmitterType::Spot:
      return intensity * smoothstep(cos_cone, cos_falloff, dot(w, direction));
    case EmitterType::Projector: {
      Vec3 l = frame.to_local(w);
      if (l.z <= 0) return {0, 0, 0};
      double sx = l.x / (l.z * tan_x), sy = l.y / (l.z * tan_y);
      if (std::abs(sx) > 1 || std::abs(sy) > 1) return {0, 0, 0};
      if (pattern == Pattern::Image && image)
        return intensity * image->view().sample_rgb_uv(0.5 * (sx + 1), 0.5 * (1 - sy), Wrap::Clamp);
      return intensity * builtin_pattern(pattern, sx, sy);
    }
    default:
      return {0, 0, 0};
  }
}

Vec3 Emitter::environment(Vec3 d) const {
  if (type != EmitterType::Environment) return {0, 0, 0};
  if (!env) return radiance;
  return env->sample_rgb(rotation.transposed() * d) * scale;
}

void Scene::build() {
  if (tracer_) fail(ErrorKind::Internal, "scene {} built twice", name);
  env_index_ = -1;
  for (size_t i = 0; i < emitters.size(); ++i) {
    Emitter& e = emitters[i];
    e.prepare();
    Surface s;
    s.name = e.name;
    s.emitter = static_cast<int>(i);
    s.proxy = false;
    s.albedo.constant = {0, 0, 0};
    switch (e.type) {
      case EmitterType::Area:
        s.role = SurfaceRole::AreaLight;
        s.mesh = e.disc ? geometry::make_disc(e.center, e.normal, e.radius)
                        : geometry::make_quad(e.center, e.normal, e.up, e.size.x, e.size.y);
        e.emit_area = e.disc ? kPi * e.radius * e.radius : e.size.x * e.size.y;
        surfaces.push_back(std::move(s));
        break;
      case EmitterType::Spot:
      case EmitterType::Projector:
        if (e.aperture_radius > 0) {
          s.role = SurfaceRole::Aperture;
          s.mesh = geometry::make_disc(e.position, e.direction, e.aperture_radius, 32);
          e.emit_area = s.mesh.total_area();
          surfaces.push_back(std::move(s));
        }
        break;
      case EmitterType::Environment:
        if (env_index_ >= 0) fail(ErrorKind::Value, "scene {}: more than one environment emitter", name);
        env_index_ = static_cast<int>(i);
        break;
      case EmitterType::Point:
        break;
    }
  }
  auto tracer = std::make_shared<geometry::RayTracer>();
  for (Surface& s : surfaces) {
    s.mesh.validate(fmt::format("scene {} surface {}", name, s.name));
    s.normals.resize(s.mesh.triangle_count());
    for (size_t t = 0; t < s.normals.size(); ++t) s.normals[t] = s.mesh.normal(t);
    tracer->add(s.mesh);
  }
  tracer->commit();
  tracer_ = std::move(tracer);
}

geometry::TriMesh Scene::proxy_mesh() const {
  if (!proxy_file.empty()) return geometry::read_mesh(proxy_file);
  geometry::TriMesh m;
  for (const Surface& s : surfaces)
    if (s.proxy && s.role == SurfaceRole::Diffuse) m.append(s.mesh);
  return m;
}

std::vector<geometry::DiffuseSurface> diffuse_surfaces(const Scene& scene) {
  std::vector<geometry::DiffuseSurface> out;
  for (const Surface& s : scene.surfaces)
    if (s.role == SurfaceRole::Diffuse) out.push_back({s.name, s.mesh, [t = s.albedo](Vec2 uv) { return t.eval(uv); }});
  return out;
}

}  // namespace ibl::lab
