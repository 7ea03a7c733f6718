// Triangle meshes for rendering, and procedural test objects.
#pragma once
#include <cstdint>
#include <vector>

#include "iblkit/core/vec.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::render {

struct Mesh {
  std::vector<float> positions;  // xyz per vertex
  std::vector<float> normals;    // xyz per vertex, unit length
  std::vector<uint32_t> indices; // three per triangle, counter-clockwise seen from outside
  std::vector<float> uvs;        // uv per vertex (OBJ/GL convention: v = 0 is the image's bottom row), or empty
  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
  Vec3 position(size_t i) const { return {positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]}; }
  Vec3 normal(size_t i) const { return {normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]}; }
  bool has_uvs() const { return !uvs.empty() && uvs.size() == 2 * vertex_count(); }
  Vec2 uv(size_t i) const { return {uvs[2 * i], uvs[2 * i + 1]}; }
  // Axis-aligned bounds.
  void bounds(Vec3* lo, Vec3* hi) const;
  // Appends another mesh (UVs kept only when both have them).
  void append(const Mesh& other);
  // Moves every vertex by t and scales about the origin by s (first scale, then move).
  void transform(double s, Vec3 t);
  // Recomputes vertex normals as area-weighted averages of face normals.
  void compute_normals();
};

// A geometry mesh (lab scenes, OBJ/PLY/glTF files) as a render mesh: float positions, its UVs when
// it has them, and area-weighted vertex normals that stay smooth across edges whose faces meet
// within crease_deg and break at sharper ones (a room's corners, a pillar's edges stay hard).
Mesh from_trimesh(const geometry::TriMesh& m, double crease_deg = 40);

// A UV sphere of `rings` × `segments` quads; u runs once around (from +X), v from the south pole (0)
// to the north pole (1). The blob has the same UVs.
Mesh make_sphere(double radius, int rings, int segments);
// The "blob": a bunny-sized lumpy closed object (a sphere displaced by a few low-frequency lobes,
// bumps and a pair of ears), about `triangles` triangles, radius ~`size`/2. It stands in for the
// Stanford bunny in tests and benchmarks: curved, self-shadowing, concave in places.
Mesh make_blob(int triangles, double size = 0.3);
// A square of side `size` in the plane y = height, facing +Y; UVs span [0,1]² (u along +X, v along −Z).
Mesh make_floor(double size, double height);

}  // namespace ibl::render
