#include "iblkit/render/gl/sh_glsl.h"

#include <cmath>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/core/vec.h"
#include "iblkit/render/gl/program.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sphere/mapping.h"

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
      if (l == m)
        s += "  p0 = pmm;\n";
      else if (l == m + 1)
        s += fmt::format("  p1 = p0; p0 = {:.1f} * z * pmm;\n", 2.0 * m + 1);
      else
        s += fmt::format("  p2 = p1; p1 = p0; p0 = ({:.1f} * z * p1 - {:.1f} * p2) * {:.17g};\n", 2.0 * l - 1,
                         static_cast<double>(l + m - 1), 1.0 / (l - m));
      const double k = sh::norm_constant(l, m);  // the C++ basis's own constant (√2 included for m > 0)
      if (m == 0) {
        s += fmt::format("  Y[{}] = {:.17g} * p0;\n", l * (l + 1), k);
      } else {
        s += fmt::format("  Y[{}] = {:.17g} * p0 * C; Y[{}] = {:.17g} * p0 * S;\n", l * (l + 1) + m, k, l * (l + 1) - m,
                         k);
      }
    }
  }
  s += "}\n";
  return s;
}

std::string sh_table_glsl_source(int bands) {
  if (bands < 1 || bands > 10) fail(ErrorKind::Value, "GLSL SH supports 1..10 bands (got {})", bands);
  // The faces' outer texel centres lie on the cube's edges (sh_table_texels), and the lookup
  // shrinks the two minor components by u_sh_table_warp = (size − 1)/size so that they land there:
  // bilinear filtering then never crosses a face edge, where interpolating between two faces at
  // 90° would cost first-order error.
  return fmt::format(
      "#define SH_BANDS {0}\n#define SH_K {1}\n"
      "uniform samplerCubeArray u_sh_table;\n"
      "uniform float u_sh_table_warp;\n"
      "void sh_eval(vec3 d, out float Y[SH_K]) {{\n"
      "  vec3 a = abs(d);\n"
      "  vec3 w = a.x >= a.y && a.x >= a.z ? vec3(1.0, u_sh_table_warp, u_sh_table_warp)\n"
      "         : (a.y >= a.z ? vec3(u_sh_table_warp, 1.0, u_sh_table_warp) : vec3(u_sh_table_warp, u_sh_table_warp, "
      "1.0));\n"
      "  vec3 q = d * w;\n"
      "  for (int j = 0; j < {2}; ++j) {{\n"
      "    vec4 v = textureLod(u_sh_table, vec4(q, float(j)), 0.0);\n"
      "    for (int c = 0; c < 4; ++c) if (4 * j + c < SH_K) Y[4 * j + c] = v[c];\n"
      "  }}\n}}\n",
      bands, bands * bands, (bands * bands + 3) / 4);
}

float sh_table_warp(int size) { return static_cast<float>(size - 1) / static_cast<float>(size); }

std::vector<float> sh_table_texels(int bands, int size) {
  if (bands < 1 || bands > 10) fail(ErrorKind::Value, "SH table supports 1..10 bands (got {})", bands);
  if (size < 2 || size > 4096) fail(ErrorKind::Value, "SH table face size {} is out of range 2..4096", size);
  const int K = bands * bands, layers = (K + 3) / 4;
  std::vector<float> out(static_cast<size_t>(layers) * 6 * size * size * 4, 0.0f);
  std::vector<double> Y(K);
  for (int f = 0; f < 6; ++f)
    for (int t = 0; t < size; ++t)
      for (int s = 0; s < size; ++s) {
        // Texel centres from edge to edge: face coordinate (2i + 1 − size)/(size − 1) ∈ [−1, 1].
        const double sc = (2.0 * s + 1 - size) / (size - 1), tc = (2.0 * t + 1 - size) / (size - 1);
        sh::eval_basis(bands, normalize(sphere::cube_face_point(f, sc, tc)), Y.data());  // GL's face order and axes
        for (int k = 0; k < K; ++k) {
          const size_t layer_face = static_cast<size_t>(k / 4) * 6 + f;
          out[((layer_face * size + t) * size + s) * 4 + k % 4] = static_cast<float>(Y[k]);
        }
      }
  return out;
}

unsigned make_sh_table_texture(int bands, int size) {
  const std::vector<float> texels = sh_table_texels(bands, size);
  const int layers = (bands * bands + 3) / 4;
  GLuint tex = 0;
  glCreateTextures(GL_TEXTURE_CUBE_MAP_ARRAY, 1, &tex);
  glTextureStorage3D(tex, 1, GL_RGBA32F, size, size, 6 * layers);
  glTextureSubImage3D(tex, 0, 0, 0, 0, size, size, 6 * layers, GL_RGBA, GL_FLOAT, texels.data());
  glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return tex;
}

std::vector<float> sh_eval_on_gl(int bands, const std::vector<Vec3>& directions, int table_size) {
  GLuint prog = build_program(
      {{GL_COMPUTE_SHADER, "sh_eval.comp", table_size > 0 ? sh_table_glsl_source(bands) : sh_glsl_source(bands)}});
  GLuint table = table_size > 0 ? make_sh_table_texture(bands, table_size) : 0;
  if (table) {
    glBindTextureUnit(7, table);
    glProgramUniform1i(prog, glGetUniformLocation(prog, "u_sh_table"), 7);
    glProgramUniform1f(prog, glGetUniformLocation(prog, "u_sh_table_warp"), sh_table_warp(table_size));
  }
  const int K = bands * bands, n = static_cast<int>(directions.size());
  std::vector<float> dirs(static_cast<size_t>(n) * 4, 0.0f);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) dirs[i * 4 + c] = static_cast<float>(directions[i][c]);
  GLuint buf[2];
  glCreateBuffers(2, buf);
  glNamedBufferStorage(buf[0], static_cast<GLsizeiptr>(dirs.size() * sizeof(float)), dirs.data(), 0);
  glNamedBufferStorage(buf[1], static_cast<GLsizeiptr>(static_cast<size_t>(n) * K * sizeof(float)), nullptr,
                       GL_MAP_READ_BIT);
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
  if (table) glDeleteTextures(1, &table);
  return out;
}

}  // namespace ibl::render::gl
