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

// Under AddressSanitizer only (a no-op otherwise): keeps every shared object loaded so far resident for the
// process's life. Call it once a GL driver is loaded (Context does, after eglInitialize; a window's context
// after it is made): eglTerminate and glfwTerminate unload Mesa's driver, and LeakSanitizer, which looks at
// exit, then reports the driver's own allocations with no module to name (so that fuzz/lsan.supp's
// "leak:dri" cannot match them) or crashes reading the unloaded driver's thread-local blocks ("Tracer
// caught signal 11"). Promoting each object to RTLD_NODELETE changes nothing else.
void keep_drivers_loaded_for_leak_checks();

}  // namespace ibl::render::gl
