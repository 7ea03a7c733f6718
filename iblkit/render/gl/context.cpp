#include "iblkit/render/gl/context.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include "iblkit/core/error.h"

#if defined(__SANITIZE_ADDRESS__)
#define IBLKIT_LEAK_CHECKED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define IBLKIT_LEAK_CHECKED 1
#endif
#endif
#ifdef IBLKIT_LEAK_CHECKED
#include <dlfcn.h>
#include <link.h>

#include <string>
#include <vector>
#endif

namespace ibl::render::gl {

void keep_drivers_loaded_for_leak_checks() {
#ifdef IBLKIT_LEAK_CHECKED
  std::vector<std::string> names;  // collected first: dlopen is not called under dl_iterate_phdr's lock
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* out) {
        if (info->dlpi_name && info->dlpi_name[0])
          static_cast<std::vector<std::string>*>(out)->push_back(info->dlpi_name);
        return 0;
      },
      &names);
  for (const auto& n : names) ::dlopen(n.c_str(), RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
#endif
}

Context::Context() {
  if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless") &&
      !epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_base"))
    fail(ErrorKind::Unsupported, "EGL has no surfaceless platform (no EGL_MESA_platform_surfaceless)");
  auto get_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_display) fail(ErrorKind::Unsupported, "EGL lacks eglGetPlatformDisplayEXT");
  EGLDisplay dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor))
    fail(ErrorKind::Unsupported, "no EGL display (eglInitialize failed, error 0x{:x})", eglGetError());
  keep_drivers_loaded_for_leak_checks();
  if (!eglBindAPI(EGL_OPENGL_API)) fail(ErrorKind::Unsupported, "EGL cannot bind the OpenGL API");
  const EGLint attribs[] = {
      EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
  if (ctx == EGL_NO_CONTEXT) {
    eglTerminate(dpy);
    fail(ErrorKind::Unsupported, "no OpenGL 4.5 core context (eglCreateContext error 0x{:x})", eglGetError());
  }
  if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
    eglDestroyContext(dpy, ctx);
    eglTerminate(dpy);
    fail(ErrorKind::Unsupported, "eglMakeCurrent failed (error 0x{:x})", eglGetError());
  }
  display_ = dpy;
  context_ = ctx;
}

Context::~Context() {
  auto dpy = static_cast<EGLDisplay>(display_);
  eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(dpy, static_cast<EGLContext>(context_));
  eglTerminate(dpy);
}

std::string Context::renderer() const { return reinterpret_cast<const char*>(glGetString(GL_RENDERER)); }
std::string Context::version() const { return reinterpret_cast<const char*>(glGetString(GL_VERSION)); }

bool available(std::string* why) {
  try {
    Context c;
    return true;
  } catch (const Error& e) {
    if (why) *why = e.what();
    return false;
  }
}

}  // namespace ibl::render::gl
