// The virtual object a composite inserts (and the lab photographs as its truth): the blob, a sphere or
// a mesh file, as world-space triangles (made by render::make_object, the objects `iblkit render` shows;
// the composite and the lab shade them with flat per-triangle normals).
#pragma once
#include <string>

#include "iblkit/core/vec.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::augment {

struct ObjectDesc {
  std::string kind = "blob";   // "blob" (geometry::make_blob), "sphere", or a mesh file (OBJ, PLY, glTF)
  double size = 0.3;           // largest extent, metres (0: a mesh file keeps its own size and place)
  int triangles = 20000;       // triangles of the blob
  Vec3 at{0, 0, 0};            // where the object's centre goes, metres
  Vec3 albedo{0.7, 0.7, 0.7};  // Lambertian reflectance in [0, 1]
};

// The object's triangles in world space. Throws ibl::Error on a bad size, albedo or file.
geometry::TriMesh make_object(const ObjectDesc& desc);

}  // namespace ibl::augment
