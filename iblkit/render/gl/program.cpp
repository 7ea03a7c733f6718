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
// The code inserted before a shader file is numbered in blocks of kBlock lines: the prelude from
// kBlock + 1, include i from (i + 2)·kBlock + 1 (drivers do not all honour #line's source-string
// number; Mesa reports 0 whatever it is told).
constexpr long kBlock = 100000;

// Prefixes each message of a driver's log with where it points: "FILE:LINE: " for the shader file
// or an included file, "FILE (generated prelude, line N): " for the generated code. Mesa writes
// "0:LINE(COLUMN): …", NVIDIA "0(LINE) : …".
std::string annotate(const std::string& log, const std::string& file, const std::vector<std::string>& includes) {
  std::regex re(R"(^\s*(\d+)(?::(\d+)\(\d+\)|\((\d+)\)))");
  std::string out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_search(line, m, re)) {
      const long at = std::stol(m[2].matched ? m[2].str() : m[3].str()), block = at / kBlock, n = at % kBlock;
      std::string where = file + ":" + std::to_string(at);
      if (block == 1) where = file + " (generated prelude, line " + std::to_string(n) + ")";
      if (block >= 2 && block - 2 < static_cast<long>(includes.size()))
        where = includes[block - 2] + ":" + std::to_string(n);
      line = where + ": " + line;
    }
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
    // Insert the prelude after the #version line (and any #extension lines, which must come first),
    // numbered from kPreludeLine + 1, and restore the file's numbering after it.
    size_t eol = src.find('\n');
    int line = 2;
    while (src.compare(eol + 1, 10, "#extension") == 0) {
      eol = src.find('\n', eol + 1);
      ++line;
    }
    std::string full = src.substr(0, eol + 1) + "#line " + std::to_string(kBlock + 1) + "\n" + st.prelude + "\n";
    for (size_t i = 0; i < st.includes.size(); ++i)
      full += "#line " + std::to_string((i + 2) * kBlock + 1) + "\n" + shader_source(st.includes[i]) + "\n";
    full += "#line " + std::to_string(line) + "\n" + src.substr(eol + 1);
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
      fail(ErrorKind::Internal, "shader {} failed to compile:\n{}", st.name, annotate(log, st.name, st.includes));
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
