// GLSL programs from iblkit's embedded shader files. Compile and link errors surface as ibl::Error
// naming the shader file and line.
#pragma once
#include <string>
#include <vector>

namespace ibl::render::gl {

// Source of an embedded shader file (iblkit/render/gl/shaders/NAME), compiled into the binary.
const std::string& shader_source(const std::string& name);

struct ShaderStage {
  unsigned type;                           // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, …
  std::string name;                        // file name, for messages
  std::string prelude;                     // code inserted after the #version line (generated constants, defines)
  std::vector<std::string> includes = {};  // embedded files inserted after the prelude (shading.glsl)
};

// Compiles and links; returns the program object. Compile errors name the file and line they are
// in: the stage's file, an included file, or "(generated prelude, line N)".
unsigned build_program(const std::vector<ShaderStage>& stages);

}  // namespace ibl::render::gl
