// A headless OpenGL 4.5 core context through EGL (surfaceless: Mesa's llvmpipe without a GPU,
// NVIDIA's driver on the device machine). Rendering goes into framebuffer objects.
#pragma once
#include <memory>
#include <string>

namespace ibl::render::gl {

class Context {
 public:
  // Creates and makes current a context; throws ibl::Error (kind Unsupported) with the reason when
  // no EGL display or no GL 4.5 core context can be had.
  Context();
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  std::string renderer() const;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version() const;   // GL_VERSION

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
};

// True when a context can be created here (for tests that skip without GL).
bool available(std::string* why = nullptr);

}  // namespace ibl::render::gl
