// iblkit view: an interactive window (GLFW) on the real-time renderer. Orbit the camera, move the
// object through an SH grid's volume or a light set, switch between several --light files, see the
// frame time. With --frames N it runs N frames on its own (orbiting) and exits: how the tests drive
// it under Xvfb.
#if defined(IBLKIT_HAVE_GL) && defined(IBLKIT_HAVE_GLFW)
// epoxy/gl.h must come before GLFW's header (which would include GL/gl.h): two blocks keep the order.
#include <epoxy/gl.h>

#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/augment/albedo.h"
#include "iblkit/augment/composite.h"
#include "iblkit/augment/gl/compositor.h"
#include "iblkit/augment/load.h"
#include "iblkit/augment/run_composite.h"
#include "iblkit/augment/soft_visibility.h"
#include "iblkit/core/error.h"
#include "iblkit/ilf/crossval.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/render/gl/context.h"
#include "iblkit/render/gl/present.h"
#include "iblkit/render/gl/renderer.h"
#include "iblkit/render/lighting_io.h"
#include "iblkit/render/objects.h"
#include "render_setup.h"

namespace {

using namespace ibl;
using namespace ibl::render;

struct ViewOpts {
  std::string size = "960x720", at = "0,0,0", screenshot;
  std::vector<std::string> lights;
  render::ObjectDesc object;          // scene, --object-size, --triangles
  render::LightingReadDesc lighting;  // --bands, --shadows
  double gloss = 0.15, exponent = 20, exposure = 0, floor_size = 6;
  int frames = 0;
  iblcli::ShadowMapOptions shadow_maps;
  // Composite mode (--composite PHOTO): the photograph behind, its camera, the captured light and proxy.
  std::string photo, albedo = "0.7,0.7,0.7";
  iblcli::PhotoSceneOptions scene;
  int gl_lights = 16;
  std::string error_grid;  // --error-grid: a cross-validated error volume shown as a false-colour slice
  double max_error = 0.5;
};

// Orbit camera around a target: azimuth, elevation (radians) and distance.
struct Orbit {
  Vec3 target;
  double azimuth = 0, elevation = 0.35, distance = 2;
  Vec3 eye() const {
    return target +
           Vec3{std::sin(azimuth) * std::cos(elevation), std::sin(elevation), std::cos(azimuth) * std::cos(elevation)} *
               distance;
  }
};

struct State {
  Orbit orbit;
  Vec3 offset;       // object displacement from --at
  int lighting = 0;  // index into the loaded lightings
  bool glossy = true;
  double exposure = 0;   // stops added to the auto exposure
  bool remeter = false;  // measure the auto exposure again on the next frame
  bool dragging = false;
  double last_x = 0, last_y = 0;
  double step = 0.05;  // metres per key press
  int slice_axis = 1;  // --error-grid: the slice's normal axis (keys X, Y, Z); it passes through the object
};

// What the viewer shows, all read before a window opens (everything that can fail on input).
struct Inputs {
  int width = 0, height = 0;
  std::vector<Lighting> lightings;
  std::vector<std::string> kinds;
  Vec3 at;
  geometry::TriMesh base;  // the object at the origin
  ilf::SHGrid error;       // --error-grid (content "cv-error"); empty without
};

Inputs read_inputs(const ViewOpts& o, const io::EnvReadDesc& rd) {
  Inputs in;
  if (std::sscanf(o.size.c_str(), "%dx%d", &in.width, &in.height) != 2 || in.width < 16 || in.height < 16 ||
      in.width > 8192 || in.height > 8192)
    fail(ErrorKind::Value, "--size '{}': expected WxH, e.g. 960x720", o.size);
  render::LightingReadDesc lopt = o.lighting;
  lopt.glossy_exponent = o.gloss > 0 ? o.exponent : 0.0;
  lopt.read = rd;
  in.lightings.resize(o.lights.size());
  in.kinds.resize(o.lights.size());
  for (size_t i = 0; i < o.lights.size(); ++i) render::read_lighting(o.lights[i], lopt, &in.lightings[i], &in.kinds[i]);
  in.at = iblcli::parse_vec3(o.at, "--at");
  render::ObjectDesc od = o.object;
  od.at = {0, 0, 0};
  in.base = render::make_object(od);
  geometry::TriMesh placed = in.base;
  placed.transform(1.0, in.at);
  for (const Lighting& L : in.lightings)
    if (std::string w = iblcli::grid_bounds_warning(L, placed); !w.empty()) iblcli::info("warning: " + w);
  if (!o.error_grid.empty()) {
    in.error = ilf::read_shgrid(o.error_grid, true);
    if (in.error.content() != "cv-error")
      fail(ErrorKind::Value,
           "--error-grid {}: holds \"{}\", not a cross-validated error volume (write one with ilf build --error-grid)",
           o.error_grid, in.error.content().empty() ? "radiance SH" : in.error.content());
  }
  return in;
}

// A w × h window with a current OpenGL 4.5 core context (EGL).
GLFWwindow* open_window(int w, int h, bool vsync) {
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  // EGL, as the headless renderer uses: libepoxy then finds the context whatever the X server.
  glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
  GLFWwindow* win = glfwCreateWindow(w, h, "iblkit view", nullptr, nullptr);
  if (!win) fail(ErrorKind::Unsupported, "no window with an OpenGL 4.5 core context could be opened on this display");
  glfwMakeContextCurrent(win);
  glfwSwapInterval(vsync ? 1 : 0);
  ibl::render::gl::keep_drivers_loaded_for_leak_checks();  // (AddressSanitizer builds only)
  return win;
}

// Keys, mouse and scroll act on the State the window's user pointer holds.
void install_controls(GLFWwindow* win, State* st) {
  glfwSetWindowUserPointer(win, st);
  glfwSetKeyCallback(win, [](GLFWwindow* wnd, int key, int, int action, int) {
    if (action == GLFW_RELEASE) return;
    auto& s = *static_cast<State*>(glfwGetWindowUserPointer(wnd));
    switch (key) {
      case GLFW_KEY_ESCAPE:
      case GLFW_KEY_Q:
        glfwSetWindowShouldClose(wnd, GLFW_TRUE);
        break;
      case GLFW_KEY_LEFT:
        s.offset.x -= s.step;
        break;
      case GLFW_KEY_RIGHT:
        s.offset.x += s.step;
        break;
      case GLFW_KEY_UP:
        s.offset.z -= s.step;
        break;
      case GLFW_KEY_DOWN:
        s.offset.z += s.step;
        break;
      case GLFW_KEY_PAGE_UP:
        s.offset.y += s.step;
        break;
      case GLFW_KEY_PAGE_DOWN:
        s.offset.y -= s.step;
        break;
      case GLFW_KEY_G:
        s.glossy = !s.glossy;
        break;
      case GLFW_KEY_E:
        s.remeter = true;
        break;
      case GLFW_KEY_EQUAL:
      case GLFW_KEY_KP_ADD:
        s.exposure += 0.5;
        break;
      case GLFW_KEY_MINUS:
      case GLFW_KEY_KP_SUBTRACT:
        s.exposure -= 0.5;
        break;
      case GLFW_KEY_TAB:
        ++s.lighting;
        break;
      case GLFW_KEY_X:
        s.slice_axis = 0;
        break;
      case GLFW_KEY_Y:
        s.slice_axis = 1;
        break;
      case GLFW_KEY_Z:
        s.slice_axis = 2;
        break;
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
}

// The window's back buffer, read back and turned into linear radiance (what the display shows).
Image capture(int fw, int fh) {
  std::vector<float> px(static_cast<size_t>(fw) * fh * 3);
  glReadBuffer(GL_BACK);
  glReadnPixels(0, 0, fw, fh, GL_RGB, GL_FLOAT, static_cast<GLsizei>(px.size() * sizeof(float)), px.data());
  Image shot(fw, fh, 3);
  for (int y = 0; y < fh; ++y)
    for (int x = 0; x < fw; ++x)
      for (int c = 0; c < 3; ++c) {
        float v = px[(static_cast<size_t>(fh - 1 - y) * fw + x) * 3 + c];                       // GL rows go up
        shot.at(x, y, c) = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);  // back to linear
      }
  return shot;
}

// The renderer and the display path of an open window, and what the frames so far measured.
// The error volume's slice through the object (--error-grid), drawn over the frame's top-left corner.
struct ErrorSlice {
  std::unique_ptr<gl::Overlay> overlay = std::make_unique<gl::Overlay>();
  int axis = -1, width = 0;
  double value = 0, mean = 0, max = 0;  // the plane; the relative error over its pixels
};

struct Viewer {
  std::unique_ptr<gl::Renderer> renderer =
      std::make_unique<gl::Renderer>();  // released before the window's context goes
  std::unique_ptr<gl::Presenter> present = std::make_unique<gl::Presenter>();
  ErrorSlice slice;
  Image last;  // the screenshot
  double ms_sum = 0, meter = 1, shown_scale = 1;
  int frame = 0, metered_lighting = -1, shown_w = 0, shown_h = 0;
  std::string renderer_name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
};

// The slice of the error volume on the plane `axis` = the object's coordinate (clamped to the volume),
// `width` pixels wide (as `ilf slice --size width` lays it out and colours it, --max-error red), with
// the object's place marked by a white cross; recomputed only when the plane or the width changes.
void update_slice(const ViewOpts& o, const Inputs& in, Vec3 object, int axis, int width, ErrorSlice* s) {
  const auto& vol = in.error.grid().volume;
  const double value = std::clamp(object[axis], vol.min[axis], vol.max[axis]);
  if (axis == s->axis && value == s->value && width == s->width) return;
  Image e = ilf::error_slice(in.error, axis, value, width);
  Image c = ilf::error_colours(e, o.max_error);
  double sum = 0, mx = 0;
  for (int y = 0; y < e.height(); ++y)
    for (int x = 0; x < e.width(); ++x) {
      sum += e.at(x, y, 0);
      mx = std::max<double>(mx, e.at(x, y, 0));
    }
  const int a1 = axis == 0 ? 2 : 0, a2 = axis == 1 ? 2 : 1;  // error_slice's image axes
  const Vec3 ext = vol.size();
  const int cx = static_cast<int>(std::floor((object[a1] - vol.min[a1]) / ext[a1] * c.width()));
  const int cy = static_cast<int>(std::floor((vol.max[a2] - object[a2]) / ext[a2] * c.height()));
  for (int d = -3; d <= 3; ++d) {
    if (cx + d >= 0 && cx + d < c.width() && cy >= 0 && cy < c.height()) c.set_rgb(cx + d, cy, {1, 1, 1});
    if (cy + d >= 0 && cy + d < c.height() && cx >= 0 && cx < c.width()) c.set_rgb(cx, cy + d, {1, 1, 1});
  }
  for (int y = 0; y < c.height(); ++y)
    for (int x = 0; x < c.width(); ++x)
      for (int ch = 0; ch < 3; ++ch) c.at(x, y, ch) = io::linear_to_srgb(c.at(x, y, ch));
  s->overlay->set(c);
  s->axis = axis;
  s->value = value;
  s->width = width;
  s->mean = sum / (double(e.width()) * e.height());
  s->max = mx;
}

// Renders, tone-maps and shows one fw × fh frame of the state's lighting, object place and camera.
void show_frame(const ViewOpts& o, Inputs& in, State& st, Viewer& v, GLFWwindow* win, int fw, int fh) {
  const int li = static_cast<int>(st.lighting % static_cast<int>(in.lightings.size()));
  FrameDesc d;
  d.camera.width = fw;
  d.camera.height = fh;
  o.shadow_maps.apply(&d);
  d.camera.target = in.at + st.offset;
  st.orbit.target = d.camera.target;
  d.camera.eye = st.orbit.eye();
  geometry::TriMesh object = in.base, floor;
  object.transform(1.0, in.at + st.offset);
  Vec3 lo, hi;
  object.bounds(&lo, &hi);
  Material mat{{0.75, 0.75, 0.75}, Vec3{1, 1, 1} * (st.glossy ? std::max(o.gloss, 0.15) : 0.0), o.exponent};
  d.objects = {{&object, mat}};
  if (o.floor_size > 0) {
    floor = geometry::make_floor(o.floor_size, lo.y - 1e-3);
    floor.transform(1.0, {in.at.x + st.offset.x, 0, in.at.z + st.offset.z});
    d.objects.push_back({&floor, Material{{0.5, 0.5, 0.5}, {0, 0, 0}, 1}});
  }
  d.lighting = std::move(in.lightings[li]);  // lent to the frame, not copied (an SH grid is megabytes)
  gl::GpuTiming t;
  auto t0 = std::chrono::steady_clock::now();
  // The frame stays on the GPU and is tone-mapped there; it is read back only to meter the auto
  // exposure (median luminance, as `render` does) when the lighting changes or on key E.
  const bool meter_now = li != v.metered_lighting || st.remeter;
  RenderResult f;
  try {
    f = v.renderer->render(d, 1, &t, meter_now);
  } catch (...) {
    in.lightings[li] = std::move(d.lighting);
    throw;
  }
  in.lightings[li] = std::move(d.lighting);
  if (meter_now) {
    v.meter = io::auto_exposure_scale(f.color);
    v.metered_lighting = li;
    st.remeter = false;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  v.shown_w = fw;
  v.shown_h = fh;
  v.shown_scale = v.meter * std::exp2(st.exposure);
  v.present->draw(v.renderer->color_texture(), fw, fh, v.shown_scale);
  if (!in.error.data().empty()) {
    update_slice(o, in, in.at + st.offset, st.slice_axis, std::clamp(fw / 3, 16, 512), &v.slice);
    v.slice.overlay->draw(8, fh - 8 - v.slice.overlay->height(), v.slice.overlay->width(), v.slice.overlay->height());
  }
  // The screenshot reads the window's own back buffer: what the display path shows.
  if (!o.screenshot.empty() && o.frames > 0 && v.frame + 1 == o.frames) v.last = capture(fw, fh);
  glfwSwapBuffers(win);
  double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  v.ms_sum += ms;
  ++v.frame;
  bool software = v.renderer_name.find("llvmpipe") != std::string::npos;
  glfwSetWindowTitle(
      win, fmt::format("iblkit view — {} — {} {:.2f} ms/frame ({}){}{}",
                       std::filesystem::path(o.lights[li]).filename().string(), software ? "wall" : "GPU",
                       software ? ms : t.frame_ms[0], in.kinds[li], st.glossy ? ", glossy" : "",
                       in.error.data().empty()
                           ? std::string()
                           : fmt::format(", error slice {} = {:.2f}: mean {:.3f}, max {:.3f} (red: {:g})",
                                         "xyz"[v.slice.axis], v.slice.value, v.slice.mean, v.slice.max, o.max_error))
               .c_str());
}

// Composite mode: the object moved over the photograph (augment/gl/compositor.h), the camera the
// photograph's; drag and the arrow keys move the object, + / - the exposure. Scripted (--frames N), the
// object goes once round a circle of half its size about --at.
void run_composite(const ViewOpts& o, const ibl::io::EnvReadDesc& rd) {
  Image photo = io::read_image(o.photo);
  const geometry::Camera cam = iblcli::photo_camera(o.scene, photo, o.photo, "--composite: ");
  augment::CompositeJob job;
  job.object = iblcli::inserted_object(o.object.scene, o.object.size, o.object.triangles, o.at);
  job.material = iblcli::object_material(o.albedo, 0, 20, "phong", "");  // Lambertian (composite takes --gloss)
  job.light = iblcli::photo_light_input(o.scene, o.lights);
  job.light.read = rd;
  job.desc.gl.split.lights = o.gl_lights;
  const augment::CompositeScene scene = augment::prepare_composite(job, &photo, &cam);
  for (const auto& n : scene.notes) iblcli::info(n);
  const augment::LoadedLight& L = scene.light;
  const geometry::TriMesh& object = scene.object;
  for (const auto& w : L.warnings) iblcli::info("warning: " + w);
  iblcli::info("estimating the proxy's albedo (CPU, once)");
  augment::AlbedoEstimate est = augment::estimate_albedo(photo, cam, L.proxy, L.light);
  const augment::SplitDesc& sd = job.desc.gl.split;
  augment::SplitLight split = augment::split_light(L.light, L.proxy, sd);
  if (!glfwInit()) fail(ErrorKind::Unsupported, "no display: GLFW could not initialise (is DISPLAY set? try xvfb-run)");
  struct Terminate {
    ~Terminate() { glfwTerminate(); }
  } terminate;
  GLFWwindow* win = open_window(photo.width(), photo.height(), o.frames == 0);
  glfwSetWindowAttrib(win, GLFW_RESIZABLE, GLFW_FALSE);  // the frame is the photograph's
  State st;
  st.exposure = o.exposure;
  st.step = 0.1 * job.object.size;
  install_controls(win, &st);
  auto comp = std::make_unique<augment::gl::Compositor>(photo, cam, L.proxy, split, est.albedo, job.desc);
  // The object's own occlusion of its soft light, which moves with it (composite, for one placement, also
  // traces the proxy's occlusion and the floor darkened by the object's shadow).
  augment::SoftVisibilityDesc vd;
  vd.proxy = false;
  vd.threshold = sd.lights > 0 ? sd.threshold : 0;
  const std::vector<Vec3> vis = augment::soft_visibility(L.light, L.proxy, object, vd);
  comp->set_object(object, job.material, &vis);
  auto present = std::make_unique<gl::Presenter>();
  const double meter = io::auto_exposure_scale(photo);
  const std::string renderer_name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  Image last;
  int frame = 0;
  double ms_sum = 0;
  while (!glfwWindowShouldClose(win) && (o.frames == 0 || frame < o.frames)) {
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(win, &fw, &fh);
    if (fw < 1 || fh < 1) {
      glfwWaitEvents();
      continue;
    }
    Vec3 offset = st.offset;
    if (o.frames > 0) {
      double a = 2 * kPi * frame / o.frames;
      offset += Vec3{std::cos(a), 0, std::sin(a)} * (0.5 * job.object.size);
    } else {
      offset += Vec3{-st.orbit.azimuth, 0, st.orbit.elevation - 0.35} * (10 * st.step);  // drag: over the floor
    }
    augment::gl::GlFrameTiming t;
    auto t0 = std::chrono::steady_clock::now();
    comp->draw(offset, true, &t);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    present->draw(comp->color_texture(), std::min(fw, photo.width()), std::min(fh, photo.height()),
                  meter * std::exp2(st.exposure));
    if (!o.screenshot.empty() && (o.frames == 0 || frame + 1 == o.frames))
      last = capture(std::min(fw, photo.width()), std::min(fh, photo.height()));
    glfwSwapBuffers(win);
    double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ms_sum += ms;
    ++frame;
    bool software = renderer_name.find("llvmpipe") != std::string::npos;
    glfwSetWindowTitle(win, fmt::format("iblkit view — composite {} — {} {:.2f} ms/frame, {} hard lights",
                                        std::filesystem::path(o.photo).filename().string(), software ? "wall" : "GPU",
                                        software ? ms : t.gpu_ms, split.hard.lights.size())
                                .c_str());
    glfwPollEvents();
  }
  present.reset();  // before the window's context goes
  comp.reset();
  glfwDestroyWindow(win);
  if (!o.screenshot.empty() && !last.empty()) io::write_image(o.screenshot, last);
  iblcli::emit({{"frames", frame},
                {"ms_per_frame", frame ? ms_sum / frame : 0.0},
                {"gl_renderer", renderer_name},
                {"screenshot", o.screenshot},
                {"mode", "composite"},
                {"hard_lights", split.hard.lights.size()}},
               [&] {
                 fmt::print(
                     "{} composite frames, {:.1f} ms per frame (shadow maps, differential render, display) on {}\n",
                     frame, frame ? ms_sum / frame : 0.0, renderer_name);
                 if (!o.screenshot.empty()) fmt::print("screenshot {}\n", o.screenshot);
               });
}

void run(const ViewOpts& o, const ibl::io::EnvReadDesc& rd) {
  if (!o.photo.empty()) return run_composite(o, rd);
  if (o.lights.empty()) fail(ErrorKind::Value, "--light is required (or --composite PHOTO with its light)");
  Inputs in = read_inputs(o, rd);
  if (!glfwInit()) fail(ErrorKind::Unsupported, "no display: GLFW could not initialise (is DISPLAY set? try xvfb-run)");
  struct Terminate {
    ~Terminate() { glfwTerminate(); }
  } terminate;
  GLFWwindow* win = open_window(in.width, in.height, o.frames == 0);
  State st;
  st.orbit.target = in.at;
  st.orbit.distance = 2.2 * o.object.size;
  st.exposure = o.exposure;
  st.glossy = o.gloss > 0;
  st.step = 0.1 * o.object.size;
  install_controls(win, &st);
  auto v = std::make_unique<Viewer>();
  while (!glfwWindowShouldClose(win) && (o.frames == 0 || v->frame < o.frames)) {
    if (o.frames > 0) st.orbit.azimuth = 2 * kPi * v->frame / o.frames;  // scripted: one turn
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(win, &fw, &fh);
    if (fw < 1 || fh < 1) {
      glfwWaitEvents();
      continue;
    }
    show_frame(o, in, st, *v, win, fw, fh);
    glfwPollEvents();
  }
  if (!o.screenshot.empty() && v->last.empty() && v->frame > 0) {
    // Interactive: the last frame shown, drawn once more (the back buffer is undefined after a swap).
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    v->present->draw(v->renderer->color_texture(), v->shown_w, v->shown_h, v->shown_scale);
    if (!in.error.data().empty())
      v->slice.overlay->draw(8, v->shown_h - 8 - v->slice.overlay->height(), v->slice.overlay->width(),
                             v->slice.overlay->height());
    v->last = capture(v->shown_w, v->shown_h);
  }
  const int frames = v->frame;
  const double ms_sum = v->ms_sum;
  const std::string renderer_name = v->renderer_name;
  const Image last = std::move(v->last);
  const ErrorSlice slice_shown{nullptr, v->slice.axis, v->slice.width, v->slice.value, v->slice.mean, v->slice.max};
  v.reset();  // the renderer and presenter before the window's context
  glfwDestroyWindow(win);
  if (!o.screenshot.empty() && !last.empty()) io::write_image(o.screenshot, last);
  nlohmann::json summary = {{"frames", frames},
                            {"ms_per_frame", frames ? ms_sum / frames : 0.0},
                            {"gl_renderer", renderer_name},
                            {"screenshot", o.screenshot}};
  if (!in.error.data().empty() && slice_shown.axis >= 0)
    summary["error_slice"] = {{"plane", fmt::format("{}={:.9g}", "xyz"[slice_shown.axis], slice_shown.value)},
                              {"width", slice_shown.width},
                              {"mean_rel_error", slice_shown.mean},
                              {"max_rel_error", slice_shown.max},
                              {"max_error", o.max_error}};
  iblcli::emit(summary, [&] {
    fmt::print("{} frames, {:.1f} ms per frame (render + tone map + display) on {}\n", frames,
               frames ? ms_sum / frames : 0.0, renderer_name);
    if (!in.error.data().empty() && slice_shown.axis >= 0)
      fmt::print("error slice {}={:.3g} ({} px wide): cross-validated relative error mean {:.3f}, max {:.3f}\n",
                 "xyz"[slice_shown.axis], slice_shown.value, slice_shown.width, slice_shown.mean, slice_shown.max);
    if (!o.screenshot.empty()) fmt::print("screenshot {}\n", o.screenshot);
  });
}

void setup(CLI::App& app) {
  auto* o = iblcli::app_owned<ViewOpts>();
  app.add_option("scene", o->object.scene, "the object: blob, sphere, or a mesh file (OBJ, PLY, glTF)")
      ->capture_default_str();
  app.add_option(
      "-l,--light", o->lights,
      "lightings to switch between (keys 1-9, Tab): probe, .shgrid (or .shtree), iblkit.sh/1, iblkit.lights/1; "
      "with --composite: an SH grid or a probe image (with --proxy)");
  app.add_option("--composite", o->photo,
                 "composite mode: this photograph behind, the object moving in it with its shadows");
  iblcli::add_photo_scene_options(app, &o->scene, "composite: ");
  app.add_option("--albedo", o->albedo, "composite: the object's Lambertian albedo r,g,b")->capture_default_str();
  app.add_option("--gl-lights", o->gl_lights, "composite: most hard lights with shadow maps")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  app.add_option("--at", o->at, "the object's starting centre x,y,z (e.g. inside an SH grid's volume)")
      ->capture_default_str();
  app.add_option("--object-size", o->object.size, "object size in metres")
      ->check(CLI::Range(0.001, 1000.0))
      ->capture_default_str();
  app.add_option("--floor-size", o->floor_size, "side of the floor square, metres")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  app.add_option("--size", o->size, "window size WxH")->capture_default_str();
  app.add_option("--gloss", o->gloss, "weight of the glossy Phong lobe (key G toggles it)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--exponent", o->exponent, "Phong exponent")->check(CLI::Range(1.0, 10000.0))->capture_default_str();
  app.add_option("--exposure", o->exposure, "stops added to the auto exposure (keys + and -)")->capture_default_str();
  app.add_option("--bands", o->lighting.bands, "SH bands when projecting a probe")
      ->check(CLI::Range(1, 9))
      ->capture_default_str();
  app.add_option("--triangles", o->object.triangles, "triangles of the blob")
      ->check(CLI::Range(100, 5000000))
      ->capture_default_str();
  app.add_option("--shadows", o->lighting.shadows, "lights of a light set that cast shadows")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  app.add_option("--frames", o->frames, "run this many frames (one orbit) and exit; 0: interactive")
      ->check(CLI::Range(0, 100000));
  app.add_option("--screenshot", o->screenshot, "write the last frame here on exit (.png)");
  iblcli::outputs(app, {"--screenshot"});  // cli.h
  app.add_option("--error-grid", o->error_grid,
                 "an error volume (ilf build --error-grid): its false-colour slice through the object, top left "
                 "(keys X / Y / Z: the plane's normal)");
  app.add_option("--max-error", o->max_error, "--error-grid: the relative error shown red (as ilf slice)")
      ->check(CLI::Range(1e-9, 1e9))
      ->capture_default_str();
  iblcli::add_shadow_map_options(app, &o->shadow_maps);
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer(
      "Keys: drag = orbit, scroll = zoom, arrows / PageUp / PageDown = move the object, 1-9 / Tab = lighting,\n"
      "G = glossy on/off, + / - = exposure, E = meter the auto exposure again, X / Y / Z = the error slice's normal\n"
      "(--error-grid), Esc = quit. The title shows the frame time.\n"
      "Examples:\n  iblkit view blob --light grid.shgrid --at 0,1,0 --object-size 0.3\n"
      "  iblkit view blob --light probe.exr --light lights.json\n"
      "  iblkit view blob --light grid.shgrid --error-grid err.shgrid --at 0,1,0 --object-size 0.3\n"
      "  xvfb-run -a iblkit view sphere --light probe.exr --frames 10 --screenshot view.png\n"
      "  iblkit view blob --composite photo.exr --eye 0,1.3,2.2 --target 0,0.3,0 --fov 40 --probes probe/probes.json "
      "--at 0.1,0.2,0.1\n"
      "Composite mode: drag or the arrows / PageUp / PageDown move the object, + / - exposure, Esc quits.");
  app.callback([o, &rd] { run(*o, rd); });
}

iblcli::Command reg("view", setup);

}  // namespace
#endif
