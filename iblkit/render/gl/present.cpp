#include "iblkit/render/gl/present.h"

#include <epoxy/gl.h>

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
  glProgramUniform3f(program_, glGetUniformLocation(program_, "u_luminance"), static_cast<float>(kLumR), static_cast<float>(kLumG),
                     static_cast<float>(kLumB));
  glBindTextureUnit(0, texture);
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindTextureUnit(0, 0);  // the frame is the renderer's target again next frame
}

}  // namespace ibl::render::gl
