#include "iblkit/geometry/raytracer.h"

#include <embree3/rtcore.h>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"

namespace ibl::geometry {

struct RayTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  uint32_t count = 0;
  bool committed = false;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

RayTracer::RayTracer() : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device)
    fail(ErrorKind::Internal, "Embree: cannot create a device (error {})",
         static_cast<int>(rtcGetDeviceError(nullptr)));
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);  // watertight: rays through shared edges hit
}

RayTracer::~RayTracer() = default;
RayTracer::RayTracer(RayTracer&&) noexcept = default;
RayTracer& RayTracer::operator=(RayTracer&&) noexcept = default;

uint32_t RayTracer::add(const TriMesh& mesh) {
  if (impl_->committed) fail(ErrorKind::Internal, "RayTracer::add after commit");
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), std::max<size_t>(1, mesh.vertex_count())));
  for (size_t i = 0; i < mesh.vertex_count(); ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + k] = static_cast<float>(mesh.positions[i][k]);
  auto* ix = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(uint32_t), mesh.triangle_count()));
  for (size_t i = 0; i < mesh.triangle_count(); ++i)
    for (int k = 0; k < 3; ++k) ix[3 * i + k] = mesh.triangles[i][k];
  rtcCommitGeometry(g);
  uint32_t id = rtcAttachGeometry(impl_->scene, g);
  rtcReleaseGeometry(g);
  if (id != impl_->count) fail(ErrorKind::Internal, "Embree geometry ids are not sequential");
  return impl_->count++;
}

void RayTracer::commit() {
  rtcCommitScene(impl_->scene);
  if (rtcGetDeviceError(impl_->device) != RTC_ERROR_NONE) fail(ErrorKind::Internal, "Embree: scene build failed");
  impl_->committed = true;
}

uint32_t RayTracer::mesh_count() const { return impl_->count; }

namespace {
// Embree asserts (and aborts) on a ray whose origin or direction is not finite or beyond 1.844e18
// (its FLT_LARGE): such a ray is an error here, before Embree sees it. The library's entry points
// keep points within ±kMaxCoordinate (core/check.h), so this only fires on a bug.
void fill_ray(RTCRay& r, Vec3 o, Vec3 d, double tnear, double tfar) {
  constexpr double kEmbreeLarge = 1e18;
  if (!in_range(o, kEmbreeLarge) || !in_range(d, kEmbreeLarge) || !(tnear >= 0 && tnear < 3.0e38) || !(tfar >= tnear))
    fail(ErrorKind::Value,
         "ray tracer: ray from ({}, {}, {}) along ({}, {}, {}), t in ({}, {}), is not finite or out of range", o.x, o.y,
         o.z, d.x, d.y, d.z, tnear, tfar);
  r.org_x = static_cast<float>(o.x);
  r.org_y = static_cast<float>(o.y);
  r.org_z = static_cast<float>(o.z);
  r.dir_x = static_cast<float>(d.x);
  r.dir_y = static_cast<float>(d.y);
  r.dir_z = static_cast<float>(d.z);
  r.tnear = static_cast<float>(tnear);
  r.tfar = tfar >= 3.0e38 ? std::numeric_limits<float>::infinity() : static_cast<float>(tfar);
  r.time = 0;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
}
}  // namespace

Hit RayTracer::intersect(Vec3 o, Vec3 d, double tnear, double tfar) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  fill_ray(rh.ray, o, d, tnear, tfar);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &ctx, &rh);
  Hit h;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
  h.hit = true;
  h.t = rh.ray.tfar;
  h.mesh = rh.hit.geomID;
  h.triangle = rh.hit.primID;
  h.b1 = rh.hit.u;
  h.b2 = rh.hit.v;
  return h;
}

bool RayTracer::occluded(Vec3 o, Vec3 d, double tnear, double tfar) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  fill_ray(r, o, d, tnear, tfar);
  rtcOccluded1(impl_->scene, &ctx, &r);
  return r.tfar < 0;
}

}  // namespace ibl::geometry
