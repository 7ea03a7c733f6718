#include "iblkit/nearfield/render.h"

#include <atomic>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/nearfield/rgbe.h"

namespace ibl::nearfield {

namespace {

constexpr double kRayOffset = 1e-4;  // metres: lifts shadow-ray origins off the surface (scene scale ~m)

Vec3 plane_point(const PlaneDesc& pl, int x, int y) {
  const double s = -pl.half_extent + (x + 0.5) * 2 * pl.half_extent / pl.resolution;
  const double t = pl.half_extent - (y + 0.5) * 2 * pl.half_extent / pl.resolution;
  return {s, t, pl.z};
}

void check_plane(const PlaneDesc& pl) {
  if (!(pl.z > 0) || !(pl.half_extent > 0) || pl.resolution < 1 || pl.resolution > 8192)
    fail(ErrorKind::Value,
         "receiver plane: distance {} m, half extent {} m, resolution {}: need z > 0, extent > 0, 1..8192 pixels", pl.z,
         pl.half_extent, pl.resolution);
}

}  // namespace

Image plane_irradiance(const std::vector<TexturedSpotlight>& lights, const Placement& placement, const PlaneDesc& pl) {
  check_plane(pl);
  const Frame f = placement.frame();
  Image out(pl.resolution, pl.resolution, 3);
  parallel_for(0, pl.resolution, [&](int64_t y) {
    for (int x = 0; x < pl.resolution; ++x) {
      const Vec3 p = placement.position + f.from_local(plane_point(pl, x, static_cast<int>(y)));
      Vec3 e{0, 0, 0};
      for (const auto& L : lights) e += irradiance(L, p, -f.n);
      out.set_rgb(x, static_cast<int>(y), e);
    }
  });
  return out;
}

Image plane_irradiance_exact(const Luminaire& lum, const PlaneDesc& pl) {
  check_plane(pl);
  Image out(pl.resolution, pl.resolution, 3);
  parallel_for(0, pl.resolution, [&](int64_t y) {
    for (int x = 0; x < pl.resolution; ++x)
      out.set_rgb(x, static_cast<int>(y), lum.irradiance(plane_point(pl, x, static_cast<int>(y)), {0, 0, -1}));
  });
  return out;
}

ErrorStats compare(const Image& a, const Image& e) {
  if (a.width() != e.width() || a.height() != e.height())
    fail(ErrorKind::Value, "compare: {}x{} against {}x{}", a.width(), a.height(), e.width(), e.height());
  double se = 0, sa = 0, sum_e = 0, sum_a = 0, max_e = 0, max_d = 0;
  const size_t n = a.pixel_count();
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      const double la = luminance(a.rgb(x, y)), le = luminance(e.rgb(x, y)), d = la - le;
      se += d * d;
      sa += std::abs(d);
      sum_e += le;
      sum_a += la;
      max_e = std::max(max_e, le);
      max_d = std::max(max_d, std::abs(d));
    }
  ErrorStats s;
  const double mean = sum_e / n;
  if (!(mean > 0)) fail(ErrorKind::Value, "compare: the exact image is black");
  s.rel_rms = std::sqrt(se / n) / mean;
  s.rel_mean_abs = sa / n / mean;
  s.rel_max = max_d / max_e;
  s.power_ratio = sum_a / sum_e;
  return s;
}

SceneView::SceneView(std::vector<geometry::DiffuseSurface> surfaces, std::string name) : name_(std::move(name)) {
  for (auto& s : surfaces) {
    if (s.mesh.triangle_count() == 0) continue;
    if (!s.albedo) fail(ErrorKind::Value, "scene '{}': surface '{}' has no albedo", name_, s.name);
    tracer_.add(s.mesh);
    surfaces_.push_back(std::move(s));
  }
  if (surfaces_.empty()) fail(ErrorKind::Value, "scene '{}' has no diffuse surfaces to light", name_);
  tracer_.commit();
}

bool SceneView::primary(const geometry::Camera& v, int x, int y, Vec3* p, Vec3* n, Vec3* albedo) const {
  const Vec3 d = v.pixel_direction(x, y);
  const auto hit = tracer_.intersect(v.eye, d);
  if (!hit.hit) return false;
  const auto& s = surfaces_[hit.mesh];
  *p = v.eye + d * hit.t;
  Vec3 nn = s.mesh.normal(hit.triangle);
  if (dot(nn, d) > 0) nn = -nn;  // shade the side the camera sees
  *n = nn;
  Vec2 uv{0, 0};
  if (!s.mesh.uvs.empty()) {
    const auto& t = s.mesh.triangles[hit.triangle];
    uv = s.mesh.uvs[t[0]] * (1 - hit.b1 - hit.b2) + s.mesh.uvs[t[1]] * hit.b1 + s.mesh.uvs[t[2]] * hit.b2;
  }
  *albedo = s.albedo(uv);
  return true;
}

bool SceneView::blocked(Vec3 p, Vec3 q) const { return tracer_.occluded(p, q - p, 0, 1 - 1e-6); }

namespace {

void check_view(const geometry::Camera& v) {
  geometry::require_camera(v);
  if (v.width < 1 || v.height < 1 || v.width > 16384 || v.height > 16384 || !(v.fov_y_deg > 0 && v.fov_y_deg < 179))
    fail(ErrorKind::Value, "view: {}x{} pixels, field of view {}°: out of range", v.width, v.height, v.fov_y_deg);
}

template <typename Shade>
Image render_rows(const SceneView& sv, const geometry::Camera& view, const ProgressFn& progress, Shade shade) {
  check_view(view);
  Image out(view.width, view.height, 3);
  std::atomic<int> done{0};
  parallel_for(0, view.height, [&](int64_t y) {
    for (int x = 0; x < view.width; ++x) {
      Vec3 p, n, a;
      if (!sv.primary(view, x, static_cast<int>(y), &p, &n, &a)) continue;
      out.set_rgb(x, static_cast<int>(y), a * shade(p + n * kRayOffset, n) * (1 / kPi));
    }
    report(progress, "render", static_cast<double>(++done) / view.height);
  });
  return out;
}

}  // namespace

Image render_spotlights(const SceneView& sv, const std::vector<TexturedSpotlight>& lights, const geometry::Camera& view,
                        bool shadows, const ProgressFn& progress, int srgbe_group) {
  if (srgbe_group < 0) fail(ErrorKind::Value, "sRGBE pass size {} must be ≥ 0", srgbe_group);
  return render_rows(sv, view, progress, [&](Vec3 p, Vec3 n) {
    Vec3 e{0, 0, 0}, pass{0, 0, 0};
    for (size_t k = 0; k < lights.size(); ++k) {
      const auto& L = lights[k];
      Vec3 c = irradiance(L, p, n);
      if ((c.x != 0 || c.y != 0 || c.z != 0) && !(shadows && L.shadow && sv.blocked(p, L.position))) pass += c;
      if (srgbe_group > 0 && ((k + 1) % static_cast<size_t>(srgbe_group) == 0 || k + 1 == lights.size())) {
        e = decode_srgbe(encode_srgbe(e + pass));  // the frame buffer between passes
        pass = {0, 0, 0};
      }
    }
    return e + pass;
  });
}

Image render_exact(const SceneView& sv, const Luminaire& lum, const Placement& placement, const geometry::Camera& view,
                   bool shadows, const ProgressFn& progress) {
  const Frame f = placement.frame();
  std::vector<Vec3> centres;
  for (const auto& e : lum.emitters) centres.push_back(placement.position + f.from_local(e.center));
  return render_rows(sv, view, progress, [&](Vec3 p, Vec3 n) {
    const Vec3 pl = f.to_local(p - placement.position), nl = f.to_local(n);
    if (shadows) return lum.irradiance(pl, nl, [&](int e) { return !sv.blocked(p, centres[static_cast<size_t>(e)]); });
    return lum.irradiance(pl, nl);
  });
}

}  // namespace ibl::nearfield
