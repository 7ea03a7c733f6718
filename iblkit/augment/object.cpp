#include "iblkit/augment/object.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/render/mesh.h"

namespace ibl::augment {

namespace {

geometry::TriMesh to_trimesh(const render::Mesh& m) {
  geometry::TriMesh t;
  for (size_t i = 0; i < m.vertex_count(); ++i) t.positions.push_back(m.position(i));
  for (size_t i = 0; i < m.triangle_count(); ++i) t.triangles.push_back({m.indices[3 * i], m.indices[3 * i + 1], m.indices[3 * i + 2]});
  return t;
}

}  // namespace

geometry::TriMesh make_object(const ObjectDesc& d) {
  for (int c = 0; c < 3; ++c)
    if (!(d.albedo[c] >= 0 && d.albedo[c] <= 1))
      fail(ErrorKind::Value, "object albedo ({}, {}, {}) must lie in [0, 1]", d.albedo.x, d.albedo.y, d.albedo.z);
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(d.at[c]) || std::abs(d.at[c]) > 1e6) fail(ErrorKind::Value, "object position is not a finite point within 1e6 m");
  const bool procedural = d.kind == "blob" || d.kind == "sphere";
  if (!(d.size >= 0 && d.size <= 1e4) || (procedural && d.size == 0))
    fail(ErrorKind::Value, "object size {} must be > 0 (and ≤ 1e4 m) for the {}", d.size, d.kind);
  geometry::TriMesh m;
  if (d.kind == "blob") {
    if (d.triangles < 100 || d.triangles > 5000000) fail(ErrorKind::Value, "blob triangles {} must lie in 100..5000000", d.triangles);
    m = to_trimesh(render::make_blob(d.triangles, d.size));
  } else if (d.kind == "sphere") {
    m = geometry::make_sphere({0, 0, 0}, d.size / 2, 64, 128);
  } else {
    m = geometry::read_mesh(d.kind);
    if (m.triangle_count() == 0) fail(ErrorKind::Value, "{}: the mesh has no triangles", d.kind);
    if (d.size == 0) return m;  // as the file has it
    Vec3 lo, hi;
    m.bounds(&lo, &hi);
    double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    if (!(extent > 0)) fail(ErrorKind::Value, "{}: the mesh has no extent", d.kind);
    m.transform(Mat3::identity(), 1.0, (lo + hi) * -0.5);
    m.transform(Mat3::identity(), d.size / extent, {0, 0, 0});
  }
  m.transform(Mat3::identity(), 1.0, d.at);
  return m;
}

}  // namespace ibl::augment
