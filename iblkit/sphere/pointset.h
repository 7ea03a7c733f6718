// Point sets on the unit sphere, for evaluating irradiance and fitting lights.
#pragma once
#include <vector>

#include "iblkit/core/vec.h"

namespace ibl::sphere {

// Face centres (normalised) of an icosahedron subdivided `level` times: 20·4^level points.
// Level 5 gives the 20480 normals of Madsen & Laursen 2007.
std::vector<Vec3> icosphere_face_centres(int level);
// Vertices of the same subdivided icosahedron (10·4^level + 2 points).
std::vector<Vec3> icosphere_vertices(int level);
// n points of the spherical Fibonacci lattice (González 2010), nearly equal areas.
std::vector<Vec3> fibonacci_sphere(int n);

}  // namespace ibl::sphere
