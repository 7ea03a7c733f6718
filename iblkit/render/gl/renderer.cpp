#include "iblkit/render/gl/renderer.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "iblkit/core/error.h"
#include "iblkit/render/gl/program.h"
#include "iblkit/render/gl/sh_glsl.h"
#include "iblkit/render/gl/uploads.h"
#include "iblkit/render/light_space.h"
#include "iblkit/sh/convolve.h"

namespace ibl::render::gl {

namespace {

// A shader storage buffer holding `v` (at least one element's room: GL refuses empty storage),
// bound at `binding`.
template <typename T>
GLuint storage_buffer(const std::vector<T>& v, GLuint binding) {
  GLuint b = 0;
  glCreateBuffers(1, &b);
  glNamedBufferStorage(b, static_cast<GLsizeiptr>(std::max<size_t>(1, v.size()) * sizeof(T)),
                       v.empty() ? nullptr : v.data(), 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, b);
  return b;
}

// A depth-texture array for shadow maps: `layers` of size², bilinear depth comparisons (2×2 PCF).
GLuint shadow_map_array(int size, int layers) {
  GLuint t = 0;
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &t);
  glTextureStorage3D(t, 1, GL_DEPTH_COMPONENT32F, size, size, layers);
  glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTextureParameteri(t, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  return t;
}

void set_vec3(GLuint prog, const char* name, Vec3 v) {
  glProgramUniform3f(prog, glGetUniformLocation(prog, name), static_cast<float>(v.x), static_cast<float>(v.y),
                     static_cast<float>(v.z));
}

// An RGBA32F 2D array of RGB images (all of one size), a layer each, alpha `alpha`, bilinear,
// repeating in s and `wrap_t` in t.
GLuint rgb_texture_array(const std::vector<const Image*>& images, float alpha, GLenum wrap_t) {
  const int w = images[0]->width(), h = images[0]->height();
  GLuint tex = 0;
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &tex);
  glTextureStorage3D(tex, 1, GL_RGBA32F, w, h, static_cast<GLsizei>(images.size()));
  std::vector<float> rgba(static_cast<size_t>(w) * h * 4);
  for (size_t li = 0; li < images.size(); ++li) {
    const Image& im = *images[li];
    for (size_t i = 0; i < im.pixel_count(); ++i)
      for (int c = 0; c < 4; ++c) rgba[i * 4 + c] = c < 3 ? im.data()[i * im.channels() + c] : alpha;
    glTextureSubImage3D(tex, 0, 0, 0, static_cast<GLint>(li), w, h, 1, GL_RGBA, GL_FLOAT, rgba.data());
  }
  glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(tex, GL_TEXTURE_WRAP_T, wrap_t);
  return tex;
}

constexpr int kMaterialFloats = 24;  // MaterialGpu in shade.comp

// What one render() sets up, filled stage by stage: Renderer::render runs the stages in order, each
// reading what the earlier ones filled. It owns the frame's own GL objects and releases them when it
// goes, also when a stage throws (what stays between frames belongs to Uploads and the Impl).
struct FramePlan {
  // programs: the frame's size, the lighting's SH bands (0: none) and the programs' coefficient
  // count (at least 1), the shading program and the one that rasterises (the same when forward)
  int W = 0, H = 0, bands = 0, K = 1;
  bool glossy = false, deferred = false;
  GLuint prog = 0, raster = 0;
  // bounds: the objects' bounding sphere (the shadow maps' frusta); their meshes on the GPU
  Vec3 centre;
  double radius = 0;
  const Uploads::Geometry* geometry = nullptr;
  // lights: rows of 8 floats per directional and point light; the shadow matrices of both
  std::vector<float> light_data, point_data;
  std::vector<Mat4f> shadow_mats;
  int unshadowed = 0;  // shadow-casting lights that got no map
  // spotlights: rows of 24 floats; their shadow matrices; their textures (Uploads')
  std::vector<float> spot_data;
  std::vector<Mat4f> spot_mats;
  GLuint spot_tex = 0;
  // shadow arrays: the lights' storage buffers, the depth arrays (S², SS²) and their framebuffer
  GLuint light_ssbo[2] = {0, 0}, point_ssbo = 0, spot_ssbo[2] = {0, 0};
  GLuint shadow_tex = 0, spot_shadow_tex = 0, shadow_fbo = 0;
  int S = 1, SS = 0;
  // SH grid: its 3D texture (Uploads')
  GLuint grid_tex = 0;
  // targets: the colour texture (Uploads'), depth, the framebuffer, the deferred G-buffer
  GLuint color_tex = 0, depth_rb = 0, fbo = 0, vis_tex = 0;
  // materials: per object its glossy-map and albedo-texture layers (−1: none), the texture arrays,
  // the material table (kMaterialFloats per object) and its storage buffer
  std::vector<int> material_layer, albedo_layer;
  GLuint glossy_tex = 0, albedo_tex = 0, material_ssbo = 0;
  std::vector<float> materials;
  // uniforms: the SH table (the Impl's) and the locations the draws set
  GLuint sh_table_tex = 0;
  GLint loc_albedo = -1, loc_specular = -1, loc_exponent = -1, loc_glossy = -1, loc_glossy_layer = -1,
        loc_albedo_layer = -1, loc_lobe = -1, loc_material = -1, loc_light_vp = -1;

  FramePlan() = default;
  FramePlan(const FramePlan&) = delete;
  FramePlan& operator=(const FramePlan&) = delete;
  ~FramePlan() {
    glDeleteFramebuffers(1, &fbo);
    glDeleteFramebuffers(1, &shadow_fbo);
    glDeleteRenderbuffers(1, &depth_rb);
    glDeleteTextures(1, &vis_tex);
    glDeleteBuffers(1, &material_ssbo);
    glDeleteTextures(1, &shadow_tex);
    glDeleteTextures(1, &glossy_tex);
    glDeleteTextures(1, &albedo_tex);
    glDeleteTextures(1, &spot_shadow_tex);
    glDeleteBuffers(2, spot_ssbo);
    glDeleteBuffers(2, light_ssbo);
    glDeleteBuffers(1, &point_ssbo);
  }
};

}  // namespace

struct Renderer::Impl {
  RendererDesc desc;
  // Programs by (SH bands (0 → 1), glossy, stage kind).
  enum Kind { Forward, GBuffer, Compute };
  std::map<std::tuple<int, bool, int>, GLuint> programs;
  std::map<int, GLuint> sh_tables;  // by bands, when desc.sh_table_size > 0

  Uploads uploads;  // what stays on the GPU between frames

  GLuint sh_table(int bands) {
    auto& t = sh_tables[bands];
    if (!t) t = make_sh_table_texture(bands, desc.sh_table_size);
    return t;
  }
  GLuint shadow_program = 0;
  GLuint layered_shadow_program = 0;  // 0 where the driver lacks GL_ARB_shader_viewport_layer_array

  GLuint program(int bands, bool glossy, Kind kind) {
    auto key = std::make_tuple(std::max(1, bands), glossy, static_cast<int>(kind));
    auto it = programs.find(key);
    if (it != programs.end()) return it->second;
    const int b = std::get<0>(key);
    std::string defs = (desc.sh_table_size > 0 ? sh_table_glsl_source(b) : sh_glsl_source(b)) +
                       (glossy ? "#define GLOSSY 1\n" : "#define GLOSSY 0\n");
    GLuint p = 0;
    switch (kind) {
      case Forward:
        p = build_program(
            {{GL_VERTEX_SHADER, "mesh.vert", ""}, {GL_FRAGMENT_SHADER, "shade.frag", defs, {"shading.glsl"}}});
        break;
      case GBuffer:
        p = build_program({{GL_VERTEX_SHADER, "mesh.vert", ""}, {GL_FRAGMENT_SHADER, "visibility.frag", ""}});
        break;
      case Compute:
        p = build_program({{GL_COMPUTE_SHADER, "shade.comp", defs, {"shading.glsl"}}});
        break;
    }
    programs[key] = p;
    return p;
  }

  // The stages of render(), in order (FramePlan says what each fills).
  void plan_programs(const FrameDesc& d, FramePlan& p);
  void plan_bounds(const FrameDesc& d, FramePlan& p);
  void plan_lights(const FrameDesc& d, FramePlan& p);
  void plan_spotlights(const FrameDesc& d, FramePlan& p);
  void plan_shadow_arrays(const FrameDesc& d, FramePlan& p);
  void plan_sh_grid(const FrameDesc& d, FramePlan& p);
  void plan_targets(const FrameDesc& d, FramePlan& p);
  void plan_materials(const FrameDesc& d, FramePlan& p);
  void plan_uniforms(const FrameDesc& d, FramePlan& p);
  void draw_frames(const FrameDesc& d, const FramePlan& p, int frames, GpuTiming* timing);
  // Every layer of a depth array from its light matrix: one instanced draw per mesh (layered) or
  // one pass per layer.
  void shadow_passes(const FramePlan& p, GLuint tex, GLuint mats_ssbo, const std::vector<Mat4f>& mats, int size);
  ~Impl() {
    for (auto& [k, p] : programs) glDeleteProgram(p);
    if (shadow_program) glDeleteProgram(shadow_program);
    if (layered_shadow_program) glDeleteProgram(layered_shadow_program);
    for (auto& [b, t] : sh_tables) glDeleteTextures(1, &t);
  }
};

Renderer::Renderer(const RendererDesc& desc) : impl_(std::make_unique<Impl>()) {
  impl_->desc = desc;
  if (desc.sh_table_size < 0 || desc.sh_table_size == 1 || desc.sh_table_size > kMaxShTableSize)
    fail(ErrorKind::Value, "SH table size {} is out of range (0 for none, 2..{})", desc.sh_table_size, kMaxShTableSize);
  impl_->shadow_program =
      build_program({{GL_VERTEX_SHADER, "shadow.vert", ""}, {GL_FRAGMENT_SHADER, "shadow.frag", ""}});
  GLint vertex_ssbos = 0;  // the layered pass reads its matrices from a storage buffer (GL 4.5 may allow none)
  glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &vertex_ssbos);
  if (desc.layered_shadows && vertex_ssbos > 0 && epoxy_has_gl_extension("GL_ARB_shader_viewport_layer_array"))
    impl_->layered_shadow_program =
        build_program({{GL_VERTEX_SHADER, "shadow_layered.vert", ""}, {GL_FRAGMENT_SHADER, "shadow.frag", ""}});
}
Renderer::~Renderer() = default;

unsigned Renderer::color_texture() const { return impl_->uploads.last_color_texture(); }

// The frame's size, the SH bands of its lighting and the programs that draw it.
void Renderer::Impl::plan_programs(const FrameDesc& d, FramePlan& p) {
  p.W = d.camera.width;
  p.H = d.camera.height;
  if (p.W <= 0 || p.H <= 0 || p.W > 16384 || p.H > 16384)
    fail(ErrorKind::Value, "frame size {}x{} is invalid", p.W, p.H);
  check_objects(d);
  const Lighting& L = d.lighting;
  p.bands = L.grid ? L.grid->bands() : (L.environment ? L.environment->bands : 0);
  for (const auto& o : d.objects) p.glossy |= max_component(o.material.specular) > 0;
  p.deferred = desc.deferred;
  p.prog = program(p.bands, p.glossy, p.deferred ? Compute : Forward);
  p.raster = p.deferred ? program(p.bands, p.glossy, GBuffer) : p.prog;
  p.K = std::max(1, p.bands) * std::max(1, p.bands);
}

// Scene bounds for the shadow maps' orthographic frusta, and the objects' meshes on the GPU.
void Renderer::Impl::plan_bounds(const FrameDesc& d, FramePlan& p) {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto& o : d.objects) {
    Vec3 a, b;
    o.mesh->bounds(&a, &b);
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], a[k]);
      hi[k] = std::max(hi[k], b[k]);
    }
  }
  p.geometry = &uploads.geometry(d.objects, p.deferred);
  p.centre = (lo + hi) * 0.5;
  p.radius = std::max(1e-6, 0.5 * length(hi - lo));
}

// Directional and point lights and their shadow matrices.
void Renderer::Impl::plan_lights(const FrameDesc& d, FramePlan& p) {
  const Lighting& L = d.lighting;
  for (const auto& l : L.lights) {
    if (l.shadow && static_cast<int>(p.shadow_mats.size()) >= kMaxShadowMaps) ++p.unshadowed;
    float layer = -1;
    if (l.shadow && static_cast<int>(p.shadow_mats.size()) < kMaxShadowMaps) {
      layer = static_cast<float>(p.shadow_mats.size());
      p.shadow_mats.push_back(light_view_projection(l.direction, p.centre, p.radius));
    }
    Vec3 dir = normalize(l.direction);
    p.light_data.insert(p.light_data.end(),
                        {static_cast<float>(dir.x), static_cast<float>(dir.y), static_cast<float>(dir.z), layer,
                         static_cast<float>(l.irradiance.x), static_cast<float>(l.irradiance.y),
                         static_cast<float>(l.irradiance.z), 0.0f});
  }
  // Point lights: a perspective shadow map when they sit outside the objects' bounding sphere, else a
  // cube of six (layers of the same array). A light that finds no free layers is drawn unshadowed
  // and counted in `unshadowed`.
  for (const auto& l : L.point_lights) {
    float layer = -1;
    Mat4f m;
    float cube = 0;
    if (l.shadow) {
      const int free_layers = kMaxShadowMaps - static_cast<int>(p.shadow_mats.size());
      if (point_light_view_projection(l.position, p.centre, p.radius, &m) && free_layers >= 1) {
        layer = static_cast<float>(p.shadow_mats.size());
        p.shadow_mats.push_back(m);
      } else if (free_layers >= 6) {
        // Inside (or next to) the objects' bounding sphere: a cube map of six faces.
        layer = static_cast<float>(p.shadow_mats.size());
        cube = 1;
        for (const Mat4f& f : cube_light_view_projections(l.position, length(p.centre - l.position) + p.radius * 1.01))
          p.shadow_mats.push_back(f);
      } else {
        ++p.unshadowed;
      }
    }
    p.point_data.insert(p.point_data.end(),
                        {static_cast<float>(l.position.x), static_cast<float>(l.position.y),
                         static_cast<float>(l.position.z), layer, static_cast<float>(l.intensity.x),
                         static_cast<float>(l.intensity.y), static_cast<float>(l.intensity.z), cube});
  }
}

// Textured spotlights: their textures in one mip-mapped 2D array (one layer each, all of one size),
// their parameters in an SSBO, and a perspective shadow map each (its own array) covering the
// frustum through its texture's extent on M.
void Renderer::Impl::plan_spotlights(const FrameDesc& d, FramePlan& p) {
  const Lighting& L = d.lighting;
  if (L.spotlights.empty()) return;
  const Uploads::SpotTextures& st = uploads.spot_textures(L.spotlights);
  p.spot_tex = st.tex;
  const int tw = (*L.spotlights[0].mips)[0].width(), th = (*L.spotlights[0].mips)[0].height();
  // Shadow maps shared by spotlights that shine the same way from within spot_shadow_share of a
  // group's first member (a near-field dataset's terms lie millimetres apart): one map per group,
  // from the group's mean position.
  std::vector<int> group_of(L.spotlights.size(), -1), group_seed;
  std::vector<Vec3> group_sum;
  std::vector<int> group_count;
  for (size_t i = 0; i < L.spotlights.size(); ++i) {
    const auto& sp = L.spotlights[i];
    if (!sp.shadow) continue;
    for (size_t g = 0; g < group_seed.size() && group_of[i] < 0; ++g) {
      const auto& seed = L.spotlights[group_seed[g]];
      if (d.spot_shadow_share > 0 && dot(seed.frame.n, sp.frame.n) > 0.99999 &&
          length(seed.position - sp.position) <= d.spot_shadow_share)
        group_of[i] = static_cast<int>(g);
    }
    if (group_of[i] < 0) {
      group_of[i] = static_cast<int>(group_seed.size());
      group_seed.push_back(static_cast<int>(i));
      group_sum.push_back({0, 0, 0});
      group_count.push_back(0);
    }
    group_sum[group_of[i]] = group_sum[group_of[i]] + sp.position;
    ++group_count[group_of[i]];
  }
  std::vector<float> group_layer(group_seed.size(), -1.0f);
  for (size_t i = 0; i < L.spotlights.size(); ++i) {
    const auto& sp = L.spotlights[i];
    float layer = -1;
    if (sp.shadow && group_layer[group_of[i]] >= 0) {
      layer = group_layer[group_of[i]];
    } else if (sp.shadow) {
      // Perspective frustum along forward through the texture's extent (a texel of margin), from
      // the group's mean position (the spotlight's own when it has the map to itself), widened by
      // the group's spread.
      const Vec3 eye = group_sum[group_of[i]] * (1.0 / group_count[group_of[i]]);
      const double spread = group_count[group_of[i]] > 1 ? d.spot_shadow_share : 0.0;
      const double pd = sp.plane_distance,
                   margin = std::max((sp.tex_max.x - sp.tex_min.x) / tw, (sp.tex_max.y - sp.tex_min.y) / th) + spread;
      const double tx = (std::max(std::abs(sp.tex_min.x), std::abs(sp.tex_max.x)) + margin) / pd;
      const double ty = (std::max(std::abs(sp.tex_min.y), std::abs(sp.tex_max.y)) + margin) / pd;
      geometry::Camera c;
      c.eye = eye;
      c.target = eye + sp.frame.n;
      c.up = sp.frame.b;
      c.fov_y_deg = 2 * std::atan(ty) * 180 / kPi;
      c.width = 1000;
      c.height = std::max(1, static_cast<int>(std::lround(1000 * ty / tx)));
      const double far_d = length(p.centre - eye) + p.radius;
      c.zfar = far_d * 1.01;
      c.znear = std::max(far_d * 1e-3, (length(p.centre - eye) - p.radius) * 0.95);
      layer = static_cast<float>(p.spot_mats.size());
      group_layer[group_of[i]] = layer;
      Mat4f proj = c.projection();
      proj[0] = static_cast<float>(1.0 / tx);  // exact horizontal extent (the aspect above is rounded)
      p.spot_mats.push_back(mul(proj, c.view()));
    }
    const double texel = std::max((sp.tex_max.x - sp.tex_min.x) / tw, (sp.tex_max.y - sp.tex_min.y) / th);
    const float row[24] = {static_cast<float>(sp.position.x),
                           static_cast<float>(sp.position.y),
                           static_cast<float>(sp.position.z),
                           layer,
                           static_cast<float>(sp.frame.t.x),
                           static_cast<float>(sp.frame.t.y),
                           static_cast<float>(sp.frame.t.z),
                           static_cast<float>(sp.tex_min.x),
                           static_cast<float>(sp.frame.b.x),
                           static_cast<float>(sp.frame.b.y),
                           static_cast<float>(sp.frame.b.z),
                           static_cast<float>(sp.tex_min.y),
                           static_cast<float>(sp.frame.n.x),
                           static_cast<float>(sp.frame.n.y),
                           static_cast<float>(sp.frame.n.z),
                           static_cast<float>(sp.plane_distance),
                           static_cast<float>(sp.tex_max.x),
                           static_cast<float>(sp.tex_max.y),
                           static_cast<float>(sp.support_area),
                           static_cast<float>(sp.support_width),
                           static_cast<float>(texel),
                           static_cast<float>(st.levels),
                           static_cast<float>(i),
                           st.scale[i]};
    p.spot_data.insert(p.spot_data.end(), row, row + 24);
  }
}

// The lights' storage buffers, and the shadow-map arrays with their framebuffer (a 1×1 placeholder
// array when no light casts shadows: the sampler needs a texture).
void Renderer::Impl::plan_shadow_arrays(const FrameDesc& d, FramePlan& p) {
  p.point_ssbo = storage_buffer(p.point_data, 7);
  p.spot_ssbo[0] = storage_buffer(p.spot_data, 8);
  p.spot_ssbo[1] = storage_buffer(p.spot_mats, 9);
  p.SS = d.spot_shadow_map_size;
  if (!p.spot_mats.empty()) {
    if (p.SS < 16 || p.SS > 8192) fail(ErrorKind::Value, "spotlight shadow map size {} is out of range 16..8192", p.SS);
    p.spot_shadow_tex = shadow_map_array(p.SS, static_cast<int>(p.spot_mats.size()));
  }
  p.light_ssbo[0] = storage_buffer(p.light_data, 0);
  p.light_ssbo[1] = storage_buffer(p.shadow_mats, 1);
  if (!p.shadow_mats.empty() && (d.shadow_map_size < 16 || d.shadow_map_size > 8192))
    fail(ErrorKind::Value, "shadow map size {} is out of range 16..8192", d.shadow_map_size);
  p.S = p.shadow_mats.empty() ? 1 : d.shadow_map_size;
  p.shadow_tex = shadow_map_array(p.S, std::max<int>(1, static_cast<int>(p.shadow_mats.size())));
  glCreateFramebuffers(1, &p.shadow_fbo);
}

// SH grid: one RGBA16F 3D texture, coefficient k in slices [k·nz, (k+1)·nz).
void Renderer::Impl::plan_sh_grid(const FrameDesc& d, FramePlan& p) {
  if (!d.lighting.grid) return;
  const ilf::SHGrid& g = *d.lighting.grid;
  const ilf::GridDesc& gd = g.grid();
  const size_t values = static_cast<size_t>(gd.count()) * p.K * 3;
  if (g.data().size() != values)
    fail(ErrorKind::Value, "SH grid {}x{}x{} with {} bands holds {} values, expected {}", gd.nx, gd.ny, gd.nz,
         g.bands(), g.data().size(), values);
  GLint max3d = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
  if (gd.nz * p.K > max3d)
    fail(ErrorKind::Unsupported, "SH grid needs a 3D texture {} deep; this GL allows {}", gd.nz * p.K, max3d);
  p.grid_tex = uploads.grid_texture(g);
}

// Colour target (the forward pass renders into it; the deferred pass writes it as an image), and
// the deferred G-buffer.
void Renderer::Impl::plan_targets(const FrameDesc& d, FramePlan& p) {
  p.color_tex = uploads.color_texture(p.W, p.H);
  glCreateRenderbuffers(1, &p.depth_rb);
  glNamedRenderbufferStorage(p.depth_rb, GL_DEPTH_COMPONENT32F, p.W, p.H);
  glCreateFramebuffers(1, &p.fbo);
  if (p.deferred) {
    glCreateTextures(GL_TEXTURE_2D, 1, &p.vis_tex);
    glTextureStorage2D(p.vis_tex, 1, GL_R32UI, p.W, p.H);
    glTextureParameteri(p.vis_tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(p.vis_tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glNamedFramebufferTexture(p.fbo, GL_COLOR_ATTACHMENT0, p.vis_tex, 0);
    for (int i = 0; i < 4; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3 + i, p.geometry->ssbo[i]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 10, p.geometry->ssbo[4]);
  } else {
    glNamedFramebufferTexture(p.fbo, GL_COLOR_ATTACHMENT0, p.color_tex, 0);
  }
  glNamedFramebufferRenderbuffer(p.fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, p.depth_rb);
  if (glCheckNamedFramebufferStatus(p.fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    fail(ErrorKind::Unsupported, "GL framebuffer {}x{} is incomplete", p.W, p.H);
}

// Materials (deferred: a table indexed from the G-buffer; forward: uniforms per object), with the
// prefiltered glossy maps of a distant probe (a layer per map a material uses) and the albedo
// textures (a layer per distinct texture) in a 2D array each, all of one size.
void Renderer::Impl::plan_materials(const FrameDesc& d, FramePlan& p) {
  const Lighting& L = d.lighting;
  std::vector<const Image*> gmaps, albedo_images;
  for (const auto& o : d.objects) {
    const GlossyMap* g = L.grid ? nullptr : L.glossy_map(o.material.environment_exponent());
    int layer = -1;
    if (g) {
      auto it = std::find(gmaps.begin(), gmaps.end(), &g->latlong);
      layer = static_cast<int>(it - gmaps.begin());
      if (it == gmaps.end()) gmaps.push_back(&g->latlong);
    }
    p.material_layer.push_back(layer);
    layer = -1;
    if (o.material.texture) {
      const Image* im = o.material.texture.get();
      auto it = std::find(albedo_images.begin(), albedo_images.end(), im);
      layer = static_cast<int>(it - albedo_images.begin());
      if (it == albedo_images.end()) albedo_images.push_back(im);
    }
    p.albedo_layer.push_back(layer);
  }
  if (!gmaps.empty()) {
    const int gw = gmaps[0]->width(), gh = gmaps[0]->height();
    for (const Image* g : gmaps)
      if (g->width() != gw || g->height() != gh || g->channels() != 3)
        fail(ErrorKind::Unsupported, "the GL renderer takes glossy maps of one size per frame ({}x{} and {}x{} given)",
             gw, gh, g->width(), g->height());
    p.glossy_tex = rgb_texture_array(gmaps, 0.0f, GL_CLAMP_TO_EDGE);
  }
  if (!albedo_images.empty()) {
    const int aw = albedo_images[0]->width(), ah = albedo_images[0]->height();
    for (const Image* im : albedo_images)
      if (im->width() != aw || im->height() != ah || im->channels() < 3)
        fail(ErrorKind::Unsupported,
             "the GL renderer takes RGB albedo textures of one size per frame ({}x{} and {}x{}x{} given)", aw, ah,
             im->width(), im->height(), im->channels());
    p.albedo_tex = rgb_texture_array(albedo_images, 1.0f, GL_REPEAT);
  }
  for (size_t oi = 0; oi < d.objects.size(); ++oi) {
    const Material& m = d.objects[oi].material;
    float row[kMaterialFloats] = {static_cast<float>(m.albedo.x),   static_cast<float>(m.albedo.y),
                                  static_cast<float>(m.albedo.z),   static_cast<float>(p.material_layer[oi]),
                                  static_cast<float>(m.specular.x), static_cast<float>(m.specular.y),
                                  static_cast<float>(m.specular.z), static_cast<float>(m.exponent)};
    if (p.bands > 0) {
      auto gz = sh::phong_zh(p.bands, m.environment_exponent());
      for (int l = 0; l < std::min(p.bands, 12); ++l) row[8 + l] = static_cast<float>(gz[l]);
    }
    row[20] = static_cast<float>(p.albedo_layer[oi]);
    row[21] = m.lobe == Lobe::BlinnPhong ? 1.0f : 0.0f;
    p.materials.insert(p.materials.end(), row, row + kMaterialFloats);
  }
  p.material_ssbo = storage_buffer(p.materials, 2);
}

// Uniforms of the shading program, and the locations the draws set per object.
void Renderer::Impl::plan_uniforms(const FrameDesc& d, FramePlan& p) {
  const geometry::Camera& cam = d.camera;
  const Lighting& L = d.lighting;
  const GLuint prog = p.prog;
  Mat4f vp = mul(cam.projection(), cam.view());
  glProgramUniformMatrix4fv(p.raster, glGetUniformLocation(p.raster, "u_view_projection"), 1, GL_FALSE, vp.data());
  set_vec3(prog, "u_eye", cam.eye);
  set_vec3(prog, "u_background", d.background);
  if (p.deferred) {
    // Camera rays: dir(x, y) ∝ f + r·sx + u·sy with sx, sy linear in the pixel position.
    Vec3 f = normalize(cam.target - cam.eye), r = normalize(cross(f, cam.up)), u = cross(r, f);
    if (cam.intrinsics) {  // a photograph's focal lengths and principal point (undistorted: checked above)
      const geometry::Intrinsics& k = *cam.intrinsics;
      set_vec3(prog, "u_ray00", f - r * (k.cx / k.fx) + u * (k.cy / k.fy));
      set_vec3(prog, "u_ray_dx", r * (1 / k.fx));
      set_vec3(prog, "u_ray_dy", u * (-1 / k.fy));
    } else {
      double t = std::tan(cam.fov_y_deg * kPi / 360.0), aspect = static_cast<double>(p.W) / p.H;
      set_vec3(prog, "u_ray00", f - r * (t * aspect) + u * t);
      set_vec3(prog, "u_ray_dx", r * (2 * t * aspect / p.W));
      set_vec3(prog, "u_ray_dy", u * (-2 * t / p.H));
    }
  }
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_light_count"), static_cast<GLint>(L.lights.size()));
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_point_light_count"),
                     static_cast<GLint>(L.point_lights.size()));
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_spot_count"), static_cast<GLint>(L.spotlights.size()));
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_spot_textures"), 4);
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_spot_shadows"), 5);
  glProgramUniform1f(prog, glGetUniformLocation(prog, "u_shadow_bias"), static_cast<float>(d.shadow_bias));
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_shadow_maps"), 0);
  int mode = L.grid ? 2 : (L.environment ? 1 : 0);
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_sh_mode"), mode);
  std::vector<float> env(static_cast<size_t>(p.K) * 3, 0.0f);
  if (mode == 1)
    for (int k = 0; k < p.K; ++k)
      for (int c = 0; c < 3; ++c) env[k * 3 + c] = static_cast<float>(L.environment->c[k][c]);
  glProgramUniform3fv(prog, glGetUniformLocation(prog, "u_env"), p.K, env.data());
  if (mode == 2) {
    const ilf::GridDesc& gd = L.grid->grid();
    set_vec3(prog, "u_grid_min", gd.volume.min);
    set_vec3(prog, "u_grid_max", gd.volume.max);
    set_vec3(prog, "u_grid_res", {static_cast<double>(gd.nx), static_cast<double>(gd.ny), static_cast<double>(gd.nz)});
  }
  if (p.bands > 0) {
    auto dz = sh::clamped_cosine_zh(p.bands);
    std::vector<float> df(dz.begin(), dz.end());
    glProgramUniform1fv(prog, glGetUniformLocation(prog, "u_diffuse_zh"), p.bands, df.data());
  }
  // Every sampler gets its own unit even when unused: two sampler types on one unit is an error.
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_grid"), 1);
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_glossy_maps"), 3);
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_albedo_textures"), 6);
  if (desc.sh_table_size > 0) {
    p.sh_table_tex = sh_table(std::max(1, p.bands));
    glProgramUniform1i(prog, glGetUniformLocation(prog, "u_sh_table"), 7);
    glProgramUniform1f(prog, glGetUniformLocation(prog, "u_sh_table_warp"), sh_table_warp(desc.sh_table_size));
  }
  p.loc_albedo = glGetUniformLocation(prog, "u_albedo");
  p.loc_specular = glGetUniformLocation(prog, "u_specular");
  p.loc_exponent = glGetUniformLocation(prog, "u_exponent");
  p.loc_glossy = glGetUniformLocation(prog, "u_glossy_zh");
  p.loc_glossy_layer = glGetUniformLocation(prog, "u_glossy_layer");
  p.loc_albedo_layer = glGetUniformLocation(prog, "u_albedo_layer");
  p.loc_lobe = glGetUniformLocation(prog, "u_lobe");
  p.loc_material = glGetUniformLocation(p.raster, "u_object");
  p.loc_light_vp = glGetUniformLocation(shadow_program, "u_light_view_projection");
}

void Renderer::Impl::shadow_passes(const FramePlan& p, GLuint tex, GLuint mats_ssbo, const std::vector<Mat4f>& mats,
                                   int size) {
  if (mats.empty()) return;
  glBindFramebuffer(GL_FRAMEBUFFER, p.shadow_fbo);
  glViewport(0, 0, size, size);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);  // both faces cast: open meshes (a floor, a room seen from outside)
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.5f, 2.0f);
  if (layered_shadow_program) {
    glUseProgram(layered_shadow_program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 11, mats_ssbo);
    glNamedFramebufferTexture(p.shadow_fbo, GL_DEPTH_ATTACHMENT, tex, 0);  // layered: all layers
    glClear(GL_DEPTH_BUFFER_BIT);
    for (auto& m : p.geometry->meshes) {
      glBindVertexArray(m.vao);
      glDrawElementsInstanced(GL_TRIANGLES, m.count, GL_UNSIGNED_INT, nullptr, static_cast<GLsizei>(mats.size()));
    }
  } else {
    glUseProgram(shadow_program);
    for (size_t i = 0; i < mats.size(); ++i) {
      glNamedFramebufferTextureLayer(p.shadow_fbo, GL_DEPTH_ATTACHMENT, tex, 0, static_cast<GLint>(i));
      glClear(GL_DEPTH_BUFFER_BIT);
      glUniformMatrix4fv(p.loc_light_vp, 1, GL_FALSE, mats[i].data());
      for (auto& m : p.geometry->meshes) {
        glBindVertexArray(m.vao);
        glDrawElements(GL_TRIANGLES, m.count, GL_UNSIGNED_INT, nullptr);
      }
    }
  }
  glDisable(GL_POLYGON_OFFSET_FILL);
}

// The frames: shadow passes, then the shading pass (forward), or the G-buffer pass then compute
// shading (deferred); one timer query per frame, read after the last frame so that the CPU never
// waits on the GPU between frames (a per-frame wait would count the GPU's idle gaps as frame time).
void Renderer::Impl::draw_frames(const FrameDesc& d, const FramePlan& p, int frames, GpuTiming* timing) {
  const int nframes = std::max(1, frames);
  std::vector<GLuint> queries(nframes);
  glGenQueries(nframes, queries.data());
  glFinish();
  auto wall0 = std::chrono::steady_clock::now();
  const std::vector<MeshBuffers>& meshes = p.geometry->meshes;
  for (int f = 0; f < nframes; ++f) {
    glBeginQuery(GL_TIME_ELAPSED, queries[f]);
    shadow_passes(p, p.shadow_tex, p.light_ssbo[1], p.shadow_mats, p.S);
    shadow_passes(p, p.spot_shadow_tex, p.spot_ssbo[1], p.spot_mats, p.SS);
    glBindFramebuffer(GL_FRAMEBUFFER, p.fbo);
    glViewport(0, 0, p.W, p.H);
    glClearColor(static_cast<float>(d.background.x), static_cast<float>(d.background.y),
                 static_cast<float>(d.background.z), 0.0f);
    if (p.deferred) {
      const GLuint zero[4] = {0, 0, 0, 0};
      glClearBufferuiv(GL_COLOR, 0, zero);
      glClear(GL_DEPTH_BUFFER_BIT);
    } else {
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    }
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glUseProgram(p.raster);
    glBindTextureUnit(0, p.shadow_tex);
    if (p.grid_tex) glBindTextureUnit(1, p.grid_tex);
    if (p.glossy_tex) glBindTextureUnit(3, p.glossy_tex);
    if (p.spot_tex) glBindTextureUnit(4, p.spot_tex);
    if (p.albedo_tex) glBindTextureUnit(6, p.albedo_tex);
    if (p.spot_shadow_tex) glBindTextureUnit(5, p.spot_shadow_tex);
    if (p.sh_table_tex) glBindTextureUnit(7, p.sh_table_tex);
    for (size_t i = 0; i < meshes.size(); ++i) {
      if (p.deferred) {
        glUniform1ui(p.loc_material, static_cast<GLuint>(i));
      } else {
        const Material& mat = d.objects[i].material;
        glUniform3f(p.loc_albedo, static_cast<float>(mat.albedo.x), static_cast<float>(mat.albedo.y),
                    static_cast<float>(mat.albedo.z));
        glUniform3f(p.loc_specular, static_cast<float>(mat.specular.x), static_cast<float>(mat.specular.y),
                    static_cast<float>(mat.specular.z));
        glUniform1f(p.loc_exponent, static_cast<float>(mat.exponent));
        glUniform1i(p.loc_glossy_layer, p.material_layer[i]);
        if (p.bands > 0) glUniform1fv(p.loc_glossy, p.bands, p.materials.data() + i * kMaterialFloats + 8);
        glUniform1i(p.loc_albedo_layer, p.albedo_layer[i]);
        glUniform1i(p.loc_lobe, mat.lobe == Lobe::BlinnPhong ? 1 : 0);
      }
      glBindVertexArray(meshes[i].vao);
      glDrawElements(GL_TRIANGLES, meshes[i].count, GL_UNSIGNED_INT, nullptr);
    }
    if (p.deferred) {
      glUseProgram(p.prog);
      glBindTextureUnit(2, p.vis_tex);
      glBindImageTexture(0, p.color_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
      glDispatchCompute(static_cast<GLuint>((p.W + 7) / 8), static_cast<GLuint>((p.H + 7) / 8), 1);
      glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    }
    glEndQuery(GL_TIME_ELAPSED);
  }
  glFinish();
  double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();
  std::vector<double> times;
  for (int f = 0; f < nframes; ++f) {
    GLuint64 ns = 0;
    glGetQueryObjectui64v(queries[f], GL_QUERY_RESULT, &ns);
    times.push_back(ns * 1e-6);
  }
  glDeleteQueries(nframes, queries.data());
  if (timing) {
    timing->frame_ms = times;
    timing->wall_ms_per_frame = wall_ms / nframes;
  }
}

namespace {

// The colour target read back into linear RGB and coverage (GL's rows go up).
void read_frame(const FramePlan& p, RenderResult& out) {
  out.color = Image(p.W, p.H, 3);
  out.coverage = Image(p.W, p.H, 1);
  std::vector<float> rgba(static_cast<size_t>(p.W) * p.H * 4);
  glGetTextureImage(p.color_tex, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(rgba.size() * sizeof(float)), rgba.data());
  for (int y = 0; y < p.H; ++y)
    for (int x = 0; x < p.W; ++x) {
      const float* px = rgba.data() + (static_cast<size_t>(p.H - 1 - y) * p.W + x) * 4;
      out.color.set_rgb(x, y, {px[0], px[1], px[2]});
      out.coverage.at(x, y, 0) = px[3];
    }
}

}  // namespace

RenderResult Renderer::render(const FrameDesc& d, int frames, GpuTiming* timing, bool read_back) {
  if (d.camera.distorted())
    fail(ErrorKind::Unsupported,
         "the GL backend cannot render through lens distortion (k1 k2 p1 p2 k3); use --backend cpu");
  Impl& r = *impl_;
  FramePlan p;
  r.plan_programs(d, p);
  r.plan_bounds(d, p);
  r.plan_lights(d, p);
  r.plan_spotlights(d, p);
  r.plan_shadow_arrays(d, p);
  r.plan_sh_grid(d, p);
  r.plan_targets(d, p);
  r.plan_materials(d, p);
  r.plan_uniforms(d, p);
  r.draw_frames(d, p, frames, timing);
  RenderResult out{Image(), Image(), p.unshadowed};
  if (read_back) read_frame(p, out);
  if (GLenum err = glGetError(); err != GL_NO_ERROR)
    fail(ErrorKind::Internal, "OpenGL error 0x{:x} while rendering", err);
  return out;
}

}  // namespace ibl::render::gl
