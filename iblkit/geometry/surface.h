// A Lambertian surface in world space: what a renderer of direct light needs of a scene, whichever way
// the scene came (a lab scene through lab::diffuse_surfaces, a scanned room, a mesh file and its
// material). nearfield/'s renderer takes a list of them.
#pragma once
#include <functional>
#include <string>

#include "iblkit/core/vec.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::geometry {

struct DiffuseSurface {
  std::string name;                     // for messages
  TriMesh mesh;                         // world-space triangles
  std::function<Vec3(Vec2 uv)> albedo;  // diffuse reflectance in [0, 1] at a texture coordinate
                                        // (called with (0, 0) when the mesh has no UVs)
};

}  // namespace ibl::geometry
