#include "iblkit/augment/gl/compositor.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/render/gl/program.h"
#include "iblkit/render/prefilter.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::augment::gl {

namespace {

using geometry::Mat4f;
constexpr int kMaxLights = Compositor::kMaxLights;
constexpr float kFar = 1e30f;  // a shadow-map texel nothing covers

// The texture units the constructor names in the programs' samplers and draw() binds: one list for both.
// The proxy and object passes share 0–10; the final pass binds its own three from 0.
enum Unit : GLuint {
  kUnitPhoto = 0,
  kUnitAlbedo = 1,
  kUnitGPosition = 2,
  kUnitGNormal = 3,
  kUnitSoft = 4,
  kUnitSoftIrradiance = 5,
  kUnitObjectMap = 6,
  kUnitProxyMap = 7,
  kUnitObjectTexture = 8,
  kUnitObjectGlossy = 9,
  kUnitFacingIrradiance = 10,
  kUnitFinalProxyComposite = 0,
  kUnitFinalObject = 1,
  kUnitFinalPhoto = 2,
};

// The prelude of the programs that include augment_common.glsl: its array bound is the compositor's.
std::string lights_prelude() { return fmt::format("#define MAX_LIGHTS {}\n", kMaxLights); }

// Flat-shaded triangles: position, face normal, UV (0 for a mesh without UVs) and the soft light's factor
// (composite.h's soft_visibility, smoothed over each vertex; 1 where none is given) per corner, 11 floats, so that both
// renders and the CPU reference see the same per-triangle normals.
struct Mesh {
  GLuint vao = 0, vbo = 0;
  GLsizei count = 0;
  void upload(const geometry::TriMesh& m, const std::vector<Vec3>* soft = nullptr) {
    // The factor at each corner is its vertex's mean over the triangles around it: one estimate per triangle (64
    // rays) is grainy, the mean over the ~6 around a vertex about 2.4× less so, and it varies smoothly.
    std::vector<Vec3> corner_share;
    if (soft) {
      corner_share.assign(m.positions.size(), Vec3{});
      std::vector<int> count(m.positions.size(), 0);
      for (size_t i = 0; i < m.triangle_count(); ++i)
        for (uint32_t vi : m.triangles[i]) {
          corner_share[vi] += (*soft)[i];
          ++count[vi];
        }
      for (size_t vi = 0; vi < corner_share.size(); ++vi)
        if (count[vi] > 0) corner_share[vi] = corner_share[vi] / static_cast<double>(count[vi]);
    }
    std::vector<float> v;
    v.reserve(m.triangle_count() * 33);
    const bool uvs = m.has_uvs();
    for (size_t i = 0; i < m.triangle_count(); ++i) {
      Vec3 n = m.normal(i);
      for (int k = 0; k < 3; ++k) {
        const uint32_t vi = m.triangles[i][k];
        Vec3 p = m.positions[vi], f = soft ? corner_share[vi] : Vec3{1, 1, 1};
        Vec2 uv = uvs ? m.uvs[vi] : Vec2{0, 0};
        for (double c : {p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y, f.x, f.y, f.z}) v.push_back(static_cast<float>(c));
      }
    }
    release();
    glCreateBuffers(1, &vbo);
    glNamedBufferStorage(vbo, static_cast<GLsizeiptr>(v.size() * sizeof(float)), v.data(), 0);
    glCreateVertexArrays(1, &vao);
    glVertexArrayVertexBuffer(vao, 0, vbo, 0, 11 * sizeof(float));
    const GLint sizes[] = {3, 3, 2, 3};
    const GLuint offsets[] = {0, 3, 6, 8};
    for (GLuint a = 0; a < 4; ++a) {
      glEnableVertexArrayAttrib(vao, a);
      glVertexArrayAttribFormat(vao, a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a] * sizeof(float));
      glVertexArrayAttribBinding(vao, a, 0);
    }
    count = static_cast<GLsizei>(m.triangle_count() * 3);
  }
  void draw() const {
    glBindVertexArray(vao);
    glDrawArrays(GL_TRIANGLES, 0, count);
  }
  void release() {
    if (vao) glDeleteVertexArrays(1, &vao);
    if (vbo) glDeleteBuffers(1, &vbo);
    vao = vbo = 0;
  }
};

GLuint texture_2d(GLenum format, int w, int h, int levels = 1) {
  GLuint t;
  glCreateTextures(GL_TEXTURE_2D, 1, &t);
  glTextureStorage2D(t, levels, format, w, h);
  glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_NEAREST);
  glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, levels > 1 ? GL_LINEAR : GL_NEAREST);
  glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return t;
}

// An RGB image as an RGBA32F texture, rows as they are (row 0 = texel row 0).
GLuint upload_rgb(const Image& img, bool latlong_filtered = false) {
  std::vector<float> px(img.pixel_count() * 4);
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      for (int c = 0; c < 4; ++c)
        px[(static_cast<size_t>(y) * img.width() + x) * 4 + c] =
            c < 3 ? img.at(x, y, std::min(c, img.channels() - 1)) : 1.0f;
  int levels = 1;
  if (latlong_filtered)
    for (int s = std::max(img.width(), img.height()); s > 1; s /= 2) ++levels;
  GLuint t = texture_2d(GL_RGBA32F, img.width(), img.height(), levels);
  glTextureSubImage2D(t, 0, 0, 0, img.width(), img.height(), GL_RGBA, GL_FLOAT, px.data());
  if (latlong_filtered) {
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glGenerateTextureMipmap(t);
  }
  return t;
}

GLuint framebuffer(std::initializer_list<GLuint> colors, GLuint depth_rb = 0) {
  GLuint f;
  glCreateFramebuffers(1, &f);
  std::vector<GLenum> bufs;
  GLenum i = 0;
  for (GLuint c : colors) {
    glNamedFramebufferTexture(f, GL_COLOR_ATTACHMENT0 + i, c, 0);
    bufs.push_back(GL_COLOR_ATTACHMENT0 + i++);
  }
  glNamedFramebufferDrawBuffers(f, static_cast<GLsizei>(bufs.size()), bufs.data());
  if (depth_rb) glNamedFramebufferRenderbuffer(f, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb);
  if (glCheckNamedFramebufferStatus(f, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    fail(ErrorKind::Internal, "the compositor's framebuffer is incomplete (status 0x{:x})",
         glCheckNamedFramebufferStatus(f, GL_FRAMEBUFFER));
  return f;
}

GLuint renderbuffer(GLenum format, int w, int h, int samples = 0) {
  GLuint r;
  glCreateRenderbuffers(1, &r);
  if (samples > 1)
    glNamedRenderbufferStorageMultisample(r, samples, format, w, h);
  else
    glNamedRenderbufferStorage(r, format, w, h);
  return r;
}

// The photograph's camera with image row 0 at framebuffer row 0 (y flipped against GL's convention).
Mat4f camera_matrix(const geometry::Camera& cam) {
  Mat4f p = cam.projection();
  for (int c = 0; c < 4; ++c) p[c * 4 + 1] = -p[c * 4 + 1];
  return geometry::mul(p, cam.view());
}

void set_mat(GLuint prog, const char* name, const Mat4f& m) {
  glProgramUniformMatrix4fv(prog, glGetUniformLocation(prog, name), 1, GL_FALSE, m.data());
}
void set_vec3(GLuint prog, const char* name, Vec3 v) {
  glProgramUniform3f(prog, glGetUniformLocation(prog, name), static_cast<float>(v.x), static_cast<float>(v.y),
                     static_cast<float>(v.z));
}
void set_int(GLuint prog, const char* name, int v) { glProgramUniform1i(prog, glGetUniformLocation(prog, name), v); }
void set_float(GLuint prog, const char* name, double v) {
  glProgramUniform1f(prog, glGetUniformLocation(prog, name), static_cast<float>(v));
}

Image read_texture(GLuint tex, int w, int h, int channels) {
  std::vector<float> px(static_cast<size_t>(w) * h * 4);
  glGetTextureImage(tex, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(px.size() * sizeof(float)), px.data());
  Image img(w, h, channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c)
        img.at(x, y, c) = px[(static_cast<size_t>(y) * w + x) * 4 + (channels == 1 ? 3 : c)];
  return img;
}

}  // namespace

struct Compositor::Impl {
  GlOptions desc;
  bool shadows = true, bounce = true;
  geometry::Camera cam;
  SplitLight light;
  Vec3 proxy_lo, proxy_hi;
  int W = 0, H = 0, lights = 0;
  Mesh proxy, object;
  OccluderSphere sphere;
  Vec3 object_albedo{0.7, 0.7, 0.7};  // the proxy's bounce: the albedo times the texture's mean
  bool have_object = false;
  GLuint object_texture = 0, object_glossy = 0;  // the material's albedo texture and prefiltered soft map (or 0)
  GLuint facing_tex = 0;  // augment::facing_irradiance of the object (set_object): what its bounce sends back
  GLuint prog_gbuffer = 0, prog_depth = 0, prog_proxy = 0, prog_object = 0, prog_final = 0, empty_vao = 0;
  GLuint photo_tex = 0, albedo_tex = 0, soft_tex = 0, irr_tex = 0, gpos = 0, gnormal = 0, proxy_comp = 0,
         object_tex = 0, color = 0, diff = 0;
  GLuint object_map = 0, proxy_map = 0, map_depth = 0, depth_rb = 0, ms_color = 0, ms_depth = 0;
  GLuint fb_gbuffer = 0, fb_proxy = 0, fb_object_ms = 0, fb_object = 0, fb_final = 0, fb_map = 0, query = 0;

  // Every GL object it holds is released when it goes, also when the constructor throws half-way (the
  // unique_ptr that owns it is a member, destroyed as the constructor unwinds).
  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() { release(); }

  void release() {
    for (GLuint p : {prog_gbuffer, prog_depth, prog_proxy, prog_object, prog_final})
      if (p) glDeleteProgram(p);
    GLuint texs[] = {photo_tex,  albedo_tex, soft_tex,       irr_tex,       gpos,
                     gnormal,    proxy_comp, object_tex,     color,         diff,
                     object_map, proxy_map,  object_texture, object_glossy, facing_tex};
    glDeleteTextures(static_cast<GLsizei>(std::size(texs)), texs);
    GLuint rbs[] = {map_depth, depth_rb, ms_color, ms_depth};
    glDeleteRenderbuffers(4, rbs);
    GLuint fbs[] = {fb_gbuffer, fb_proxy, fb_object_ms, fb_object, fb_final, fb_map};
    glDeleteFramebuffers(6, fbs);
    if (empty_vao) glDeleteVertexArrays(1, &empty_vao);
    if (query) glDeleteQueries(1, &query);
    proxy.release();
    object.release();
    prog_gbuffer = prog_depth = prog_proxy = prog_object = prog_final = empty_vao = query = 0;
    photo_tex = albedo_tex = soft_tex = irr_tex = gpos = gnormal = proxy_comp = object_tex = color = diff = 0;
    object_map = proxy_map = object_texture = object_glossy = facing_tex = 0;
    map_depth = depth_rb = ms_color = ms_depth = 0;
    fb_gbuffer = fb_proxy = fb_object_ms = fb_object = fb_final = fb_map = 0;
  }

  // The light uniforms and both shadow maps of every hard light, fitted to the object's bounding sphere at c.
  void shadow_maps(Vec3 c) {
    const double R = sphere.bound_radius * 1.05;
    Vec3 mid = (proxy_lo + proxy_hi) * 0.5;
    const double reach = length(proxy_hi - proxy_lo) + length(c - mid) + R;  // beyond every proxy point and the object
    const int S = desc.shadow_map_size;
    glBindFramebuffer(GL_FRAMEBUFFER, fb_map);
    glViewport(0, 0, S, S);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    for (int l = 0; l < lights; ++l) {
      const lights::Light& h = light.hard.lights[static_cast<size_t>(l)];
      const bool distant = !h.position;
      const Vec3 position = h.position.value_or(Vec3{});
      geometry::Camera lc;
      lc.width = lc.height = 1;
      Mat4f vp;
      float eye_w;
      Vec3 dir = h.direction;
      if (distant) {
        lc.eye = c + dir * reach;
        lc.target = c;
        lc.up = std::abs(dir.y) > 0.99 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        Mat4f p{};
        p[0] = p[5] = static_cast<float>(1 / R);
        p[10] = static_cast<float>(-2 / (2 * reach));
        p[14] = -1;
        p[15] = 1;
        vp = geometry::mul(p, lc.view());
        eye_w = static_cast<float>(2 * R / S);
      } else {
        lc.eye = position + (light.centre - position) * 0.01;  // off the proxy surface the light sits on
        double D = length(c - lc.eye);
        lc.target = c;
        Vec3 to = (c - lc.eye) / std::max(D, 1e-12);
        lc.up = std::abs(to.y) > 0.99 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        if (D > R) {
          lc.fov_y_deg = 2 * std::asin(std::min(1.0, R / D)) * 180 / kPi;
          lc.znear = std::max(1e-4, 0.02 * (D - R));
          lc.zfar = reach + D;
          vp = geometry::mul(lc.projection(), lc.view());
          eye_w = static_cast<float>(2 * std::tan(lc.fov_y_deg * kPi / 360) / S);
        } else {
          vp = Mat4f{};
          eye_w = -1;  // the light is within the object's sphere: no shadow map
        }
      }
      const std::string i = fmt::format("[{}]", l);
      for (GLuint prog : {prog_proxy, prog_object}) {
        glProgramUniform4f(prog, glGetUniformLocation(prog, ("u_light_dir" + i).c_str()), static_cast<float>(dir.x),
                           static_cast<float>(dir.y), static_cast<float>(dir.z), distant ? 0.0f : 1.0f);
        Vec3 off = position - light.centre;
        glProgramUniform4f(prog, glGetUniformLocation(prog, ("u_light_pos" + i).c_str()),
                           static_cast<float>(position.x), static_cast<float>(position.y),
                           static_cast<float>(position.z), static_cast<float>(dot(off, off)));
        glProgramUniform4f(prog, glGetUniformLocation(prog, ("u_light_e" + i).c_str()),
                           static_cast<float>(h.irradiance.x), static_cast<float>(h.irradiance.y),
                           static_cast<float>(h.irradiance.z), 0.0f);
        glProgramUniformMatrix4fv(prog, glGetUniformLocation(prog, ("u_light_vp" + i).c_str()), 1, GL_FALSE, vp.data());
        glProgramUniform4f(prog, glGetUniformLocation(prog, ("u_light_eye" + i).c_str()), static_cast<float>(lc.eye.x),
                           static_cast<float>(lc.eye.y), static_cast<float>(lc.eye.z), eye_w);
      }
      if (eye_w < 0) continue;
      glUseProgram(prog_depth);
      set_mat(prog_depth, "u_view_projection", vp);
      set_vec3(prog_depth, "u_map_eye", lc.eye);
      set_vec3(prog_depth, "u_map_dir", dir);
      set_int(prog_depth, "u_map_local", distant ? 0 : 1);
      const float far[4] = {kFar, kFar, kFar, kFar};
      for (int pass = 0; pass < 2; ++pass) {
        glNamedFramebufferTextureLayer(fb_map, GL_COLOR_ATTACHMENT0, pass == 0 ? proxy_map : object_map, 0, l);
        glClearBufferfv(GL_COLOR, 0, far);
        glClear(GL_DEPTH_BUFFER_BIT);
        set_vec3(prog_depth, "u_offset", pass == 0 ? Vec3{} : c - sphere.centre);
        if (pass == 0)
          proxy.draw();
        else
          object.draw();
      }
    }
  }
};

Compositor::Compositor(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                       const SplitLight& light, const Image& albedo, const CompositeDesc& full_desc)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  const GlOptions& desc = full_desc.gl;
  if (photo.width() != cam.width || photo.height() != cam.height || albedo.width() != cam.width ||
      albedo.height() != cam.height)
    fail(ErrorKind::Value, "the photograph ({}x{}), its albedo ({}x{}) and the camera's frame ({}x{}) must agree",
         photo.width(), photo.height(), albedo.width(), albedo.height(), cam.width, cam.height);
  if (photo.channels() < 3)
    fail(ErrorKind::Value, "the photograph has {} channels; an RGB image is needed", photo.channels());
  if (desc.shadow_map_size < 16 || desc.shadow_map_size > 8192)
    fail(ErrorKind::Value, "shadow map size {} must lie in 16..8192", desc.shadow_map_size);
  if (desc.pcf < 0 || desc.pcf > 4) fail(ErrorKind::Value, "pcf radius {} must lie in 0..4", desc.pcf);
  if (desc.msaa < 1 || desc.msaa > 16) fail(ErrorKind::Value, "msaa {} must lie in 1..16", desc.msaa);
  if (!(desc.soft_cutoff >= 0 && desc.soft_cutoff < 1))
    fail(ErrorKind::Value, "soft cut-off {} must lie in [0, 1)", desc.soft_cutoff);
  if (proxy.triangle_count() == 0) fail(ErrorKind::Value, "the proxy has no triangles");
  if (light.hard.lights.size() > static_cast<size_t>(kMaxLights))
    fail(ErrorKind::Value, "{} hard lights: the GL compositor takes at most {}", light.hard.lights.size(), kMaxLights);
  m.desc = desc;
  m.shadows = full_desc.shadows;
  m.bounce = full_desc.bounce_samples > 0;
  m.cam = cam;
  m.light = light;
  m.W = cam.width;
  m.H = cam.height;
  m.lights = static_cast<int>(light.hard.lights.size());
  proxy.bounds(&m.proxy_lo, &m.proxy_hi);
  using render::gl::build_program;
  using render::gl::ShaderStage;
  const std::vector<std::string> common = {"augment_common.glsl"};
  const std::string prelude = lights_prelude();
  m.prog_gbuffer =
      build_program({{GL_VERTEX_SHADER, "augment_mesh.vert", ""}, {GL_FRAGMENT_SHADER, "augment_gbuffer.frag", ""}});
  m.prog_depth =
      build_program({{GL_VERTEX_SHADER, "augment_mesh.vert", ""}, {GL_FRAGMENT_SHADER, "augment_depth.frag", ""}});
  m.prog_proxy = build_program(
      {{GL_VERTEX_SHADER, "augment_quad.vert", ""}, {GL_FRAGMENT_SHADER, "augment_proxy.frag", prelude, common}});
  m.prog_object = build_program(
      {{GL_VERTEX_SHADER, "augment_mesh.vert", ""}, {GL_FRAGMENT_SHADER, "augment_object.frag", prelude, common}});
  m.prog_final =
      build_program({{GL_VERTEX_SHADER, "augment_quad.vert", ""}, {GL_FRAGMENT_SHADER, "augment_final.frag", ""}});
  glCreateVertexArrays(1, &m.empty_vao);
  glCreateQueries(GL_TIME_ELAPSED, 1, &m.query);
  m.proxy.upload(proxy);
  m.photo_tex = upload_rgb(photo);
  m.albedo_tex = upload_rgb(albedo);
  m.soft_tex = upload_rgb(light.soft, true);
  m.irr_tex = upload_rgb(light.soft_irradiance, true);
  const int W = m.W, H = m.H, S = desc.shadow_map_size;
  m.gpos = texture_2d(GL_RGBA32F, W, H);
  m.gnormal = texture_2d(GL_RGBA32F, W, H);
  m.proxy_comp = texture_2d(GL_RGBA32F, W, H);
  m.object_tex = texture_2d(GL_RGBA32F, W, H);
  m.color = texture_2d(GL_RGBA32F, W, H);
  m.diff = texture_2d(GL_RGBA32F, W, H);
  m.depth_rb = renderbuffer(GL_DEPTH_COMPONENT32F, W, H);
  m.ms_color = renderbuffer(GL_RGBA32F, W, H, desc.msaa);
  m.ms_depth = renderbuffer(GL_DEPTH_COMPONENT32F, W, H, desc.msaa);
  m.map_depth = renderbuffer(GL_DEPTH_COMPONENT32F, S, S);
  for (GLuint* t : {&m.object_map, &m.proxy_map}) {
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, t);
    glTextureStorage3D(*t, 1, GL_R32F, S, S, std::max(1, m.lights));
    glTextureParameteri(*t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(*t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  m.fb_gbuffer = framebuffer({m.gpos, m.gnormal}, m.depth_rb);
  m.fb_proxy = framebuffer({m.proxy_comp});
  m.fb_object = framebuffer({m.object_tex});
  m.fb_final = framebuffer({m.color, m.diff});
  glCreateFramebuffers(1, &m.fb_object_ms);
  glNamedFramebufferRenderbuffer(m.fb_object_ms, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, m.ms_color);
  glNamedFramebufferRenderbuffer(m.fb_object_ms, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, m.ms_depth);
  glCreateFramebuffers(1, &m.fb_map);
  glNamedFramebufferTextureLayer(m.fb_map, GL_COLOR_ATTACHMENT0, m.proxy_map, 0, 0);
  glNamedFramebufferRenderbuffer(m.fb_map, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, m.map_depth);
  for (GLuint f : {m.fb_object_ms, m.fb_map})
    if (glCheckNamedFramebufferStatus(f, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      fail(ErrorKind::Internal, "the compositor's framebuffer is incomplete (status 0x{:x})",
           glCheckNamedFramebufferStatus(f, GL_FRAMEBUFFER));

  // The G-buffer: the proxy at every pixel's centre, once.
  const Mat4f vp = camera_matrix(cam);
  glBindFramebuffer(GL_FRAMEBUFFER, m.fb_gbuffer);
  glViewport(0, 0, W, H);
  glDisable(GL_CULL_FACE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  const float zero[4] = {0, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, zero);
  glClearBufferfv(GL_COLOR, 1, zero);
  glClear(GL_DEPTH_BUFFER_BIT);
  glUseProgram(m.prog_gbuffer);
  set_mat(m.prog_gbuffer, "u_view_projection", vp);
  set_vec3(m.prog_gbuffer, "u_offset", {});
  set_vec3(m.prog_gbuffer, "u_eye", cam.eye);
  m.proxy.draw();

  // Constant uniforms.
  set_mat(m.prog_object, "u_view_projection", vp);
  set_vec3(m.prog_object, "u_eye", cam.eye);
  for (GLuint p : {m.prog_proxy, m.prog_object}) {
    set_int(p, "u_light_count", m.lights);
    set_int(p, "u_map_size", S);
    set_int(p, "u_pcf", desc.pcf);
    set_int(p, "u_object_map", kUnitObjectMap);
    set_int(p, "u_proxy_map", kUnitProxyMap);
    set_int(p, "u_soft_irradiance", kUnitSoftIrradiance);
  }
  set_int(m.prog_object, "u_object_texture", kUnitObjectTexture);
  set_int(m.prog_object, "u_object_glossy", kUnitObjectGlossy);
  set_int(m.prog_proxy, "u_photo", kUnitPhoto);
  set_int(m.prog_proxy, "u_albedo", kUnitAlbedo);
  set_int(m.prog_proxy, "u_gpos", kUnitGPosition);
  set_int(m.prog_proxy, "u_gnormal", kUnitGNormal);
  set_int(m.prog_proxy, "u_soft", kUnitSoft);
  set_int(m.prog_proxy, "u_facing_irradiance", kUnitFacingIrradiance);
  set_float(m.prog_proxy, "u_cut", desc.soft_cutoff);
  set_float(m.prog_proxy, "u_soft_texel", (2 * kPi / light.soft.width()) * (kPi / light.soft.height()));
  set_int(m.prog_proxy, "u_bounce", m.bounce ? 1 : 0);
  set_int(m.prog_proxy, "u_shadows", m.shadows ? 1 : 0);
  set_int(m.prog_final, "u_proxy_composite", kUnitFinalProxyComposite);
  set_int(m.prog_final, "u_object", kUnitFinalObject);
  set_int(m.prog_final, "u_photo", kUnitFinalPhoto);
  set_int(m.prog_final, "u_height", H);
  GLenum err = glGetError();
  if (err != GL_NO_ERROR) fail(ErrorKind::Internal, "OpenGL error 0x{:x} while setting up the compositor", err);
}

Compositor::~Compositor() = default;  // Impl releases its GL objects

void Compositor::set_object(const geometry::TriMesh& object, const render::Material& material,
                            const std::vector<Vec3>* soft_visibility) {
  if (object.triangle_count() == 0) fail(ErrorKind::Value, "the object has no triangles");
  if (soft_visibility && soft_visibility->size() != object.triangle_count())
    fail(ErrorKind::Value, "soft visibility for {} triangles given for an object of {}", soft_visibility->size(),
         object.triangle_count());
  render::check_material(material);
  const Vec3 a = material.albedo, k = material.specular;
  const bool glossy = max_component(k) > 0;
  Impl& m = *impl_;
  m.object.upload(object, soft_visibility);
  m.sphere = equivalent_sphere(object);
  // The soft light the object's faces receive, by the way they face (with each triangle's factor: the floor
  // under it darkened by its shadow): what the sphere's bounce sends back to a proxy point.
  if (m.facing_tex) glDeleteTextures(1, &m.facing_tex);
  m.facing_tex = 0;
  m.facing_tex = upload_rgb(facing_irradiance(object, soft_visibility, m.light.soft_irradiance), true);
  Vec3 mean_texture{1, 1, 1};
  if (m.object_texture) glDeleteTextures(1, &m.object_texture);
  if (m.object_glossy) glDeleteTextures(1, &m.object_glossy);
  m.object_texture = m.object_glossy = 0;
  if (material.texture) {
    const Image& t = *material.texture;
    if (t.pixel_count() == 0) fail(ErrorKind::Value, "the object's texture is empty");
    Vec3 sum;
    for (int y = 0; y < t.height(); ++y)
      for (int x = 0; x < t.width(); ++x) sum += t.rgb(x, y);
    mean_texture = sum / static_cast<double>(t.pixel_count());
    // Bilinear and repeating, as render::texture_albedo reads it (texel centres at half-integers).
    m.object_texture = upload_rgb(t);
    glTextureParameteri(m.object_texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(m.object_texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(m.object_texture, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(m.object_texture, GL_TEXTURE_WRAP_T, GL_REPEAT);
  }
  if (glossy) {
    // G_s of the soft map (the hard lights' lobe is evaluated per light in the shader): bilinear, u repeats, v clamps.
    render::GlossyMap g = render::prefilter_phong(
        sphere::EnvMap::from_image(m.light.soft, sphere::MappingKind::LatLong), material.environment_exponent());
    m.object_glossy = upload_rgb(g.latlong);
    glTextureParameteri(m.object_glossy, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(m.object_glossy, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(m.object_glossy, GL_TEXTURE_WRAP_S, GL_REPEAT);
  }
  m.object_albedo = a * mean_texture;
  const GLuint p = m.prog_object;
  set_vec3(p, "u_material_albedo", a);
  set_int(p, "u_textured", material.texture ? 1 : 0);
  set_vec3(p, "u_specular", glossy ? k : Vec3{});
  set_float(p, "u_exponent", material.exponent);
  set_int(p, "u_blinn", material.lobe == render::Lobe::BlinnPhong ? 1 : 0);
  m.have_object = true;
}

void Compositor::draw(Vec3 offset, bool gl_rows, GlFrameTiming* timing) {
  Impl& m = *impl_;
  if (!m.have_object) fail(ErrorKind::Value, "the compositor has no object (set_object)");
  auto t0 = std::chrono::steady_clock::now();
  glBeginQuery(GL_TIME_ELAPSED, m.query);
  const Vec3 c = m.sphere.centre + offset;
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  m.shadow_maps(c);  // the object's own shadows need them even when the proxy's (desc.shadows) are off
  const std::pair<Unit, GLuint> bound[] = {
      {kUnitPhoto, m.photo_tex},      {kUnitAlbedo, m.albedo_tex},  {kUnitGPosition, m.gpos},
      {kUnitGNormal, m.gnormal},      {kUnitSoft, m.soft_tex},      {kUnitSoftIrradiance, m.irr_tex},
      {kUnitObjectMap, m.object_map}, {kUnitProxyMap, m.proxy_map}, {kUnitFacingIrradiance, m.facing_tex}};
  for (const auto& [unit, tex] : bound) glBindTextureUnit(unit, tex);

  // The proxy's pixels: photo + min(ρ, 1)/π ΔE.
  glBindFramebuffer(GL_FRAMEBUFFER, m.fb_proxy);
  glViewport(0, 0, m.W, m.H);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(m.prog_proxy);
  glProgramUniform4f(m.prog_proxy, glGetUniformLocation(m.prog_proxy, "u_sphere"), static_cast<float>(c.x),
                     static_cast<float>(c.y), static_cast<float>(c.z), static_cast<float>(m.sphere.radius));
  set_vec3(m.prog_proxy, "u_object_albedo", m.object_albedo);
  glBindVertexArray(m.empty_vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);

  // The object, multisampled, behind the proxy where the proxy is in front.
  glBindFramebuffer(GL_FRAMEBUFFER, m.fb_object_ms);
  const float zero[4] = {0, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, zero);
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  const Mat4f vp = camera_matrix(m.cam);
  glUseProgram(m.prog_depth);  // the proxy's depth only
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  set_mat(m.prog_depth, "u_view_projection", vp);
  set_vec3(m.prog_depth, "u_offset", {});
  m.proxy.draw();
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glUseProgram(m.prog_object);
  set_vec3(m.prog_object, "u_offset", offset);
  glBindTextureUnit(kUnitObjectTexture, m.object_texture);
  glBindTextureUnit(kUnitObjectGlossy, m.object_glossy);
  m.object.draw();
  glBlitNamedFramebuffer(m.fb_object_ms, m.fb_object, 0, 0, m.W, m.H, 0, 0, m.W, m.H, GL_COLOR_BUFFER_BIT, GL_NEAREST);

  // The object over the proxy's composite.
  glBindFramebuffer(GL_FRAMEBUFFER, m.fb_final);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(m.prog_final);
  set_int(m.prog_final, "u_flip", gl_rows ? 1 : 0);
  glBindTextureUnit(kUnitFinalProxyComposite, m.proxy_comp);
  glBindTextureUnit(kUnitFinalObject, m.object_tex);
  glBindTextureUnit(kUnitFinalPhoto, m.photo_tex);
  glBindVertexArray(m.empty_vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glEndQuery(GL_TIME_ELAPSED);
  glFinish();
  if (timing) {
    GLuint64 ns = 0;
    glGetQueryObjectui64v(m.query, GL_QUERY_RESULT, &ns);
    timing->gpu_ms = static_cast<double>(ns) * 1e-6;
    timing->wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  GLenum err = glGetError();
  if (err != GL_NO_ERROR) fail(ErrorKind::Internal, "OpenGL error 0x{:x} in a compositor frame", err);
}

unsigned Compositor::color_texture() const { return impl_->color; }
int Compositor::width() const { return impl_->W; }
int Compositor::height() const { return impl_->H; }
const SplitLight& Compositor::light() const { return impl_->light; }

void Compositor::read_back(Image* composite, Image* mask, Image* difference, Image* proxy_composite) const {
  const Impl& m = *impl_;
  if (composite) *composite = read_texture(m.color, m.W, m.H, 3);
  if (mask) *mask = read_texture(m.diff, m.W, m.H, 1);
  if (difference) *difference = read_texture(m.diff, m.W, m.H, 3);
  if (proxy_composite) *proxy_composite = read_texture(m.proxy_comp, m.W, m.H, 3);
}

}  // namespace ibl::augment::gl
