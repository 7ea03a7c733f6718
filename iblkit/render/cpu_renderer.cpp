#include "iblkit/render/cpu_renderer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::render {

namespace {

// A vertex attribute at float precision, as the GPU reads it (render/frame.h): both renderers draw
// the same triangles with the same normals.
Vec3 f32(Vec3 v) { return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)}; }
Vec2 f32(Vec2 v) { return {static_cast<float>(v.x), static_cast<float>(v.y)}; }

// Embree scene of every object, for shadow rays.
class ShadowScene {
 public:
  explicit ShadowScene(const FrameDesc& d) {
    device_ = rtcNewDevice("threads=0");
    if (!device_) fail(ErrorKind::Internal, "Embree device creation failed");
    scene_ = rtcNewScene(device_);
    for (const auto& o : d.objects) {
      const geometry::TriMesh& m = *o.mesh;
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                            3 * sizeof(float), m.vertex_count()));
      for (size_t i = 0; i < m.vertex_count(); ++i)
        for (int k = 0; k < 3; ++k) v[3 * i + k] = static_cast<float>(m.positions[i][k]);
      auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(uint32_t), m.triangle_count()));
      for (size_t t = 0; t < m.triangle_count(); ++t)
        for (int k = 0; k < 3; ++k) idx[3 * t + k] = m.triangles[t][k];
      rtcCommitGeometry(g);
      rtcAttachGeometry(scene_, g);
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene_);
  }
  ~ShadowScene() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }
  bool occluded(Vec3 o, Vec3 dir, double distance) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray{};
    ray.org_x = static_cast<float>(o.x);
    ray.org_y = static_cast<float>(o.y);
    ray.org_z = static_cast<float>(o.z);
    ray.dir_x = static_cast<float>(dir.x);
    ray.dir_y = static_cast<float>(dir.y);
    ray.dir_z = static_cast<float>(dir.z);
    ray.tnear = 0.0f;
    ray.tfar =
        std::isfinite(distance) ? static_cast<float>(distance * (1 - 1e-4)) : std::numeric_limits<float>::infinity();
    ray.mask = 0xffffffff;
    rtcOccluded1(scene_, &ctx, &ray);
    return ray.tfar < 0.0f;
  }

 private:
  RTCDevice device_;
  RTCScene scene_;
};

struct Hit {
  float depth = std::numeric_limits<float>::infinity();
  int object = -1;
  uint32_t tri = 0;
  float b1 = 0, b2 = 0;  // perspective-correct barycentrics of vertices 1 and 2
};

struct ClipVertex {
  double c[4];  // clip-space position
  Vec3 b;       // barycentric coordinates in the original triangle
};

// Clips a triangle against z ≥ −w (GL's near plane); returns 0, 3 or 4 vertices.
int clip_near(const ClipVertex in[3], ClipVertex out[4]) {
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % 3];
    double da = a.c[2] + a.c[3], db = b.c[2] + b.c[3];
    if (da >= 0) out[n++] = a;
    if ((da >= 0) != (db >= 0)) {
      double t = da / (da - db);
      ClipVertex v;
      for (int r = 0; r < 4; ++r) v.c[r] = a.c[r] + t * (b.c[r] - a.c[r]);
      v.b = a.b + (b.b - a.b) * t;
      out[n++] = v;
    }
  }
  return n;
}

// Rasterises one (clipped) triangle into rows [y_lo, y_hi): pixel centres inside, depth test,
// perspective-correct barycentrics of the original triangle.
void raster_triangle(const ClipVertex& v0, const ClipVertex& v1, const ClipVertex& v2, int W, int H, int y_lo, int y_hi,
                     int object, uint32_t tri, std::vector<Hit>& hits) {
  const ClipVertex* v[3] = {&v0, &v1, &v2};
  double sx[3], sy[3], sz[3], iw[3];
  for (int k = 0; k < 3; ++k) {
    double w = v[k]->c[3];
    if (w <= 0) return;  // only possible for degenerate clips at the eye
    iw[k] = 1.0 / w;
    sx[k] = (v[k]->c[0] * iw[k] + 1) * 0.5 * W;
    sy[k] = (1 - v[k]->c[1] * iw[k]) * 0.5 * H;
    sz[k] = v[k]->c[2] * iw[k];
  }
  double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
  if (area >= 0) return;  // back-facing (counter-clockwise in world is clockwise in y-down screen)
  double minx = std::min({sx[0], sx[1], sx[2]}), maxx = std::max({sx[0], sx[1], sx[2]});
  double miny = std::min({sy[0], sy[1], sy[2]}), maxy = std::max({sy[0], sy[1], sy[2]});
  int x0 = std::max(0, static_cast<int>(std::ceil(minx - 0.5))),
      x1 = std::min(W - 1, static_cast<int>(std::floor(maxx - 0.5)));
  int y0 = std::max(y_lo, static_cast<int>(std::ceil(miny - 0.5))),
      y1 = std::min(y_hi - 1, static_cast<int>(std::floor(maxy - 0.5)));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      double px = x + 0.5, py = y + 0.5;
      double w0 = (sx[1] - px) * (sy[2] - py) - (sx[2] - px) * (sy[1] - py);
      double w1 = (sx[2] - px) * (sy[0] - py) - (sx[0] - px) * (sy[2] - py);
      double w2 = (sx[0] - px) * (sy[1] - py) - (sx[1] - px) * (sy[0] - py);
      if (w0 > 0 || w1 > 0 || w2 > 0) continue;
      double s0 = w0 / area, s1 = w1 / area, s2 = w2 / area;
      double z = s0 * sz[0] + s1 * sz[1] + s2 * sz[2];
      Hit& h = hits[static_cast<size_t>(y) * W + x];
      if (z >= h.depth || z < -1 || z > 1) continue;
      double q0 = s0 * iw[0], q1 = s1 * iw[1], q2 = s2 * iw[2], qs = q0 + q1 + q2;
      Vec3 b = (v0.b * q0 + v1.b * q1 + v2.b * q2) / qs;
      h = {static_cast<float>(z), object, tri, static_cast<float>(b.y), static_cast<float>(b.z)};
    }
}

}  // namespace

RenderResult render_cpu(const FrameDesc& d, const ProgressFn& progress) {
  const geometry::Camera& cam = d.camera;
  const int W = cam.width, H = cam.height;
  if (W <= 0 || H <= 0) fail(ErrorKind::Value, "frame size {}x{} is invalid", W, H);
  check_objects(d);
  if (cam.distorted())
    fail(ErrorKind::Unsupported,
         "render: the rasteriser cannot draw through lens distortion (k1 k2 p1 p2 k3); composite --backend cpu "
         "casts rays through it");
  geometry::Mat4f vp = geometry::mul(cam.projection(), cam.view());
  std::vector<Hit> hits(static_cast<size_t>(W) * H);
  // Rasterise in horizontal bands, one task each: every band tests every triangle's bounds.
  constexpr int kBand = 16;
  int bands = (H + kBand - 1) / kBand;
  parallel_for(0, bands, [&](int64_t band) {
    int y_lo = static_cast<int>(band) * kBand, y_hi = std::min(H, y_lo + kBand);
    for (size_t oi = 0; oi < d.objects.size(); ++oi) {
      const geometry::TriMesh& m = *d.objects[oi].mesh;
      for (size_t t = 0; t < m.triangle_count(); ++t) {
        // Clip space, then clip against GL's near plane z ≥ −w, carrying each vertex's barycentric
        // coordinates in the original triangle.
        ClipVertex tri[3];
        for (int k = 0; k < 3; ++k) {
          Vec3 p = f32(m.positions[m.triangles[t][k]]);
          for (int r = 0; r < 4; ++r) tri[k].c[r] = vp[r] * p.x + vp[4 + r] * p.y + vp[8 + r] * p.z + vp[12 + r];
          tri[k].b = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0};
        }
        ClipVertex poly[4];
        int n = clip_near(tri, poly);
        for (int f = 1; f + 1 < n; ++f)
          raster_triangle(poly[0], poly[f], poly[f + 1], W, H, y_lo, y_hi, static_cast<int>(oi),
                          static_cast<uint32_t>(t), hits);
      }
    }
  });
  report(progress, "rasterise", 1.0);
  bool need_shadows = false;
  for (const auto& l : d.lighting.lights) need_shadows |= l.shadow;
  for (const auto& l : d.lighting.point_lights) need_shadows |= l.shadow;
  for (const auto& l : d.lighting.spotlights) need_shadows |= l.shadow;
  std::unique_ptr<ShadowScene> shadows;
  if (need_shadows) shadows = std::make_unique<ShadowScene>(d);
  RenderResult f{Image(W, H, 3), Image(W, H, 1)};
  std::atomic<int> rows_done{0};
  parallel_for(0, H, [&](int64_t yy) {
    int y = static_cast<int>(yy);
    for (int x = 0; x < W; ++x) {
      const Hit& h = hits[static_cast<size_t>(y) * W + x];
      if (h.object < 0) {
        f.color.set_rgb(x, y, d.background);
        continue;
      }
      const RenderObject& o = d.objects[h.object];
      const geometry::TriMesh& m = *o.mesh;
      const auto [i0, i1, i2] = m.triangles[h.tri];
      double b0 = 1.0 - h.b1 - h.b2;
      Vec3 p = f32(m.positions[i0]) * b0 + f32(m.positions[i1]) * h.b1 + f32(m.positions[i2]) * h.b2;
      Vec3 n = normalize(f32(m.normals[i0]) * b0 + f32(m.normals[i1]) * h.b1 + f32(m.normals[i2]) * h.b2);
      Vec3 v = normalize(cam.eye - p);
      VisibilityFn vis;
      if (shadows)
        vis = [&](Vec3 q, Vec3 l, double dist) { return !shadows->occluded(q + n * d.shadow_bias, l, dist); };
      if (o.material.texture) {
        Vec2 uv = m.has_uvs() ? f32(m.uvs[i0]) * b0 + f32(m.uvs[i1]) * h.b1 + f32(m.uvs[i2]) * h.b2 : Vec2{0, 0};
        Material tm = o.material;
        tm.albedo = tm.albedo * texture_albedo(*o.material.texture, uv);
        f.color.set_rgb(x, y, shade(d.lighting, tm, p, n, v, vis));
      } else {
        f.color.set_rgb(x, y, shade(d.lighting, o.material, p, n, v, vis));
      }
      f.coverage.at(x, y, 0) = 1.0f;
    }
    report(progress, "shade", static_cast<double>(++rows_done) / H);
  });
  return f;
}

}  // namespace ibl::render
