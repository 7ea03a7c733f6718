#include "iblkit/render/objects.h"

#include <algorithm>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/geometry/mesh_io.h"

namespace ibl::render {

geometry::TriMesh make_object(const ObjectDesc& desc) {
  const std::string& scene = desc.scene;
  const double size = desc.size;
  if (!(size > 0) && (scene == "blob" || scene == "sphere"))
    fail(ErrorKind::Value, "object size {} must be > 0 for the {}", size, scene);
  require_point("object position", desc.at);
  require_number("object size", size, 0, kMaxCoordinate);
  if (scene == "blob" && (desc.triangles < 100 || desc.triangles > 5000000))
    fail(ErrorKind::Value, "blob triangles {} must lie in 100..5000000", desc.triangles);
  geometry::TriMesh object;
  if (scene == "blob") {
    object = geometry::make_blob(desc.triangles, size);
  } else if (scene == "sphere") {
    object = geometry::make_sphere({0, 0, 0}, size / 2, 128, 256);
  } else {
    object = geometry::with_normals(geometry::read_mesh(scene));
    if (size == 0) return object;  // as the file has it
    // Centre the file's mesh on the origin and scale its largest extent to `size`.
    Vec3 lo, hi;
    object.bounds(&lo, &hi);
    double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    if (!(extent > 0)) fail(ErrorKind::Value, "{}: the mesh has no extent", scene);
    object.transform(1.0, (lo + hi) * -0.5);
    object.transform(size / extent, {0, 0, 0});
  }
  object.transform(1.0, desc.at);
  if (object.triangle_count() == 0) fail(ErrorKind::Value, "{}: the mesh has no triangles", scene);
  return object;
}

bool reaches_outside_grid(const Lighting& L, const geometry::TriMesh& object) {
  if (!L.grid) return false;
  Vec3 lo, hi;
  object.bounds(&lo, &hi);
  const ilf::Box& v = L.grid->grid().volume;
  constexpr double kSlack = 1e-6;  // metres: an object exactly on the volume's faces is inside
  for (int a = 0; a < 3; ++a)
    if (lo[a] < v.min[a] - kSlack || hi[a] > v.max[a] + kSlack) return true;
  return false;
}

}  // namespace ibl::render
