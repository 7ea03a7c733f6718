#include "iblkit/render/frame.h"

#include "iblkit/core/error.h"

namespace ibl::render {

void check_objects(const FrameDesc& d) {
  geometry::require_camera(d.camera);
  for (size_t i = 0; i < d.objects.size(); ++i) {
    const geometry::TriMesh* m = d.objects[i].mesh;
    if (!m) fail(ErrorKind::Value, "object {} has no mesh", i);
    const Vec3 a = d.objects[i].material.albedo;
    if (!is_finite(a) || a.x < 0 || a.y < 0 || a.z < 0 || a.x > 1 || a.y > 1 || a.z > 1)
      fail(ErrorKind::Value, "object {}: albedo ({}, {}, {}) must lie in [0, 1] per channel", i, a.x, a.y, a.z);
    if (!m->has_normals() && m->vertex_count() > 0)
      fail(ErrorKind::Value,
           "object {}: its mesh has {} normals for {} vertices (geometry::with_normals gives a mesh its shading "
           "normals)",
           i, m->normals.size(), m->vertex_count());
  }
}

}  // namespace ibl::render
