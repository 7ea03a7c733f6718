#include "iblkit/render/gl/sh_glsl.h"

#include <cmath>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/core/vec.h"
#include "iblkit/render/gl/program.h"
#include "iblkit/sh/basis.h"

namespace ibl::render::gl {

// The recurrence of iblkit/sh/basis.h, unrolled into GLSL with sh::norm_constant's values:
//   Y_l0 = K_l0 P̃_l0(z),  Y_l±m = K_lm P̃_lm(z) · {Re, Im}(x + iy)^m,
// P̃_mm = (2m−1)!!, P̃_{m+1,m} = (2m+1) z P̃_mm, P̃_lm = ((2l−1) z P̃_{l−1,m} − (l+m−1) P̃_{l−2,m}) / (l−m).
std::string sh_glsl_source(int bands) {
  if (bands < 1 || bands > 10) fail(ErrorKind::Value, "GLSL SH supports 1..10 bands (got {})", bands);
  std::string s = fmt::format("#define SH_BANDS {}\n#define SH_K {}\n", bands, bands * bands);
  s += "void sh_eval(vec3 d, out float Y[SH_K]) {\n  float x = d.x, y = d.y, z = d.z;\n";
  s += "  float C = 1.0, S = 0.0, pmm = 1.0, p0, p1, p2;\n";
  for (int m = 0; m < bands; ++m) {
    if (m > 0) {
      s += fmt::format("  {{ float c = C * x - S * y; S = C * y + S * x; C = c; }} pmm *= {:.1f};\n", 2.0 * m - 1);
    }
    for (int l = m; l < bands; ++l) {
      if (l == m) s += "  p0 = pmm;\n";
      else if (l == m + 1) s += fmt::format("  p1 = p0; p0 = {:.1f} * z * pmm;\n", 2.0 * m + 1);
      else
        s += fmt::format("  p2 = p1; p1 = p0; p0 = ({:.1f} * z * p1 - {:.1f} * p2) * {:.17g};\n", 2.0 * l - 1,
                         static_cast<double>(l + m - 1), 1.0 / (l - m));
      const double k = sh::norm_constant(l, m);  // the C++ basis's own constant (√2 included for m > 0)
      if (m == 0) {
        s += fmt::format("  Y[{}] = {:.17g} * p0;\n", l * (l + 1), k);
      } else {
        s += fmt::format("  Y[{}] = {:.17g} * p0 * C; Y[{}] = {:.17g} * p0 * S;\n", l * (l + 1) + m, k, l * (l + 1) - m, k);
      }
    }
  }
  s += "}\n";
  return s;
}

std::vector<float> sh_eval_on_gl(int bands, const std::vector<Vec3>& directions) {
  GLuint prog = build_program({{GL_COMPUTE_SHADER, "sh_eval.comp", sh_glsl_source(bands)}});
  const int K = bands * bands, n = static_cast<int>(directions.size());
  std::vector<float> dirs(static_cast<size_t>(n) * 4, 0.0f);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) dirs[i * 4 + c] = static_cast<float>(directions[i][c]);
  GLuint buf[2];
  glCreateBuffers(2, buf);
  glNamedBufferStorage(buf[0], static_cast<GLsizeiptr>(dirs.size() * sizeof(float)), dirs.data(), 0);
  glNamedBufferStorage(buf[1], static_cast<GLsizeiptr>(static_cast<size_t>(n) * K * sizeof(float)), nullptr, GL_MAP_READ_BIT);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buf[0]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buf[1]);
  glUseProgram(prog);
  glUniform1i(glGetUniformLocation(prog, "u_count"), n);
  glDispatchCompute(static_cast<GLuint>((n + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<float> out(static_cast<size_t>(n) * K);
  glGetNamedBufferSubData(buf[1], 0, static_cast<GLsizeiptr>(out.size() * sizeof(float)), out.data());
  glDeleteBuffers(2, buf);
  glDeleteProgram(prog);
  return out;
}

}  // namespace ibl::render::gl
