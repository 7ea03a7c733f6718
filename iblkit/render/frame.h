// What both renderers draw: a mesh with a material, seen by a camera, under a lighting.
#pragma once
#include "iblkit/core/image.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/render/mesh.h"
#include "iblkit/render/shading.h"

namespace ibl::render {

struct RenderObject {
  const Mesh* mesh = nullptr;
  Material material;
};

struct FrameDesc {
  geometry::Camera camera;
  std::vector<RenderObject> objects;
  Lighting lighting;
  Vec3 background{0, 0, 0};  // radiance where no surface is hit
  int shadow_map_size = 2048;  // GPU only: shadow map resolution
  int spot_shadow_map_size = 512;   // GPU only: shadow map resolution of each textured spotlight (63 of
                                    // them for a 9×7 luminaire: 16 M depth texels a frame at 512²)
  double spot_shadow_share = 0;  // GPU only, metres: textured spotlights shining the same way within
                                 // this distance of a group's first member share one shadow map,
                                 // from the group's mean position (0: a map each)
  double shadow_bias = 2e-3;   // offset along the normal before shadow tests, metres
};

// Per-pixel result: RGB radiance (linear HDR) and coverage.
struct RenderResult {
  Image color;     // width × height × 3
  Image coverage;  // 1 where a surface was hit, else 0
  int unshadowed_lights = 0;  // GPU: shadow-casting lights drawn without a shadow map (beyond
                              // gl::Renderer::kMaxShadowMaps, or point lights inside the objects'
                              // bounding sphere); 0 on the CPU, whose shadow rays serve every light
};

}  // namespace ibl::render
