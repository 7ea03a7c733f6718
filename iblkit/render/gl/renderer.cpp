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
  glNamedBufferStorage(b, static_cast<GLsizeiptr>(std::max<size_t>(1, v.size()) * sizeof(T)), v.empty() ? nullptr : v.data(), 0);
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
    std::string defs = (desc.sh_table_size > 0 ? sh_table_glsl_source(b) : sh_glsl_source(b)) + (glossy ? "#define GLOSSY 1\n" : "#define GLOSSY 0\n");
    GLuint p = 0;
    switch (kind) {
      case Forward: p = build_program({{GL_VERTEX_SHADER, "mesh.vert", ""}, {GL_FRAGMENT_SHADER, "shade.frag", defs, {"shading.glsl"}}}); break;
      case GBuffer: p = build_program({{GL_VERTEX_SHADER, "mesh.vert", ""}, {GL_FRAGMENT_SHADER, "visibility.frag", ""}}); break;
      case Compute: p = build_program({{GL_COMPUTE_SHADER, "shade.comp", defs, {"shading.glsl"}}}); break;
    }
    programs[key] = p;
    return p;
  }
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
  impl_->shadow_program = build_program({{GL_VERTEX_SHADER, "shadow.vert", ""}, {GL_FRAGMENT_SHADER, "shadow.frag", ""}});
  GLint vertex_ssbos = 0;  // the layered pass reads its matrices from a storage buffer (GL 4.5 may allow none)
  glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &vertex_ssbos);
  if (desc.layered_shadows && vertex_ssbos > 0 && epoxy_has_gl_extension("GL_ARB_shader_viewport_layer_array"))
    impl_->layered_shadow_program =
        build_program({{GL_VERTEX_SHADER, "shadow_layered.vert", ""}, {GL_FRAGMENT_SHADER, "shadow.frag", ""}});
}
Renderer::~Renderer() = default;

unsigned Renderer::color_texture() const { return impl_->uploads.last_color_texture(); }

RenderResult Renderer::render(const FrameDesc& d, int frames, GpuTiming* timing, bool read_back) {
  const geometry::Camera& cam = d.camera;
  const int W = cam.width, H = cam.height;
  if (W <= 0 || H <= 0 || W > 16384 || H > 16384) fail(ErrorKind::Value, "frame size {}x{} is invalid", W, H);
  const Lighting& L = d.lighting;
  int bands = L.grid ? L.grid->bands() : (L.environment ? L.environment->bands : 0);
  bool glossy = false;
  for (const auto& o : d.objects) glossy |= max_component(o.material.specular) > 0;
  const bool deferred = impl_->desc.deferred;
  GLuint prog = impl_->program(bands, glossy, deferred ? Impl::Compute : Impl::Forward);
  GLuint raster = deferred ? impl_->program(bands, glossy, Impl::GBuffer) : prog;
  int K = std::max(1, bands) * std::max(1, bands);

  // Scene bounds for the shadow maps' orthographic frusta.
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto& o : d.objects) {
    Vec3 a, b;
    o.mesh->bounds(&a, &b);
    for (int k = 0; k < 3; ++k) { lo[k] = std::min(lo[k], a[k]); hi[k] = std::max(hi[k], b[k]); }
  }
  const Uploads::Geometry& geometry = impl_->uploads.geometry(d.objects, deferred);
  const std::vector<MeshBuffers>& meshes = geometry.meshes;
  Vec3 centre = (lo + hi) * 0.5;
  double radius = std::max(1e-6, 0.5 * length(hi - lo));

  // Lights and shadow matrices.
  std::vector<float> light_data;
  std::vector<Mat4f> shadow_mats;
  int unshadowed = 0;
  for (const auto& l : L.lights) {
    if (l.shadow && static_cast<int>(shadow_mats.size()) >= kMaxShadowMaps) ++unshadowed;
    float layer = -1;
    if (l.shadow && static_cast<int>(shadow_mats.size()) < kMaxShadowMaps) {
      layer = static_cast<float>(shadow_mats.size());
      shadow_mats.push_back(light_view_projection(l.direction, centre, radius));
    }
    Vec3 dir = normalize(l.direction);
    light_data.insert(light_data.end(), {static_cast<float>(dir.x), static_cast<float>(dir.y), static_cast<float>(dir.z), layer,
                                         static_cast<float>(l.irradiance.x), static_cast<float>(l.irradiance.y),
                                         static_cast<float>(l.irradiance.z), 0.0f});
  }
  // Point lights: a perspective shadow map when they sit outside the objects' bounding sphere, else a
  // cube of six (layers of the same array). A light that finds no free layers is drawn unshadowed
  // and counted in `unshadowed`.
  std::vector<float> point_data;
  for (const auto& l : L.point_lights) {
    float layer = -1;
    Mat4f m;
    float cube = 0;
    if (l.shadow) {
      const int free_layers = kMaxShadowMaps - static_cast<int>(shadow_mats.size());
      if (point_light_view_projection(l.position, centre, radius, &m) && free_layers >= 1) {
        layer = static_cast<float>(shadow_mats.size());
        shadow_mats.push_back(m);
      } else if (free_layers >= 6) {
        // Inside (or next to) the objects' bounding sphere: a cube map of six faces.
        layer = static_cast<float>(shadow_mats.size());
        cube = 1;
        for (const Mat4f& f : cube_light_view_projections(l.position, length(centre - l.position) + radius * 1.01))
          shadow_mats.push_back(f);
      } else {
        ++unshadowed;
      }
    }
    point_data.insert(point_data.end(), {static_cast<float>(l.position.x), static_cast<float>(l.position.y),
                                         static_cast<float>(l.position.z), layer, static_cast<float>(l.intensity.x),
                                         static_cast<float>(l.intensity.y), static_cast<float>(l.intensity.z), cube});
  }
  const GLuint point_ssbo = storage_buffer(point_data, 7);
  // Textured spotlights: their textures in one mip-mapped 2D array (one layer each, all of one
  // size), their parameters in an SSBO, and a perspective shadow map each (its own array) covering
  // the frustum through its texture's extent on M.
  std::vector<float> spot_data;
  std::vector<Mat4f> spot_mats;
  GLuint spot_tex = 0;
  int spot_levels = 0;
  const std::vector<float>* spot_scale = nullptr;
  if (!L.spotlights.empty()) {
    const Uploads::SpotTextures& st = impl_->uploads.spot_textures(L.spotlights);
    spot_tex = st.tex;
    spot_levels = st.levels;
    spot_scale = &st.scale;
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
        if (d.spot_shadow_share > 0 && dot(seed.frame.n, sp.frame.n) > 0.99999 && length(seed.position - sp.position) <= d.spot_shadow_share)
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
        const double pd = sp.plane_distance, margin = std::max((sp.tex_max.x - sp.tex_min.x) / tw, (sp.tex_max.y - sp.tex_min.y) / th) + spread;
        const double tx = (std::max(std::abs(sp.tex_min.x), std::abs(sp.tex_max.x)) + margin) / pd;
        const double ty = (std::max(std::abs(sp.tex_min.y), std::abs(sp.tex_max.y)) + margin) / pd;
        geometry::Camera c;
        c.eye = eye;
        c.target = eye + sp.frame.n;
        c.up = sp.frame.b;
        c.fov_y_deg = 2 * std::atan(ty) * 180 / kPi;
        c.width = 1000;
        c.height = std::max(1, static_cast<int>(std::lround(1000 * ty / tx)));
        const double far_d = length(centre - eye) + radius;
        c.zfar = far_d * 1.01;
        c.znear = std::max(far_d * 1e-3, (length(centre - eye) - radius) * 0.95);
        layer = static_cast<float>(spot_mats.size());
        group_layer[group_of[i]] = layer;
        Mat4f proj = c.projection();
        proj[0] = static_cast<float>(1.0 / tx);  // exact horizontal extent (the aspect above is rounded)
        spot_mats.push_back(mul(proj, c.view()));
      }
      const double texel = std::max((sp.tex_max.x - sp.tex_min.x) / tw, (sp.tex_max.y - sp.tex_min.y) / th);
      const float row[24] = {static_cast<float>(sp.position.x), static_cast<float>(sp.position.y), static_cast<float>(sp.position.z), layer,
                             static_cast<float>(sp.frame.t.x), static_cast<float>(sp.frame.t.y), static_cast<float>(sp.frame.t.z), static_cast<float>(sp.tex_min.x),
                             static_cast<float>(sp.frame.b.x), static_cast<float>(sp.frame.b.y), static_cast<float>(sp.frame.b.z), static_cast<float>(sp.tex_min.y),
                             static_cast<float>(sp.frame.n.x), static_cast<float>(sp.frame.n.y), static_cast<float>(sp.frame.n.z), static_cast<float>(sp.plane_distance),
                             static_cast<float>(sp.tex_max.x), static_cast<float>(sp.tex_max.y), static_cast<float>(sp.support_area), static_cast<float>(sp.support_width),
                             static_cast<float>(texel), static_cast<float>(spot_levels), static_cast<float>(i), (*spot_scale)[i]};
      spot_data.insert(spot_data.end(), row, row + 24);
    }
  }
  const GLuint spot_ssbo[2] = {storage_buffer(spot_data, 8), storage_buffer(spot_mats, 9)};
  const int SS = d.spot_shadow_map_size;
  GLuint spot_shadow_tex = 0;
  if (!spot_mats.empty()) {
    if (SS < 16 || SS > 8192) fail(ErrorKind::Value, "spotlight shadow map size {} is out of range 16..8192", SS);
    spot_shadow_tex = shadow_map_array(SS, static_cast<int>(spot_mats.size()));
  }

  const GLuint ssbo[2] = {storage_buffer(light_data, 0), storage_buffer(shadow_mats, 1)};

  // Shadow-map array and its framebuffer.
  // (A 1×1 placeholder when no light casts shadows: the sampler needs a texture.)
  if (!shadow_mats.empty() && (d.shadow_map_size < 16 || d.shadow_map_size > 8192))
    fail(ErrorKind::Value, "shadow map size {} is out of range 16..8192", d.shadow_map_size);
  int S = shadow_mats.empty() ? 1 : d.shadow_map_size, layers = std::max<int>(1, static_cast<int>(shadow_mats.size()));
  GLuint shadow_tex = shadow_map_array(S, layers), shadow_fbo;
  glCreateFramebuffers(1, &shadow_fbo);

  // SH grid: one RGBA16F 3D texture, coefficient k in slices [k·nz, (k+1)·nz).
  GLuint grid_tex = 0;
  if (L.grid) {
    const ilf::SHGrid& g = *L.grid;
    const ilf::GridDesc& gd = g.grid();
    if (g.data().size() != static_cast<size_t>(gd.count()) * K * 3)
      fail(ErrorKind::Value, "SH grid {}x{}x{} with {} bands holds {} values, expected {}", gd.nx, gd.ny, gd.nz, g.bands(),
           g.data().size(), static_cast<size_t>(gd.count()) * K * 3);
    GLint max3d = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    if (gd.nz * K > max3d)
      fail(ErrorKind::Unsupported, "SH grid needs a 3D texture {} deep; this GL allows {}", gd.nz * K, max3d);
    grid_tex = impl_->uploads.grid_texture(g);
  }

  // Colour target (the forward pass renders into it; the deferred pass writes it as an image), and
  // the deferred G-buffer.
  GLuint color_tex = impl_->uploads.color_texture(W, H), depth_rb, fbo, vis_tex = 0;
  glCreateRenderbuffers(1, &depth_rb);
  glNamedRenderbufferStorage(depth_rb, GL_DEPTH_COMPONENT32F, W, H);
  glCreateFramebuffers(1, &fbo);
  if (deferred) {
    glCreateTextures(GL_TEXTURE_2D, 1, &vis_tex);
    glTextureStorage2D(vis_tex, 1, GL_R32UI, W, H);
    glTextureParameteri(vis_tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(vis_tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, vis_tex, 0);
    for (int i = 0; i < 4; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3 + i, geometry.ssbo[i]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 10, geometry.ssbo[4]);
  } else {
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color_tex, 0);
  }
  glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb);
  if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    fail(ErrorKind::Unsupported, "GL framebuffer {}x{} is incomplete", W, H);

  // Prefiltered glossy maps of a distant probe: one 2D array texture, a layer per map used by a
  // material (all of one size).
  std::vector<const GlossyMap*> gmaps;
  std::vector<int> material_layer;
  for (const auto& o : d.objects) {
    const GlossyMap* g = L.grid ? nullptr : L.glossy_map(o.material.environment_exponent());
    int layer = -1;
    if (g) {
      auto it = std::find(gmaps.begin(), gmaps.end(), g);
      layer = static_cast<int>(it - gmaps.begin());
      if (it == gmaps.end()) gmaps.push_back(g);
    }
    material_layer.push_back(layer);
  }
  GLuint glossy_tex = 0;
  if (!gmaps.empty()) {
    const int gw = gmaps[0]->latlong.width(), gh = gmaps[0]->latlong.height();
    for (const GlossyMap* g : gmaps)
      if (g->latlong.width() != gw || g->latlong.height() != gh || g->latlong.channels() != 3)
        fail(ErrorKind::Unsupported, "the GL renderer takes glossy maps of one size per frame ({}x{} and {}x{} given)", gw, gh,
             g->latlong.width(), g->latlong.height());
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &glossy_tex);
    glTextureStorage3D(glossy_tex, 1, GL_RGBA32F, gw, gh, static_cast<GLsizei>(gmaps.size()));
    std::vector<float> rgba(static_cast<size_t>(gw) * gh * 4);
    for (size_t li = 0; li < gmaps.size(); ++li) {
      const Image& im = gmaps[li]->latlong;
      for (size_t i = 0; i < im.pixel_count(); ++i)
        for (int c = 0; c < 4; ++c) rgba[i * 4 + c] = c < 3 ? im.data()[i * 3 + c] : 0.0f;
      glTextureSubImage3D(glossy_tex, 0, 0, 0, static_cast<GLint>(li), gw, gh, 1, GL_RGBA, GL_FLOAT, rgba.data());
    }
    glTextureParameteri(glossy_tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(glossy_tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(glossy_tex, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(glossy_tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }

  // Materials (deferred: a table indexed from the G-buffer; forward: uniforms per object).
  // Albedo textures: one 2D array, a layer per distinct texture (all of one size).
  std::vector<const Image*> albedo_images;
  std::vector<int> albedo_layer;
  for (const auto& o : d.objects) {
    int layer = -1;
    if (o.material.texture) {
      const Image* im = o.material.texture.get();
      auto it = std::find(albedo_images.begin(), albedo_images.end(), im);
      layer = static_cast<int>(it - albedo_images.begin());
      if (it == albedo_images.end()) albedo_images.push_back(im);
    }
    albedo_layer.push_back(layer);
  }
  GLuint albedo_tex = 0;
  if (!albedo_images.empty()) {
    const int aw = albedo_images[0]->width(), ah = albedo_images[0]->height();
    for (const Image* im : albedo_images)
      if (im->width() != aw || im->height() != ah || im->channels() < 3)
        fail(ErrorKind::Unsupported, "the GL renderer takes RGB albedo textures of one size per frame ({}x{} and {}x{}x{} given)", aw, ah,
             im->width(), im->height(), im->channels());
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &albedo_tex);
    glTextureStorage3D(albedo_tex, 1, GL_RGBA32F, aw, ah, static_cast<GLsizei>(albedo_images.size()));
    std::vector<float> rgba(static_cast<size_t>(aw) * ah * 4);
    for (size_t li = 0; li < albedo_images.size(); ++li) {
      const Image& im = *albedo_images[li];
      for (size_t i = 0; i < im.pixel_count(); ++i)
        for (int c = 0; c < 4; ++c) rgba[i * 4 + c] = c < 3 ? im.data()[i * im.channels() + c] : 1.0f;
      glTextureSubImage3D(albedo_tex, 0, 0, 0, static_cast<GLint>(li), aw, ah, 1, GL_RGBA, GL_FLOAT, rgba.data());
    }
    glTextureParameteri(albedo_tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(albedo_tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(albedo_tex, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(albedo_tex, GL_TEXTURE_WRAP_T, GL_REPEAT);
  }

  std::vector<float> materials;
  constexpr int kMaterialFloats = 24;  // MaterialGpu in shade.comp
  for (size_t oi = 0; oi < d.objects.size(); ++oi) {
    const Material& m = d.objects[oi].material;
    float row[kMaterialFloats] = {static_cast<float>(m.albedo.x),   static_cast<float>(m.albedo.y),   static_cast<float>(m.albedo.z),
                     static_cast<float>(material_layer[oi]),
                     static_cast<float>(m.specular.x), static_cast<float>(m.specular.y), static_cast<float>(m.specular.z),
                     static_cast<float>(m.exponent)};
    if (bands > 0) {
      auto gz = sh::phong_zh(bands, m.environment_exponent());
      for (int l = 0; l < std::min(bands, 12); ++l) row[8 + l] = static_cast<float>(gz[l]);
    }
    row[20] = static_cast<float>(albedo_layer[oi]);
    row[21] = m.lobe == Lobe::BlinnPhong ? 1.0f : 0.0f;
    materials.insert(materials.end(), row, row + kMaterialFloats);
  }
  const GLuint material_ssbo = storage_buffer(materials, 2);

  // Uniforms of the shading program.
  Mat4f vp = mul(cam.projection(), cam.view());
  glProgramUniformMatrix4fv(raster, glGetUniformLocation(raster, "u_view_projection"), 1, GL_FALSE, vp.data());
  set_vec3(prog, "u_eye", cam.eye);
  set_vec3(prog, "u_background", d.background);
  if (deferred) {
    // Camera rays: dir(x, y) ∝ f + r·sx + u·sy with sx, sy linear in the pixel position.
    Vec3 f = normalize(cam.target - cam.eye), r = normalize(cross(f, cam.up)), u = cross(r, f);
    double t = std::tan(cam.fov_y_deg * kPi / 360.0), aspect = static_cast<double>(W) / H;
    set_vec3(prog, "u_ray00", f - r * (t * aspect) + u * t);
    set_vec3(prog, "u_ray_dx", r * (2 * t * aspect / W));
    set_vec3(prog, "u_ray_dy", u * (-2 * t / H));
  }
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_light_count"), static_cast<GLint>(L.lights.size()));
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_point_light_count"), static_cast<GLint>(L.point_lights.size()));
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_spot_count"), static_cast<GLint>(L.spotlights.size()));
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_spot_textures"), 4);
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_spot_shadows"), 5);
  glProgramUniform1f(prog, glGetUniformLocation(prog, "u_shadow_bias"), static_cast<float>(d.shadow_bias));
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_shadow_maps"), 0);
  int mode = L.grid ? 2 : (L.environment ? 1 : 0);
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_sh_mode"), mode);
  std::vector<float> env(static_cast<size_t>(K) * 3, 0.0f);
  if (mode == 1)
    for (int k = 0; k < K; ++k)
      for (int c = 0; c < 3; ++c) env[k * 3 + c] = static_cast<float>(L.environment->c[k][c]);
  glProgramUniform3fv(prog, glGetUniformLocation(prog, "u_env"), K, env.data());
  if (mode == 2) {
    const ilf::GridDesc& gd = L.grid->grid();
    set_vec3(prog, "u_grid_min", gd.volume.min);
    set_vec3(prog, "u_grid_max", gd.volume.max);
    set_vec3(prog, "u_grid_res", {static_cast<double>(gd.nx), static_cast<double>(gd.ny), static_cast<double>(gd.nz)});
  }
  if (bands > 0) {
    auto dz = sh::clamped_cosine_zh(bands);
    std::vector<float> df(dz.begin(), dz.end());
    glProgramUniform1fv(prog, glGetUniformLocation(prog, "u_diffuse_zh"), bands, df.data());
  }
  // Every sampler gets its own unit even when unused: two sampler types on one unit is an error.
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_grid"), 1);
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_glossy_maps"), 3);
  glProgramUniform1i(prog, glGetUniformLocation(prog, "u_albedo_textures"), 6);
  GLuint sh_table_tex = 0;
  if (impl_->desc.sh_table_size > 0) {
    sh_table_tex = impl_->sh_table(std::max(1, bands));
    glProgramUniform1i(prog, glGetUniformLocation(prog, "u_sh_table"), 7);
    glProgramUniform1f(prog, glGetUniformLocation(prog, "u_sh_table_warp"), sh_table_warp(impl_->desc.sh_table_size));
  }
  GLint loc_albedo = glGetUniformLocation(prog, "u_albedo"), loc_specular = glGetUniformLocation(prog, "u_specular"),
        loc_exponent = glGetUniformLocation(prog, "u_exponent"), loc_glossy = glGetUniformLocation(prog, "u_glossy_zh"),
        loc_glossy_layer = glGetUniformLocation(prog, "u_glossy_layer"),
        loc_albedo_layer = glGetUniformLocation(prog, "u_albedo_layer"), loc_lobe = glGetUniformLocation(prog, "u_lobe"),
        loc_material = glGetUniformLocation(raster, "u_object"),
        loc_light_vp = glGetUniformLocation(impl_->shadow_program, "u_light_view_projection");

  // One timer query per frame, read after the last frame so that the CPU never waits on the GPU
  // between frames (a per-frame wait would count the GPU's idle gaps as frame time).
  const int nframes = std::max(1, frames);
  std::vector<GLuint> queries(nframes);
  glGenQueries(nframes, queries.data());
  std::vector<double> times;
  glFinish();
  auto wall0 = std::chrono::steady_clock::now();
  for (int f = 0; f < nframes; ++f) {
    glBeginQuery(GL_TIME_ELAPSED, queries[f]);
    // Shadow passes: every layer of a depth array from its light matrix, in one instanced draw per
    // mesh (layered) or one pass per layer.
    auto shadow_passes = [&](GLuint tex, GLuint mats_ssbo, const std::vector<Mat4f>& mats, int size) {
      if (mats.empty()) return;
      glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
      glViewport(0, 0, size, size);
      glEnable(GL_DEPTH_TEST);
      glDisable(GL_CULL_FACE);  // both faces cast: open meshes (a floor, a room seen from outside)
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.5f, 2.0f);
      if (impl_->layered_shadow_program) {
        glUseProgram(impl_->layered_shadow_program);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 11, mats_ssbo);
        glNamedFramebufferTexture(shadow_fbo, GL_DEPTH_ATTACHMENT, tex, 0);  // layered: all layers
        glClear(GL_DEPTH_BUFFER_BIT);
        for (auto& m : meshes) {
          glBindVertexArray(m.vao);
          glDrawElementsInstanced(GL_TRIANGLES, m.count, GL_UNSIGNED_INT, nullptr, static_cast<GLsizei>(mats.size()));
        }
      } else {
        glUseProgram(impl_->shadow_program);
        for (size_t i = 0; i < mats.size(); ++i) {
          glNamedFramebufferTextureLayer(shadow_fbo, GL_DEPTH_ATTACHMENT, tex, 0, static_cast<GLint>(i));
          glClear(GL_DEPTH_BUFFER_BIT);
          glUniformMatrix4fv(loc_light_vp, 1, GL_FALSE, mats[i].data());
          for (auto& m : meshes) {
            glBindVertexArray(m.vao);
            glDrawElements(GL_TRIANGLES, m.count, GL_UNSIGNED_INT, nullptr);
          }
        }
      }
      glDisable(GL_POLYGON_OFFSET_FILL);
    };
    shadow_passes(shadow_tex, ssbo[1], shadow_mats, S);
    shadow_passes(spot_shadow_tex, spot_ssbo[1], spot_mats, SS);
    // Shading pass (forward), or G-buffer pass then compute shading (deferred).
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, W, H);
    glClearColor(static_cast<float>(d.background.x), static_cast<float>(d.background.y), static_cast<float>(d.background.z), 0.0f);
    if (deferred) {
      const GLuint zero[4] = {0, 0, 0, 0};
      glClearBufferuiv(GL_COLOR, 0, zero);
      glClear(GL_DEPTH_BUFFER_BIT);
    } else {
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    }
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glUseProgram(raster);
    glBindTextureUnit(0, shadow_tex);
    if (grid_tex) glBindTextureUnit(1, grid_tex);
    if (glossy_tex) glBindTextureUnit(3, glossy_tex);
    if (spot_tex) glBindTextureUnit(4, spot_tex);
    if (albedo_tex) glBindTextureUnit(6, albedo_tex);
    if (spot_shadow_tex) glBindTextureUnit(5, spot_shadow_tex);
    if (sh_table_tex) glBindTextureUnit(7, sh_table_tex);
    for (size_t i = 0; i < meshes.size(); ++i) {
      if (deferred) {
        glUniform1ui(loc_material, static_cast<GLuint>(i));
      } else {
        const Material& mat = d.objects[i].material;
        glUniform3f(loc_albedo, static_cast<float>(mat.albedo.x), static_cast<float>(mat.albedo.y), static_cast<float>(mat.albedo.z));
        glUniform3f(loc_specular, static_cast<float>(mat.specular.x), static_cast<float>(mat.specular.y), static_cast<float>(mat.specular.z));
        glUniform1f(loc_exponent, static_cast<float>(mat.exponent));
        glUniform1i(loc_glossy_layer, material_layer[i]);
        if (bands > 0) glUniform1fv(loc_glossy, bands, materials.data() + i * kMaterialFloats + 8);
        glUniform1i(loc_albedo_layer, albedo_layer[i]);
        glUniform1i(loc_lobe, mat.lobe == Lobe::BlinnPhong ? 1 : 0);
      }
      glBindVertexArray(meshes[i].vao);
      glDrawElements(GL_TRIANGLES, meshes[i].count, GL_UNSIGNED_INT, nullptr);
    }
    if (deferred) {
      glUseProgram(prog);
      glBindTextureUnit(2, vis_tex);
      glBindImageTexture(0, color_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
      glDispatchCompute(static_cast<GLuint>((W + 7) / 8), static_cast<GLuint>((H + 7) / 8), 1);
      glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    }
    glEndQuery(GL_TIME_ELAPSED);
  }
  glFinish();
  double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();
  for (int f = 0; f < nframes; ++f) {
    GLuint64 ns = 0;
    glGetQueryObjectui64v(queries[f], GL_QUERY_RESULT, &ns);
    times.push_back(ns * 1e-6);
  }
  if (timing) {
    timing->frame_ms = times;
    timing->wall_ms_per_frame = wall_ms / nframes;
  }

  RenderResult out{Image(), Image(), unshadowed};
  if (read_back) {
    out.color = Image(W, H, 3);
    out.coverage = Image(W, H, 1);
    std::vector<float> rgba(static_cast<size_t>(W) * H * 4);
    glGetTextureImage(color_tex, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(rgba.size() * sizeof(float)), rgba.data());
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const float* p = rgba.data() + (static_cast<size_t>(H - 1 - y) * W + x) * 4;  // GL rows go up
        out.color.set_rgb(x, y, {p[0], p[1], p[2]});
        out.coverage.at(x, y, 0) = p[3];
      }
  }
  GLenum err = glGetError();
  glDeleteQueries(nframes, queries.data());
  glDeleteFramebuffers(1, &fbo);
  glDeleteFramebuffers(1, &shadow_fbo);
  glDeleteRenderbuffers(1, &depth_rb);
  if (deferred) {
    glDeleteTextures(1, &vis_tex);
  }
  glDeleteBuffers(1, &material_ssbo);
  glDeleteTextures(1, &shadow_tex);
  if (glossy_tex) glDeleteTextures(1, &glossy_tex);
  if (albedo_tex) glDeleteTextures(1, &albedo_tex);
  if (spot_shadow_tex) glDeleteTextures(1, &spot_shadow_tex);
  glDeleteBuffers(2, spot_ssbo);
  glDeleteBuffers(2, ssbo);
  glDeleteBuffers(1, &point_ssbo);
  if (err != GL_NO_ERROR) fail(ErrorKind::Internal, "OpenGL error 0x{:x} while rendering", err);
  return out;
}

}  // namespace ibl::render::gl
