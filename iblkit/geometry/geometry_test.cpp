#include <gtest/gtest.h>

#include <filesystem>

#include "iblkit/core/error.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/geometry/raytracer.h"

namespace ibl::geometry {
namespace {

constexpr double kAreaTol = 1e-9;   // rectangles: exact up to rounding
constexpr double kFloatTol = 2e-5;  // Embree works in float: distances of a few metres

TEST(GeometryMesh, RoomFacesInwardWithExactArea) {
  RoomDesc d;
  d.lo = {-1, 0, -2};
  d.hi = {3, 2.5, 1};
  TriMesh m = make_room(d);
  Vec3 c = (d.lo + d.hi) * 0.5, s = d.hi - d.lo;
  EXPECT_NEAR(m.total_area(), 2 * (s.x * s.y + s.y * s.z + s.x * s.z), kAreaTol);
  for (size_t i = 0; i < m.triangle_count(); ++i) {
    const Vec3 p = m.positions[m.triangles[i][0]];
    EXPECT_GT(dot(m.normal(i), c - p), 0) << "triangle " << i << " faces outwards";
  }
  make_box(d.lo, d.hi).bounds(&c, &s);
  EXPECT_EQ(c.x, d.lo.x);
  EXPECT_EQ(s.z, d.hi.z);
}

TEST(GeometryMesh, OpeningsAndOmittedWallsRemoveTheirArea) {
  RoomDesc d;
  d.lo = {0, 0, 0};
  d.hi = {4, 3, 5};
  double full = make_room(d).total_area();
  d.openings.push_back({2, true, {1, 0}, {2.5, 2}});  // a door 1.5 × 2 in the +z wall (x, y)
  d.openings.push_back({0, false, {1, 1}, {2, 3}});   // a window 1 × 2 in the −x wall (y, z)
  EXPECT_NEAR(make_room(d).total_area(), full - 3 - 2, kAreaTol);
  d.omit[3] = true;  // no ceiling
  EXPECT_NEAR(make_room(d).total_area(), full - 5 - 20, kAreaTol);
}

TEST(GeometryMesh, PrimitivesHaveTheirAreasAndOrientation) {
  constexpr double kTessTol = 0.01;  // relative: 64-segment and 32×64 tessellations
  TriMesh sph = make_sphere({1, 2, 3}, 0.5, 32, 64);
  EXPECT_NEAR(sph.total_area() / (kFourPi * 0.25), 1.0, kTessTol);
  for (size_t i = 0; i < sph.triangle_count(); ++i)
    ASSERT_GT(dot(sph.normal(i), sph.positions[sph.triangles[i][0]] - Vec3{1, 2, 3}), 0);
  TriMesh in = make_sphere({0, 0, 0}, 1, 8, 16, true);
  for (size_t i = 0; i < in.triangle_count(); ++i) ASSERT_LT(dot(in.normal(i), in.positions[in.triangles[i][0]]), 0);
  TriMesh disc = make_disc({0, 1, 0}, {0, -1, 0}, 0.3, 64);
  EXPECT_NEAR(disc.total_area() / (kPi * 0.09), 1.0, kTessTol);
  for (size_t i = 0; i < disc.triangle_count(); ++i) ASSERT_NEAR(disc.normal(i).y, -1, 1e-12);
  TriMesh cyl = make_cylinder({0, 0, 0}, {0, 2, 0}, 0.5, 64, true);
  EXPECT_NEAR(cyl.total_area() / (kTwoPi * 0.5 * 2 + 2 * kPi * 0.25), 1.0, kTessTol);
  TriMesh q = make_quad({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 2, 3);
  EXPECT_NEAR(q.total_area(), 6, kAreaTol);
  EXPECT_NEAR(q.normal(0).z, 1, 1e-12);
}

// A unit cube of 8 shared corners: within a 40° crease every face keeps its own normal (each corner
// splits into 3 vertices, 24 in all); with 100° all faces meet smoothly and the corners stay shared,
// their normals pointing outwards along the corner's diagonal.
TEST(GeometryMesh, WithNormalsSplitsCornersAtCreases) {
  TriMesh cube;
  for (int i = 0; i < 8; ++i) cube.positions.push_back({i & 1 ? 1.0 : -1.0, i & 2 ? 1.0 : -1.0, i & 4 ? 1.0 : -1.0});
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};  // outward
  for (const auto& f : faces) {
    cube.triangles.push_back({static_cast<uint32_t>(f[0]), static_cast<uint32_t>(f[1]), static_cast<uint32_t>(f[2])});
    cube.triangles.push_back({static_cast<uint32_t>(f[0]), static_cast<uint32_t>(f[2]), static_cast<uint32_t>(f[3])});
  }
  TriMesh hard = with_normals(cube, 40);
  ASSERT_TRUE(hard.has_normals());
  EXPECT_EQ(hard.vertex_count(), 24u);
  EXPECT_EQ(hard.triangle_count(), 12u);
  for (size_t t = 0; t < hard.triangle_count(); ++t)
    for (uint32_t v : hard.triangles[t])
      EXPECT_NEAR(length(hard.normals[v] - hard.normal(t)), 0, 1e-12) << "triangle " << t;
  TriMesh smooth = with_normals(cube, 100);
  EXPECT_EQ(smooth.vertex_count(), 8u);
  for (size_t v = 0; v < 8; ++v) {
    EXPECT_NEAR(length(smooth.normals[v]), 1, 1e-12);
    EXPECT_GT(dot(smooth.normals[v], normalize(smooth.positions[v])), 0.8) << "corner " << v;
  }
}

// The renderers' objects: a sphere's normals are its radii, the blob is closed and faces outwards
// with unit smooth normals, the floor faces +Y with u along +X and v along −Z; normals follow flip,
// transform and append.
TEST(GeometryMesh, RenderObjectsCarryTheirNormals) {
  TriMesh sph = make_sphere({1, 0, 0}, 0.5, 16, 32);
  ASSERT_TRUE(sph.has_normals());
  for (size_t i = 0; i < sph.vertex_count(); ++i)
    ASSERT_NEAR(length(sph.normals[i] - (sph.positions[i] - Vec3{1, 0, 0}) * 2.0), 0, 1e-12);
  EXPECT_THROW(make_sphere({0, 0, 0}, 1, 1, 8), Error);
  TriMesh blob = make_blob(4000, 0.8);
  ASSERT_TRUE(blob.has_normals());
  EXPECT_NEAR(blob.triangle_count(), 4000, 400);
  int outward = 0;
  for (size_t t = 0; t < blob.triangle_count(); ++t)
    outward += dot(blob.normal(t), blob.positions[blob.triangles[t][0]]) > 0;
  EXPECT_GT(outward, 0.99 * blob.triangle_count());
  for (const auto& t : blob.triangles)  // (one vertex at each pole belongs to no triangle)
    for (uint32_t v : t) ASSERT_NEAR(length(blob.normals[v]), 1, 1e-12);
  TriMesh floor = make_floor(2, -0.5);
  ASSERT_TRUE(floor.has_normals() && floor.has_uvs());
  EXPECT_NEAR(floor.total_area(), 4, kAreaTol);
  for (size_t i = 0; i < floor.vertex_count(); ++i) {
    EXPECT_EQ(floor.normals[i].y, 1.0);
    EXPECT_EQ(floor.positions[i].y, -0.5);
    EXPECT_NEAR(floor.uvs[i].x, (floor.positions[i].x + 1) / 2, 1e-12);
    EXPECT_NEAR(floor.uvs[i].y, (1 - floor.positions[i].z) / 2, 1e-12);
  }
  for (size_t t = 0; t < floor.triangle_count(); ++t) EXPECT_NEAR(floor.normal(t).y, 1, 1e-12);
  floor.flip();
  EXPECT_EQ(floor.normals[0].y, -1.0);
  floor.transform(Mat3::rotation({1, 0, 0}, kPi / 2), 1.0, {0, 0, 0});  // −Y turns to −Z
  EXPECT_NEAR(floor.normals[0].z, -1, 1e-12);
  floor.append(make_quad({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 1, 1));  // no normals: the result has none
  EXPECT_FALSE(floor.has_normals());
  EXPECT_TRUE(floor.has_uvs());
}

// Hostile input: Embree aborts on a ray that is not finite or beyond 1.8e18; the ray tracer refuses it first.
TEST(GeometryRayTracer, NonFiniteOrHugeRaysAreErrorsNotAborts) {
  RayTracer rt;
  rt.add(make_box({-1, -1, -1}, {1, 1, 1}, true));
  rt.commit();
  const double nan = std::nan("");
  EXPECT_THROW(rt.intersect({nan, 0, 0}, {0, 1, 0}), Error);
  EXPECT_THROW(rt.intersect({0, 0, 0}, {0, nan, 0}), Error);
  EXPECT_THROW(rt.intersect({1e30, 0, 0}, {0, 1, 0}), Error);
  EXPECT_THROW(rt.occluded({0, 0, 0}, {0, 1, 0}, nan, 1), Error);
  EXPECT_THROW(rt.occluded({0, 0, 0}, {0, 1, 0}, 0, nan), Error);
  EXPECT_TRUE(rt.intersect({0, 0, 0}, {0, 1, 0}).hit);
}

// A sphere of 1e5 × 1e5 quads is refused before anything is allocated.
TEST(GeometryMesh, GeneratedMeshesAreBoundedBeforeAllocating) {
  EXPECT_THROW(make_sphere({0, 0, 0}, 1, 100000, 100000), Error);
  EXPECT_THROW(make_blob(2000000000), Error);
  EXPECT_NO_THROW(make_sphere({0, 0, 0}, 1, 8, 16));
}

TEST(GeometryRayTracer, DistancesInsideABoxAreAnalytic) {
  Vec3 lo{-1, 0, -2}, hi{2, 3, 1}, o{0.3, 1.1, -0.4};
  RayTracer rt;
  rt.add(make_box(lo, hi, true));
  rt.commit();
  for (int i = 0; i < 200; ++i) {
    double th = 0.3 + 2.5 * i / 200.0, ph = 0.7 * i;
    Vec3 d{std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
    double t = 1e30;
    for (int k = 0; k < 3; ++k)
      if (d[k] != 0) t = std::min(t, ((d[k] > 0 ? hi[k] : lo[k]) - o[k]) / d[k]);
    Hit h = rt.intersect(o, d);
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, t, kFloatTol * t);
    EXPECT_TRUE(rt.occluded(o, d, 0, t * 1.01));
    EXPECT_FALSE(rt.occluded(o, d, 0, t * 0.99));
  }
  EXPECT_FALSE(rt.intersect({5, 5, 5}, {1, 0, 0}).hit);
}

TEST(GeometryMeshIo, ObjRoundTripKeepsTrianglesAndArea) {
  auto path = (std::filesystem::temp_directory_path() / "iblkit_geometry_rt.obj").string();
  TriMesh m = make_cylinder({0, 0, 0}, {0, 1, 0}, 0.25, 16, true);
  write_obj(path, m, "round trip");
  TriMesh r = read_mesh(path);
  EXPECT_EQ(r.triangle_count(), m.triangle_count());
  EXPECT_NEAR(r.total_area(), m.total_area(), 1e-4);
  EXPECT_THROW(read_mesh(path + ".missing"), Error);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace ibl::geometry
