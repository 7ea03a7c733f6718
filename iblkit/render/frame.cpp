#include "iblkit/render/frame.h"

#include <fmt/format.h>

#include "iblkit/core/error.h"

namespace ibl::render {

void check_objects(const FrameDesc& d) {
  geometry::require_camera(d.camera);
  for (size_t i = 0; i < d.objects.size(); ++i) {
    const geometry::TriMesh* m = d.objects[i].mesh;
    if (!m) fail(ErrorKind::Value, "object {} has no mesh", i);
    check_material(d.objects[i].material, fmt::format("object {}", i));
    if (!m->has_normals() && m->vertex_count() > 0)
      fail(ErrorKind::Value,
           "object {}: its mesh has {} normals for {} vertices (geometry::with_normals gives a mesh its shading "
           "normals)",
           i, m->normals.size(), m->vertex_count());
  }
}

}  // namespace ibl::render
