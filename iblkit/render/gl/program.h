// GLSL programs from iblkit's embedded shader files. Compile and link errors surface as ibl::Error
// naming the shader file and line.
#pragma once
#include <string>
#include <vector>

namespace ibl::render::gl {

// Source of an embedded shader file (iblkit/render/gl/shaders/NAME), compiled into the binary.
const std::string& shader_source(const std::string& name);

struct ShaderStage {
  unsigned type;        // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, …
  std::string name;     // file name, for messages
  std::string prelude;  // code inserted after the #version line (generated constants, defines)
};

// Compiles and links; returns the program object. Line numbers in messages refer to the file
// (the prelude is accounted for with a #line directive).
unsigned build_program(const std::vector<ShaderStage>& stages);

}  // namespace ibl::render::gl
