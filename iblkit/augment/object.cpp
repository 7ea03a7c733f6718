#include "iblkit/augment/object.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/render/objects.h"

namespace ibl::augment {

geometry::TriMesh make_object(const ObjectDesc& d) {
  for (int c = 0; c < 3; ++c)
    if (!(d.albedo[c] >= 0 && d.albedo[c] <= 1))
      fail(ErrorKind::Value, "object albedo ({}, {}, {}) must lie in [0, 1]", d.albedo.x, d.albedo.y, d.albedo.z);
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(d.at[c]) || std::abs(d.at[c]) > 1e6)
      fail(ErrorKind::Value, "object position is not a finite point within 1e6 m");
  const bool procedural = d.kind == "blob" || d.kind == "sphere";
  if (!(d.size >= 0 && d.size <= 1e4) || (procedural && d.size == 0))
    fail(ErrorKind::Value, "object size {} must be > 0 (and ≤ 1e4 m) for the {}", d.size, d.kind);
  if (d.kind == "blob" && (d.triangles < 100 || d.triangles > 5000000))
    fail(ErrorKind::Value, "blob triangles {} must lie in 100..5000000", d.triangles);
  // The one object maker (render's): the same blob, sphere or file as `iblkit render` shows.
  geometry::TriMesh m = render::make_object({d.kind, d.size, d.triangles, d.at});
  if (m.triangle_count() == 0) fail(ErrorKind::Value, "{}: the mesh has no triangles", d.kind);
  return m;
}

}  // namespace ibl::augment
