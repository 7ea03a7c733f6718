// The object a render or view frame shows: the blob, a sphere, or a mesh file, sized and placed —
// what `iblkit render SCENE` and `iblkit view SCENE` take (docs/render.md).
#pragma once
#include <string>

#include "iblkit/core/vec.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/render/shading.h"

namespace ibl::render {

struct ObjectDesc {
  std::string scene = "blob";  // "blob" (geometry::make_blob), "sphere", or a mesh file (OBJ, PLY, glTF)
  double size = 0.8;           // metres: the blob's size, the sphere's diameter, a mesh file's largest
                               // extent (0: a mesh file as large and where the file has it, e.g. a room)
  int triangles = 100000;      // triangles of the blob
  Vec3 at;                     // where the object's centre goes (not used for a file kept as it is)
};

// The one object maker: the blob, sphere or mesh file that `iblkit render` shows, `composite` inserts
// and the lab photographs as its truth (their defaults differ: augment/run_composite.h). With its shading
// normals: a mesh file's break at creases over 40° (geometry::with_normals),
// centred on the origin and scaled to `size` before it moves to `at`.
// Throws ibl::Error on a bad size, position, triangle count, file or an empty mesh.
geometry::TriMesh make_object(const ObjectDesc& desc);

// True when the object reaches outside the volume of L's SH grid (lookups there clamp to the grid's
// faces); false without a grid. An object exactly on the volume's faces is inside.
bool reaches_outside_grid(const Lighting& L, const geometry::TriMesh& object);

}  // namespace ibl::render
