#include "iblkit/render/gl/program.h"

#include <epoxy/gl.h>

#include <map>
#include <regex>
#include <sstream>

#include "iblkit/core/error.h"
#include "iblkit/render/gl/shaders_embedded.h"

namespace ibl::render::gl {

const std::string& shader_source(const std::string& name) {
  static const std::map<std::string, std::string> sources = [] {
    std::map<std::string, std::string> m;
    for (size_t i = 0; i < kEmbeddedShaderCount; ++i) m[kEmbeddedShaders[i].name] = kEmbeddedShaders[i].source;
    return m;
  }();
  auto it = sources.find(name);
  if (it == sources.end()) fail(ErrorKind::Internal, "no embedded shader named {}", name);
  return it->second;
}

namespace {
// Rewrites "0:LINE(COL)" / "0:LINE:" in driver logs to "FILE:LINE".
std::string annotate(const std::string& log, const std::string& file) {
  std::regex re(R"((\d+):(\d+)(\(\d+\))?)");
  std::string out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_search(line, m, re)) line = file + ":" + m[2].str() + ": " + line;
    out += line + "\n";
  }
  return out;
}
}  // namespace

unsigned build_program(const std::vector<ShaderStage>& stages) {
  GLuint prog = glCreateProgram();
  std::vector<GLuint> shaders;
  for (const auto& st : stages) {
    const std::string& src = shader_source(st.name);
    // Insert the prelude after the #version line and restore the file's numbering.
    size_t eol = src.find('\n');
    std::string full = src.substr(0, eol + 1) + st.prelude + "\n#line 2\n" + src.substr(eol + 1);
    GLuint sh = glCreateShader(st.type);
    const char* p = full.c_str();
    glShaderSource(sh, 1, &p, nullptr);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      GLint len = 0;
      glGetShaderiv(sh, GL_INFO_LOG_LENGTH, &len);
      std::string log(static_cast<size_t>(std::max(len, 1)), '\0');
      glGetShaderInfoLog(sh, len, nullptr, log.data());
      glDeleteShader(sh);
      glDeleteProgram(prog);
      fail(ErrorKind::Internal, "shader {} failed to compile:\n{}", st.name, annotate(log, st.name));
    }
    glAttachShader(prog, sh);
    shaders.push_back(sh);
  }
  glLinkProgram(prog);
  for (GLuint sh : shaders) glDeleteShader(sh);
  GLint ok = 0;
  glGetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(prog, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<size_t>(std::max(len, 1)), '\0');
    glGetProgramInfoLog(prog, len, nullptr, log.data());
    glDeleteProgram(prog);
    std::string names;
    for (const auto& st : stages) names += st.name + " ";
    fail(ErrorKind::Internal, "shader program ({}) failed to link:\n{}", names, log);
  }
  return prog;
}

}  // namespace ibl::render::gl
