// Shows a frame of the GL renderer (Renderer::color_texture()) in the bound framebuffer: exposure,
// io::tonemap's tone curve and sRGB encoding in a fragment shader, so that an interactive viewer
// does not read frames back to tone-map them on the CPU. The picture is io::tonemap's, sRGB-encoded
// (test RenderGl.PresentMatchesCpuToneMapping).
#pragma once
#include "iblkit/io/tonemap.h"

namespace ibl::render::gl {

class Presenter {
 public:
  Presenter();  // needs a current context, which must outlive the Presenter
  ~Presenter();
  Presenter(const Presenter&) = delete;
  Presenter& operator=(const Presenter&) = delete;

  // Draws `texture` (RGBA32F linear radiance, width × height, the size of the viewport it goes to)
  // times `scale`, through `curve`, sRGB-encoded, into the currently bound draw framebuffer.
  void draw(unsigned texture, int width, int height, double scale, io::ToneCurve curve = io::ToneCurve::Aces);

 private:
  unsigned program_ = 0, vao_ = 0;
};

}  // namespace ibl::render::gl
