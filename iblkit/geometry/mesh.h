// Triangle meshes (positions, optional UVs, counter-clockwise triangles seen from the front) and the
// primitives the lab builds scenes from: quads, discs, spheres, cylinders, boxes and box rooms with
// rectangular openings. The front side of a triangle is the side its normal cross(p1−p0, p2−p0)
// points to (the OBJ / glTF convention); emitters emit from the front side only.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "iblkit/core/vec.h"

namespace ibl::geometry {

struct TriMesh {
  std::vector<Vec3> positions;                  // one per vertex, metres
  std::vector<Vec2> uvs;                        // one per vertex, or empty (no texture coordinates)
  std::vector<std::array<uint32_t, 3>> triangles;  // vertex indices, counter-clockwise from the front

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return triangles.size(); }
  // Unit normal of triangle i (front side), zero for a degenerate triangle.
  Vec3 normal(size_t i) const;
  double area(size_t i) const;
  double total_area() const;
  // Axis-aligned bounds; lo > hi when empty.
  void bounds(Vec3* lo, Vec3* hi) const;
  // Appends another mesh (UVs kept only when both have them, or this one is empty).
  void append(const TriMesh& other);
  // p -> rotation·(scale·p) + translation for every vertex.
  void transform(const Mat3& rotation, double scale, Vec3 translation);
  // Turns every triangle around (the front becomes the back).
  void flip();
  // Throws ibl::Error naming `what` on indices out of range or non-finite positions.
  void validate(const std::string& what) const;
};

// A w × h rectangle centred at `center`, front towards `normal`, its h side along `up` (projected
// into the plane). UVs span [0,1]², u along the w side, v along `up`.
TriMesh make_quad(Vec3 center, Vec3 normal, Vec3 up, double w, double h);
// A disc as a fan of `segments` triangles (the polygon is inscribed in the circle).
TriMesh make_disc(Vec3 center, Vec3 normal, double radius, int segments = 128);
// A UV sphere; front outwards, or inwards when `inward` (the inside of a closed emitter).
TriMesh make_sphere(Vec3 center, double radius, int rings = 32, int segments = 64, bool inward = false);
// A cylinder from `base` to base + axis; front outwards; `caps` closes both ends.
TriMesh make_cylinder(Vec3 base, Vec3 axis, double radius, int segments = 48, bool caps = true);
// A closed axis-aligned box, front outwards (an obstacle), or inwards when `inward`.
TriMesh make_box(Vec3 lo, Vec3 hi, bool inward = false);

// A rectangular hole in one wall of a room.
struct Opening {
  int axis = 2;        // 0,1,2: the wall is perpendicular to x, y or z
  bool at_max = false; // the wall at max[axis] (true) or min[axis] (false)
  Vec2 lo, hi;         // the hole's extent in the wall's two other world axes, in x<y<z order (metres)
};

struct RoomDesc {
  Vec3 lo{-2, 0, -2}, hi{2, 3, 2};   // inner bounds of the room, metres
  std::vector<Opening> openings;      // holes in the walls (doors, windows, corridor joints)
  std::array<bool, 6> omit{};        // drop whole walls: −x, +x, −y, +y, −z, +z
};
// The six walls of a box room, front faces inwards, each wall's UVs spanning [0,1]², with the
// openings cut out (each wall is split on the openings' edges into cells; cells inside a hole go).
TriMesh make_room(const RoomDesc& desc);

}  // namespace ibl::geometry
