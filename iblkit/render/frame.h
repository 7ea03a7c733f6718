// What both renderers draw: a mesh with a material, seen by a camera, under a lighting.
#pragma once
#include "iblkit/core/image.h"
#include "iblkit/render/camera.h"
#include "iblkit/render/mesh.h"
#include "iblkit/render/shading.h"

namespace ibl::render {

struct RenderObject {
  const Mesh* mesh = nullptr;
  Material material;
};

struct FrameDesc {
  Camera camera;
  std::vector<RenderObject> objects;
  Lighting lighting;
  Vec3 background{0, 0, 0};  // radiance where no surface is hit
  int shadow_map_size = 2048;  // GPU only: shadow map resolution
  double shadow_bias = 2e-3;   // offset along the normal before shadow tests, metres
};

// Per-pixel result: RGB radiance (linear HDR) and coverage.
struct RenderResult {
  Image color;     // width × height × 3
  Image coverage;  // 1 where a surface was hit, else 0
};

}  // namespace ibl::render
