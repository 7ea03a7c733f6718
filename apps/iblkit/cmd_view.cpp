// iblkit view: an interactive window (GLFW) on the real-time renderer. Orbit the camera, move the
// object through an SH grid's volume or a light set, switch between several --light files, see the
// frame time. With --frames N it runs N frames on its own (orbiting) and exits: how the tests drive
// it under Xvfb.
#if defined(IBLKIT_HAVE_GL) && defined(IBLKIT_HAVE_GLFW)
#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "cli.h"
#include "render_setup.h"
#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/render/gl/present.h"
#include "iblkit/render/gl/renderer.h"

namespace {

using namespace ibl;
using namespace ibl::render;

struct ViewOpts {
  std::string scene = "blob", size = "960x720", at = "0,0,0", screenshot;
  std::vector<std::string> lights;
  double object_size = 0.8, gloss = 0.15, exponent = 20, exposure = 0, floor_size = 6;
  int triangles = 100000, bands = 5, shadows = 4, frames = 0;
  iblcli::ShadowMapOptions shadow_maps;
};

// Orbit camera around a target: azimuth, elevation (radians) and distance.
struct Orbit {
  Vec3 target;
  double azimuth = 0, elevation = 0.35, distance = 2;
  Vec3 eye() const {
    return target + Vec3{std::sin(azimuth) * std::cos(elevation), std::sin(elevation), std::cos(azimuth) * std::cos(elevation)} * distance;
  }
};

struct State {
  Orbit orbit;
  Vec3 offset;          // object displacement from --at
  int lighting = 0;     // index into the loaded lightings
  bool glossy = true;
  double exposure = 0;  // stops added to the auto exposure
  bool remeter = false;  // measure the auto exposure again on the next frame
  bool dragging = false;
  double last_x = 0, last_y = 0;
  double step = 0.05;   // metres per key press
};

void run(const ViewOpts& o, const ibl::io::EnvReadDesc& rd) {
  int w = 0, h = 0;
  if (std::sscanf(o.size.c_str(), "%dx%d", &w, &h) != 2 || w < 16 || h < 16 || w > 8192 || h > 8192)
    fail(ErrorKind::Value, "--size '{}': expected WxH, e.g. 960x720", o.size);
  // Everything that can fail on input is read before a window opens.
  iblcli::LightingOptions lopt;
  lopt.bands = o.bands;
  lopt.shadows = o.shadows;
  lopt.glossy_exponent = o.gloss > 0 ? o.exponent : 0.0;
  lopt.read = rd;
  std::vector<Lighting> lightings(o.lights.size());
  std::vector<std::string> kinds(o.lights.size());
  for (size_t i = 0; i < o.lights.size(); ++i)
    iblcli::load_lighting(o.lights[i], lopt, &lightings[i], &kinds[i]);
  const Vec3 at = iblcli::parse_vec3(o.at, "--at");
  const Mesh base = iblcli::make_object(o.scene, o.object_size, o.triangles, {0, 0, 0});
  {
    Mesh placed = base;
    placed.transform(1.0, at);
    for (const Lighting& L : lightings)
      if (std::string w = iblcli::grid_bounds_warning(L, placed); !w.empty()) iblcli::info("warning: " + w);
  }

  if (!glfwInit()) fail(ErrorKind::Unsupported, "no display: GLFW could not initialise (is DISPLAY set? try xvfb-run)");
  struct Terminate { ~Terminate() { glfwTerminate(); } } terminate;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  // EGL, as the headless renderer uses: libepoxy then finds the context whatever the X server.
  glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
  GLFWwindow* win = glfwCreateWindow(w, h, "iblkit view", nullptr, nullptr);
  if (!win) fail(ErrorKind::Unsupported, "no window with an OpenGL 4.5 core context could be opened on this display");
  glfwMakeContextCurrent(win);
  glfwSwapInterval(o.frames > 0 ? 0 : 1);

  State st;
  st.orbit.target = at;
  st.orbit.distance = 2.2 * o.object_size;
  st.exposure = o.exposure;
  st.glossy = o.gloss > 0;
  st.step = 0.1 * o.object_size;
  glfwSetWindowUserPointer(win, &st);
  glfwSetKeyCallback(win, [](GLFWwindow* wnd, int key, int, int action, int) {
    if (action == GLFW_RELEASE) return;
    auto& s = *static_cast<State*>(glfwGetWindowUserPointer(wnd));
    switch (key) {
      case GLFW_KEY_ESCAPE: case GLFW_KEY_Q: glfwSetWindowShouldClose(wnd, GLFW_TRUE); break;
      case GLFW_KEY_LEFT: s.offset.x -= s.step; break;
      case GLFW_KEY_RIGHT: s.offset.x += s.step; break;
      case GLFW_KEY_UP: s.offset.z -= s.step; break;
      case GLFW_KEY_DOWN: s.offset.z += s.step; break;
      case GLFW_KEY_PAGE_UP: s.offset.y += s.step; break;
      case GLFW_KEY_PAGE_DOWN: s.offset.y -= s.step; break;
      case GLFW_KEY_G: s.glossy = !s.glossy; break;
      case GLFW_KEY_E: s.remeter = true; break;
      case GLFW_KEY_EQUAL: case GLFW_KEY_KP_ADD: s.exposure += 0.5; break;
      case GLFW_KEY_MINUS: case GLFW_KEY_KP_SUBTRACT: s.exposure -= 0.5; break;
      case GLFW_KEY_TAB: ++s.lighting; break;
      default:
        if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) s.lighting = key - GLFW_KEY_1;
    }
  });
  glfwSetMouseButtonCallback(win, [](GLFWwindow* wnd, int button, int action, int) {
    auto& s = *static_cast<State*>(glfwGetWindowUserPointer(wnd));
    if (button == GLFW_MOUSE_BUTTON_LEFT) s.dragging = action == GLFW_PRESS;
    glfwGetCursorPos(wnd, &s.last_x, &s.last_y);
  });
  glfwSetCursorPosCallback(win, [](GLFWwindow* wnd, double x, double y) {
    auto& s = *static_cast<State*>(glfwGetWindowUserPointer(wnd));
    if (s.dragging) {
      s.orbit.azimuth -= (x - s.last_x) * 0.01;
      s.orbit.elevation = std::clamp(s.orbit.elevation + (y - s.last_y) * 0.01, -1.5, 1.5);
    }
    s.last_x = x;
    s.last_y = y;
  });
  glfwSetScrollCallback(win, [](GLFWwindow* wnd, double, double dy) {
    auto& s = *static_cast<State*>(glfwGetWindowUserPointer(wnd));
    s.orbit.distance = std::max(0.01, s.orbit.distance * std::pow(0.9, dy));
  });

  auto renderer_ptr = std::make_unique<gl::Renderer>();  // released before the window's context goes
  gl::Renderer& renderer = *renderer_ptr;
  auto present = std::make_unique<gl::Presenter>();
  Image last;
  double ms_sum = 0, meter = 1, shown_scale = 1;
  int frame = 0, metered_lighting = -1, shown_w = 0, shown_h = 0;
  // The window's back buffer, read back and turned into linear radiance (what the display shows).
  auto capture = [](int fw, int fh) {
    std::vector<float> px(static_cast<size_t>(fw) * fh * 3);
    glReadBuffer(GL_BACK);
    glReadnPixels(0, 0, fw, fh, GL_RGB, GL_FLOAT, static_cast<GLsizei>(px.size() * sizeof(float)), px.data());
    Image shot(fw, fh, 3);
    for (int y = 0; y < fh; ++y)
      for (int x = 0; x < fw; ++x)
        for (int c = 0; c < 3; ++c) {
          float v = px[(static_cast<size_t>(fh - 1 - y) * fw + x) * 3 + c];  // GL rows go up
          shot.at(x, y, c) = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);  // back to linear
        }
    return shot;
  };
  std::string renderer_name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  while (!glfwWindowShouldClose(win) && (o.frames == 0 || frame < o.frames)) {
    if (o.frames > 0) st.orbit.azimuth = 2 * kPi * frame / o.frames;  // scripted: one turn
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(win, &fw, &fh);
    if (fw < 1 || fh < 1) {
      glfwWaitEvents();
      continue;
    }
    const int li = static_cast<int>(st.lighting % static_cast<int>(lightings.size()));
    FrameDesc d;
    d.camera.width = fw;
    d.camera.height = fh;
    o.shadow_maps.apply(&d);
    d.camera.target = at + st.offset;
    st.orbit.target = d.camera.target;
    d.camera.eye = st.orbit.eye();
    Mesh object = base;
    object.transform(1.0, at + st.offset);
    Vec3 lo, hi;
    object.bounds(&lo, &hi);
    Mesh floor = make_floor(o.floor_size, lo.y - 1e-3);
    floor.transform(1.0, {at.x + st.offset.x, 0, at.z + st.offset.z});
    Material mat{{0.75, 0.75, 0.75}, Vec3{1, 1, 1} * (st.glossy ? std::max(o.gloss, 0.15) : 0.0), o.exponent};
    d.objects = {{&object, mat}, {&floor, Material{{0.5, 0.5, 0.5}, {0, 0, 0}, 1}}};
    d.lighting = std::move(lightings[li]);  // lent to the frame, not copied (an SH grid is megabytes)
    gl::GpuTiming t;
    auto t0 = std::chrono::steady_clock::now();
    // The frame stays on the GPU and is tone-mapped there; it is read back only to meter the auto
    // exposure (median luminance, as `render` does) when the lighting changes or on key E.
    const bool meter_now = li != metered_lighting || st.remeter;
    RenderResult f;
    try {
      f = renderer.render(d, 1, &t, meter_now);
    } catch (...) {
      lightings[li] = std::move(d.lighting);
      throw;
    }
    lightings[li] = std::move(d.lighting);
    if (meter_now) {
      meter = io::auto_exposure_scale(f.color);
      metered_lighting = li;
      st.remeter = false;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    shown_w = fw;
    shown_h = fh;
    shown_scale = meter * std::exp2(st.exposure);
    present->draw(renderer.color_texture(), fw, fh, shown_scale);
    // The screenshot reads the window's own back buffer: what the display path shows.
    if (!o.screenshot.empty() && o.frames > 0 && frame + 1 == o.frames) last = capture(fw, fh);
    glfwSwapBuffers(win);
    double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ms_sum += ms;
    ++frame;
    bool software = renderer_name.find("llvmpipe") != std::string::npos;
    glfwSetWindowTitle(win, fmt::format("iblkit view — {} — {} {:.2f} ms/frame ({}){}", std::filesystem::path(o.lights[li]).filename().string(),
                                        software ? "wall" : "GPU", software ? ms : t.frame_ms[0], kinds[li],
                                        st.glossy ? ", glossy" : "").c_str());
    glfwPollEvents();
  }
  if (!o.screenshot.empty() && last.empty() && frame > 0) {
    // Interactive: the last frame shown, drawn once more (the back buffer is undefined after a swap).
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    present->draw(renderer.color_texture(), shown_w, shown_h, shown_scale);
    last = capture(shown_w, shown_h);
  }
  present.reset();
  renderer_ptr.reset();
  glfwDestroyWindow(win);
  if (!o.screenshot.empty() && !last.empty()) io::write_image(o.screenshot, last);
  iblcli::emit({{"frames", frame}, {"ms_per_frame", frame ? ms_sum / frame : 0.0}, {"gl_renderer", renderer_name},
                {"screenshot", o.screenshot}},
               [&] {
                 fmt::print("{} frames, {:.1f} ms per frame (render + tone map + display) on {}\n", frame, frame ? ms_sum / frame : 0.0,
                            renderer_name);
                 if (!o.screenshot.empty()) fmt::print("screenshot {}\n", o.screenshot);
               });
}

void setup(CLI::App& app) {
  auto* o = new ViewOpts();
  app.add_option("scene", o->scene, "the object: blob, sphere, or a mesh file (OBJ, PLY, glTF)")->capture_default_str();
  app.add_option("-l,--light", o->lights, "lightings to switch between (keys 1-9, Tab): probe, .shgrid, iblkit.sh/1, iblkit.lights/1")
      ->required();
  app.add_option("--at", o->at, "the object's starting centre x,y,z (e.g. inside an SH grid's volume)")->capture_default_str();
  app.add_option("--object-size", o->object_size, "object size in metres")->check(CLI::Range(0.001, 1000.0))->capture_default_str();
  app.add_option("--floor-size", o->floor_size, "side of the floor square, metres")->check(CLI::Range(0.0, 1000.0))->capture_default_str();
  app.add_option("--size", o->size, "window size WxH")->capture_default_str();
  app.add_option("--gloss", o->gloss, "weight of the glossy Phong lobe (key G toggles it)")->check(CLI::Range(0.0, 1.0))->capture_default_str();
  app.add_option("--exponent", o->exponent, "Phong exponent")->check(CLI::Range(1.0, 10000.0))->capture_default_str();
  app.add_option("--exposure", o->exposure, "stops added to the auto exposure (keys + and -)")->capture_default_str();
  app.add_option("--bands", o->bands, "SH bands when projecting a probe")->check(CLI::Range(1, 9))->capture_default_str();
  app.add_option("--triangles", o->triangles, "triangles of the blob")->check(CLI::Range(100, 5000000))->capture_default_str();
  app.add_option("--shadows", o->shadows, "lights of a light set that cast shadows")->check(CLI::Range(0, 16))->capture_default_str();
  app.add_option("--frames", o->frames, "run this many frames (one orbit) and exit; 0: interactive")->check(CLI::Range(0, 100000));
  app.add_option("--screenshot", o->screenshot, "write the last frame here on exit (.png)");
  iblcli::add_shadow_map_options(app, &o->shadow_maps);
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer(
      "Keys: drag = orbit, scroll = zoom, arrows / PageUp / PageDown = move the object, 1-9 / Tab = lighting,\n"
      "G = glossy on/off, + / - = exposure, E = meter the auto exposure again, Esc = quit. The title shows the frame time.\n"
      "Examples:\n  iblkit view blob --light grid.shgrid --at 0,1,0 --object-size 0.3\n"
      "  iblkit view blob --light probe.exr --light lights.json\n"
      "  xvfb-run -a iblkit view sphere --light probe.exr --frames 10 --screenshot view.png");
  app.callback([o, &rd] { run(*o, rd); });
}

iblcli::Command reg("view", setup);

}  // namespace
#endif
