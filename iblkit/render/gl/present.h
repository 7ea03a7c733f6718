// Shows a frame of the GL renderer (Renderer::color_texture()) in the bound framebuffer: exposure,
// io::tonemap's tone curve and sRGB encoding in a fragment shader, so that an interactive viewer
// does not read frames back to tone-map them on the CPU. The picture is io::tonemap's, sRGB-encoded
// (test RenderGl.PresentMatchesCpuToneMapping).
#pragma once
#include "iblkit/core/image.h"
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

// A small picture shown over the frame (the viewer's error-volume slice): `set` quantises an image of
// display values (3 channels in [0, 1], already sRGB-encoded; row 0 at the top) to 8 bits and keeps
// it in a texture; `draw` copies it, nearest-neighbour and stretched, into pixels [x, x + w) × [y,
// y + h) of the bound draw framebuffer (GL's y, from the bottom), byte for byte (sRGB conversion off).
class Overlay {
 public:
  Overlay();  // needs a current context, which must outlive the Overlay
  ~Overlay();
  Overlay(const Overlay&) = delete;
  Overlay& operator=(const Overlay&) = delete;

  void set(const Image& display);
  void draw(int x, int y, int w, int h) const;
  int width() const { return w_; }
  int height() const { return h_; }

 private:
  unsigned texture_ = 0, fbo_ = 0;
  int w_ = 0, h_ = 0;
};

}  // namespace ibl::render::gl
