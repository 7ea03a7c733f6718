// What both renderers draw: a mesh with a material, seen by a camera, under a lighting.
#pragma once
#include "iblkit/core/image.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/render/shading.h"

namespace ibl::render {

struct RenderObject {
  const geometry::TriMesh* mesh = nullptr;  // with vertex normals (geometry::with_normals); both
                                            // renderers read its positions, normals and UVs at float
                                            // precision (the GPU's)
  Material material;
};

struct FrameDesc {
  geometry::Camera camera;
  std::vector<RenderObject> objects;
  Lighting lighting;
  Vec3 background{0, 0, 0};        // radiance where no surface is hit
  int shadow_map_size = 2048;      // GPU only: shadow map resolution
  int spot_shadow_map_size = 512;  // GPU only: shadow map resolution of each textured spotlight (63 of
                                   // them for a 9×7 luminaire: 16 M depth texels a frame at 512²)
  double spot_shadow_share = 0;    // GPU only, metres: textured spotlights shining the same way within
                                   // this distance of a group's first member share one shadow map,
                                   // from the group's mean position (0: a map each)
  double shadow_bias = 2e-3;       // offset along the normal before shadow tests, metres
};

// Throws ibl::Error unless the camera passes geometry::require_camera and every object has a mesh
// with one normal per vertex (both renderers call it; a mesh without UVs, or with too few, reads its
// texture at (0,0)).
void check_objects(const FrameDesc& d);

// Per-pixel result: RGB radiance (linear HDR) and coverage.
struct RenderResult {
  Image color;                // width × height × 3
  Image coverage;             // 1 where a surface was hit, else 0
  int unshadowed_lights = 0;  // GPU: shadow-casting lights drawn without a shadow map (beyond
                              // gl::Renderer::kMaxShadowMaps, or point lights inside the objects'
                              // bounding sphere); 0 on the CPU, whose shadow rays serve every light
};

}  // namespace ibl::render
