// Ray queries on triangle meshes with Embree 3: closest hit and any hit (shadow rays). Build once,
// query from any number of threads.
#pragma once
#include <cstdint>
#include <limits>
#include <memory>

#include "iblkit/core/vec.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::geometry {

struct Hit {
  bool hit = false;       // false: the ray left the scene
  double t = 0;           // distance along the (unit) ray direction
  uint32_t mesh = 0;      // index of the mesh, in the order add() was called
  uint32_t triangle = 0;  // triangle index inside that mesh
  double b1 = 0, b2 = 0;  // barycentric weights of the triangle's vertices 1 and 2
};

class RayTracer {
 public:
  RayTracer();
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;
  RayTracer(RayTracer&&) noexcept;
  RayTracer& operator=(RayTracer&&) noexcept;

  // Adds a mesh (copied into Embree's buffers); returns its index. Not after commit().
  uint32_t add(const TriMesh& mesh);
  // Builds the acceleration structure. Required before queries.
  void commit();
  uint32_t mesh_count() const;

  // Closest hit along o + t·d, t in (tnear, tfar); d need not be unit but t is in its units.
  Hit intersect(Vec3 o, Vec3 d, double tnear = 0, double tfar = std::numeric_limits<double>::infinity()) const;
  // True when anything lies along o + t·d, t in (tnear, tfar).
  bool occluded(Vec3 o, Vec3 d, double tnear, double tfar) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ibl::geometry
