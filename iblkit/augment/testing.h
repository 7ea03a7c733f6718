// Fixtures the augment/ tests share (CPU and GL compositor tests): a constant photograph and a
// sphere object at a point.
#pragma once
#include "iblkit/core/image.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/render/objects.h"

namespace ibl::augment::testing {

inline Image constant_photo(int w, int h, double v) {
  Image p(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) p.set_rgb(x, y, {v, v, v});
  return p;
}

inline geometry::TriMesh sphere_at(Vec3 c, double size) { return render::make_object({"sphere", size, 0, c}); }

}  // namespace ibl::augment::testing
