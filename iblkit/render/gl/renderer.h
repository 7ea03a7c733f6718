// The real-time renderer: OpenGL 4.5 core, headless through EGL. Draws a FrameDesc (render/frame.h)
// with the shading model of render/shading.h: an SH environment or SH grid (RGBA16F 3D texture,
// hardware trilinear; zonal harmonics rotated per fragment, or the basis from a table), a probe's
// prefiltered glossy maps, any number of directional and point lights and textured spotlights in
// one pass with shadow maps, constant or textured Lambert + Phong/Blinn-Phong materials. What it
// keeps on the GPU between frames: uploads.h.
#pragma once
#include <memory>
#include <vector>

#include "iblkit/render/frame.h"
#include "iblkit/render/gl/context.h"

namespace ibl::render::gl {

struct GpuTiming {
  std::vector<double> frame_ms;  // GPU time per frame (GL_TIME_ELAPSED), shadow passes included
  double wall_ms_per_frame = 0;  // CPU wall clock over all frames until glFinish, divided by frames
                                 // (the meaningful figure on software renderers such as llvmpipe,
                                 // whose timer queries are not)
};

struct RendererDesc {
  // Shade in a compute pass over a G-buffer instead of in the fragment shader. Faster on GPUs whose
  // fragment stage runs on few units (the H100: see bench/RESULTS.md); both give the same image.
  bool deferred = true;
  // Draw all layers of a shadow-map array in one instanced pass (the vertex shader picks the layer,
  // GL_ARB_shader_viewport_layer_array) instead of one pass per light. Falls back to passes per
  // light where the extension is missing; both give the same maps.
  bool layered_shadows = true;
  // How shaders evaluate the SH basis at the normal and the reflection vector: 0 (default) by its
  // polynomials per fragment, as Löw et al. did; N > 0 by a lookup in a precomputed table of the
  // basis (a cube-map array with faces of N×N texels, bilinear), the variant they suggested. Max
  // |ΔY| of the table: about 2e-3 at N = 64, 5e-4 at N = 128 (test RenderGl.GlslShTableMatchesCpp).
  int sh_table_size = 0;
};

class Renderer {
 public:
  // Needs a current context (the Context must outlive the Renderer).
  explicit Renderer(const RendererDesc& desc = {});
  ~Renderer();
  // Renders `frames` times (uploads once; frames > 1 for timing) and reads back the last frame —
  // or, with read_back false, leaves it on the GPU in color_texture() (the result's images empty).
  RenderResult render(const FrameDesc& desc, int frames = 1, GpuTiming* timing = nullptr, bool read_back = true);
  // The last frame: an RGBA32F texture (rgb linear radiance, alpha coverage; GL's rows, bottom up),
  // valid until the next render() or the renderer's end; 0 before the first frame.
  unsigned color_texture() const;

  static constexpr int kMaxShadowMaps = 16;     // shadow-casting lights per pass
  static constexpr int kMaxShTableSize = 1024;  // 7 layers × 6 faces × 1024² × 16 B = 704 MB at 5 bands

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ibl::render::gl
