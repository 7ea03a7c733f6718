// Triangle meshes (positions, optional shading normals and UVs, counter-clockwise triangles seen from
// the front): the one mesh type of the library (lab scenes, fusion proxies, the renderers), and the
// primitives the lab builds scenes from: quads, discs, spheres, cylinders, boxes and box rooms with
// rectangular openings, and the renderers' test objects (the blob, a floor). The front side of a triangle is the side
// its normal cross(p1−p0, p2−p0) points to (the OBJ / glTF convention); emitters emit from the front side only.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "iblkit/core/vec.h"

namespace ibl::geometry {

struct TriMesh {
  std::vector<Vec3> positions;                     // one per vertex, metres
  std::vector<Vec3> normals;                       // one unit shading normal per vertex, or empty (the
                                                   // renderers need them: with_normals() gives them)
  std::vector<Vec2> uvs;                           // one per vertex (OBJ/GL convention: v = 0 is the
                                                   // image's bottom row), or empty
  std::vector<std::array<uint32_t, 3>> triangles;  // vertex indices, counter-clockwise from the front

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return triangles.size(); }
  bool has_normals() const { return !normals.empty() && normals.size() == positions.size(); }
  bool has_uvs() const { return !uvs.empty() && uvs.size() == positions.size(); }
  // Unit normal of triangle i (front side), zero for a degenerate triangle.
  Vec3 normal(size_t i) const;
  double area(size_t i) const;
  double total_area() const;
  // Axis-aligned bounds; lo > hi when empty.
  void bounds(Vec3* lo, Vec3* hi) const;
  // Appends another mesh (normals and UVs each kept only when both have them, or this one is empty).
  void append(const TriMesh& other);
  // p -> rotation·(scale·p) + translation for every vertex; normals n -> rotation·n.
  void transform(const Mat3& rotation, double scale, Vec3 translation);
  // p -> scale·p + translation (first scale, then move); normals stay (scale > 0).
  void transform(double scale, Vec3 translation);
  // Turns every triangle around (the front becomes the back; normals too).
  void flip();
  // Sets every vertex normal to the area-weighted average of the normals of the triangles around it
  // (smooth everywhere; with_normals() keeps creases).
  void compute_normals();
  // Throws ibl::Error naming `what` on indices out of range, non-finite positions, or normals or
  // UVs that do not match the vertices.
  void validate(const std::string& what) const;
};

// A copy of m with shading normals: area-weighted vertex normals that stay smooth across edges whose
// faces meet within crease_deg and break at sharper ones (a room's corners, a pillar's edges stay
// hard). Corners of one vertex that end up with different normals become separate vertices (same
// position and UV); m's own normals are not used.
TriMesh with_normals(const TriMesh& m, double crease_deg = 40);

// A w × h rectangle centred at `center`, front towards `normal`, its h side along `up` (projected
// into the plane). UVs span [0,1]², u along the w side, v along `up`.
TriMesh make_quad(Vec3 center, Vec3 normal, Vec3 up, double w, double h);
// A disc as a fan of `segments` triangles (the polygon is inscribed in the circle).
TriMesh make_disc(Vec3 center, Vec3 normal, double radius, int segments = 128);
// A UV sphere of `rings` × `segments` quads (the library's one UV-sphere generator); front outwards,
// or inwards when `inward` (the inside of a closed emitter). Its normals are the exact radial ones
// (towards the front); u runs once around (from +X), v from the south pole (0) to the north pole (1).
TriMesh make_sphere(Vec3 center, double radius, int rings = 32, int segments = 64, bool inward = false);
// A cylinder from `base` to base + axis; front outwards; `caps` closes both ends.
TriMesh make_cylinder(Vec3 base, Vec3 axis, double radius, int segments = 48, bool caps = true);
// A closed axis-aligned box, front outwards (an obstacle), or inwards when `inward`.
TriMesh make_box(Vec3 lo, Vec3 hi, bool inward = false);

// The "blob": a bunny-sized lumpy closed object (a unit sphere displaced by a few low-frequency
// lobes, bumps and a pair of ears), about `triangles` triangles, radius ~`size`/2, centred at the
// origin, with smooth vertex normals and the sphere's UVs. It stands in for the Stanford bunny in
// tests and benchmarks: curved, self-shadowing, concave in places.
TriMesh make_blob(int triangles, double size = 0.3);
// A square of side `size` in the plane y = height centred on the y axis, facing +Y (normals +Y);
// UVs span [0,1]² (u along +X, v along −Z).
TriMesh make_floor(double size, double height);

// A rectangular hole in one wall of a room.
struct Opening {
  int axis = 2;         // 0,1,2: the wall is perpendicular to x, y or z
  bool at_max = false;  // the wall at max[axis] (true) or min[axis] (false)
  Vec2 lo, hi;          // the hole's extent in the wall's two other world axes, in x<y<z order (metres)
};

struct RoomDesc {
  Vec3 lo{-2, 0, -2}, hi{2, 3, 2};  // inner bounds of the room, metres
  std::vector<Opening> openings;    // holes in the walls (doors, windows, corridor joints)
  std::array<bool, 6> omit{};       // drop whole walls: −x, +x, −y, +y, −z, +z
};
// The six walls of a box room, front faces inwards, each wall's UVs spanning [0,1]², with the
// openings cut out (each wall is split on the openings' edges into cells; cells inside a hole go).
TriMesh make_room(const RoomDesc& desc);

}  // namespace ibl::geometry
