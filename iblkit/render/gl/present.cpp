#include "iblkit/render/gl/present.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "iblkit/core/error.h"

#include "iblkit/core/vec.h"
#include "iblkit/render/gl/program.h"

namespace ibl::render::gl {

Presenter::Presenter() {
  program_ = build_program({{GL_VERTEX_SHADER, "present.vert", ""}, {GL_FRAGMENT_SHADER, "present.frag", ""}});
  glCreateVertexArrays(1, &vao_);  // the triangle comes from gl_VertexID; core profile needs a VAO bound
}

Presenter::~Presenter() {
  glDeleteVertexArrays(1, &vao_);
  glDeleteProgram(program_);
}

void Presenter::draw(unsigned texture, int width, int height, double scale, io::ToneCurve curve) {
  glUseProgram(program_);
  glProgramUniform1f(program_, glGetUniformLocation(program_, "u_scale"), static_cast<float>(scale));
  glProgramUniform1i(program_, glGetUniformLocation(program_, "u_curve"),
                     curve == io::ToneCurve::Clamp ? 0 : (curve == io::ToneCurve::Reinhard ? 1 : 2));
  glProgramUniform3f(program_, glGetUniformLocation(program_, "u_luminance"), static_cast<float>(kLumR),
                     static_cast<float>(kLumG), static_cast<float>(kLumB));
  glBindTextureUnit(0, texture);
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindTextureUnit(0, 0);  // the frame is the renderer's target again next frame
}

Overlay::Overlay() { glCreateFramebuffers(1, &fbo_); }

Overlay::~Overlay() {
  glDeleteFramebuffers(1, &fbo_);
  if (texture_) glDeleteTextures(1, &texture_);
}

void Overlay::set(const Image& img) {
  if (img.width() < 1 || img.height() < 1 || img.channels() < 3)
    fail(ErrorKind::Value, "overlay: expected an RGB image, got {}x{}x{}", img.width(), img.height(), img.channels());
  if (img.width() != w_ || img.height() != h_) {
    if (texture_) glDeleteTextures(1, &texture_);
    glCreateTextures(GL_TEXTURE_2D, 1, &texture_);
    glTextureStorage2D(texture_, 1, GL_RGBA8, img.width(), img.height());
    glNamedFramebufferTexture(fbo_, GL_COLOR_ATTACHMENT0, texture_, 0);
    w_ = img.width();
    h_ = img.height();
  }
  std::vector<uint8_t> px(static_cast<size_t>(w_) * h_ * 4, 255);
  for (int y = 0; y < h_; ++y)
    for (int x = 0; x < w_; ++x)
      for (int c = 0; c < 3; ++c) {
        const float v = img.at(x, y, c);
        px[(static_cast<size_t>(h_ - 1 - y) * w_ + x) * 4 + c] = static_cast<uint8_t>(
            std::lround(255.0 * std::clamp(std::isfinite(v) ? double(v) : 0.0, 0.0, 1.0)));  // GL rows go up
      }
  glTextureSubImage2D(texture_, 0, 0, 0, w_, h_, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
}

void Overlay::draw(int x, int y, int w, int h) const {
  if (!texture_ || w < 1 || h < 1) return;
  GLint draw_fb = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_fb);
  const GLboolean srgb = glIsEnabled(GL_FRAMEBUFFER_SRGB);
  glDisable(GL_FRAMEBUFFER_SRGB);
  glBlitNamedFramebuffer(fbo_, static_cast<GLuint>(draw_fb), 0, 0, w_, h_, x, y, x + w, y + h, GL_COLOR_BUFFER_BIT,
                         GL_NEAREST);
  if (srgb) glEnable(GL_FRAMEBUFFER_SRGB);
}

}  // namespace ibl::render::gl
