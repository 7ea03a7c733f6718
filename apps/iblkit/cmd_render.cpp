// iblkit render: a mesh scene lit by an iblkit representation, on the CPU (reference) or with
// OpenGL (real time, headless EGL). Prints per-frame GPU time and fps for the GL backend.
#ifdef IBLKIT_HAVE_GEOMETRY
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/render/cpu_renderer.h"
#include "iblkit/render/lighting_io.h"
#include "iblkit/render/objects.h"
#include "iblkit/render/prefilter.h"
#include "iblkit/sh/project.h"
#include "render_setup.h"
#include "render_truth.h"
#ifdef IBLKIT_HAVE_GL
#include "iblkit/render/gl/context.h"
#include "iblkit/render/gl/renderer.h"
#endif

namespace {

namespace fs = std::filesystem;
using namespace ibl;
using namespace ibl::render;

struct Opts {
  std::vector<std::string> lights;
  render::ObjectDesc object;          // scene, --object-size, --triangles (and --at)
  render::LightingReadDesc lighting;  // --bands, --shadows (and the probe read options, --luminaire…)
  std::string out = "frame.png", backend = "auto", size = "1024x768", eye, target,
              at = "0,0,0";  // eye, target empty: from --at
  int frames = 1, sh_table = 0;
  iblcli::ShadowMapOptions shadow_maps;
  double gloss = 0, exponent = 20;
  std::string glossy = "map";
  std::string truth;
  int truth_samples = 4, truth_bounces = 1;
  double floor_size = 6;
  std::string luminaire = "0,1,0", luminaire_dir = "0,0,1";
  std::string texture, lobe = "phong", albedo = "0.75,0.75,0.75";
  double exposure = 0, fov = 40;
};

void add_options(CLI::App& app, Opts* o) {
  app.add_option("scene", o->object.scene,
                 "the object: blob (a bunny-sized procedural object), sphere, or a mesh file (OBJ, PLY, glTF), "
                 "scaled to --object-size and placed at --at, on a floor")
      ->capture_default_str();
  app.add_option("-l,--light", o->lights,
                 "lighting: a probe image, an SH grid (.shgrid, or an adaptive .shtree resampled to dense), "
                 "iblkit.sh/1 or iblkit.lights/1 JSON; several render one "
                 "frame each (OUT_<name>.ext; NAME_<k> where two share a name)")
      ->required();
  app.add_option("--at", o->at, "place the object's centre here, x,y,z (e.g. inside an SH grid's volume)")
      ->capture_default_str();
  app.add_option("--object-size", o->object.size,
                 "object size in metres; 0 keeps a mesh file's own size and place (a room)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  app.add_option("-o,--out", o->out, "output .png (tone mapped) or .exr (linear)")->capture_default_str();
  app.add_option("--backend", o->backend, "cpu, gl or auto (gl when available)")
      ->check(CLI::IsMember({"cpu", "gl", "auto"}))
      ->capture_default_str();
  app.add_option("--size", o->size, "frame size WxH")->capture_default_str();
  app.add_option("--frames", o->frames, "GL: render this many frames and report the median GPU time")
      ->check(CLI::Range(1, 10000));
  app.add_option("--shadows", o->lighting.shadows, "lights (in the file's priority order) that cast shadows")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  iblcli::add_shadow_map_options(app, &o->shadow_maps);
  app.add_option("--bands", o->lighting.bands, "SH bands when projecting a probe")
      ->check(CLI::Range(1, 9))
      ->capture_default_str();
  app.add_option("--triangles", o->object.triangles, "triangles of the blob")
      ->check(CLI::Range(100, 5000000))
      ->capture_default_str();
  app.add_option("--gloss", o->gloss, "weight of the glossy Phong lobe (0..1)")->check(CLI::Range(0.0, 1.0));
  app.add_option("--exponent", o->exponent, "Phong exponent of the glossy lobe")->check(CLI::Range(1.0, 10000.0));
  app.add_option("--lobe", o->lobe,
                 "glossy lobe: phong, or blinn (Blinn-Phong for lights; SH and maps use Phong of exponent/4)")
      ->check(CLI::IsMember({"phong", "blinn"}))
      ->capture_default_str();
  app.add_option("--albedo", o->albedo, "the object's diffuse reflectance r,g,b")->capture_default_str();
  app.add_option("--texture", o->texture,
                 "albedo texture of the object (sRGB PNG/JPG or linear EXR), at the mesh's UVs");
  app.add_option("--exposure", o->exposure, "stops added to the auto exposure of PNG output")->capture_default_str();
  app.add_option("--glossy", o->glossy,
                 "probe lighting with --gloss > 0: the glossy lobe from a prefiltered Phong map of the probe (map) "
                 "or from its --bands SH (sh, band-limited)")
      ->check(CLI::IsMember({"map", "sh"}))
      ->capture_default_str();
  app.add_option(
         "--sh-table", o->sh_table,
         "GL backend only: evaluate the SH basis from a precomputed table with faces of N×N texels (Löw et al.'s "
         "suggested variant; 64: |ΔY| about 2e-3) instead of its polynomials per fragment (0)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option("--floor-size", o->floor_size,
                 "side of the square floor under the object, metres (a table top when small; 0: no floor)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  app.add_option(
      "--truth", o->truth,
      "a lab scene (iblkit.scene/1, e.g. examples/low-scene2.json): also photograph the object and floor in it "
      "with its real emitters (lab path tracing) and report the frame's error against that photograph");
  app.add_option("--truth-samples", o->truth_samples, "--truth: n×n rays per pixel")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option(
         "--truth-bounces", o->truth_bounces,
         "--truth: indirect bounces; one more than the capture's (lab capture --bounces, 0 by default): a probe "
         "sees the room's lit walls and floor, so their light must reach the photographed object too")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  app.add_option("--luminaire", o->luminaire, "a near-field dataset's luminaire: centre of its sampling plane, x,y,z")
      ->capture_default_str();
  app.add_option("--luminaire-dir", o->luminaire_dir, "the direction the luminaire shines, x,y,z")
      ->capture_default_str();
  app.add_option("--eye", o->eye, "camera position x,y,z (default: --at + (0, 0.5, 1.6), looking at the object)");
  app.add_option("--fov", o->fov, "vertical field of view, degrees")
      ->check(CLI::Range(1.0, 170.0))
      ->capture_default_str();
  app.add_option("--target", o->target, "camera target x,y,z (default: --at)");
  app.footer(
      "Examples:\n  iblkit render blob --light probe.exr --out blob.png --backend cpu --size 400x300\n"
      "  iblkit render blob --light lights.json --backend gl --frames 10 --size 320x240 --out blob.exr\n"
      "  iblkit render blob --light grid.shgrid --at 0.5,0.3,0.5 --object-size 0.3 --eye 0.5,0.6,1.6 --target "
      "0.5,0.3,0.5");
}

// What the frame shows: the object (and a floor under it) with its material; `d` points at them.
struct Scene {
  geometry::TriMesh object, floor;
  FrameDesc d;
};

// The frame the options describe (camera, object, floor, material), lighting still empty.
void make_scene(const Opts& o, Scene* s) {
  int w = 0, h = 0;
  if (std::sscanf(o.size.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > 16384 || h > 16384)
    fail(ErrorKind::Value, "--size '{}': expected WxH, e.g. 1024x768", o.size);
  FrameDesc& d = s->d;
  d.camera.width = w;
  d.camera.height = h;
  o.shadow_maps.apply(&d);
  render::ObjectDesc od = o.object;
  od.at = iblcli::parse_vec3(o.at, "--at");
  // The camera looks at the object wherever --at puts it, unless --eye/--target say otherwise.
  d.camera.target = o.target.empty() ? od.at : iblcli::parse_vec3(o.target, "--target");
  d.camera.eye = o.eye.empty() ? od.at + Vec3{0, 0.5, 1.6} : iblcli::parse_vec3(o.eye, "--eye");
  d.camera.fov_y_deg = o.fov;
  if (!(od.size > 0) && (od.scene == "blob" || od.scene == "sphere"))
    fail(ErrorKind::Value, "--object-size must be > 0 for the {}", od.scene);
  s->object = render::make_object(od);
  Vec3 lo, hi;
  s->object.bounds(&lo, &hi);
  if (o.floor_size > 0) {
    s->floor = geometry::make_floor(o.floor_size, lo.y - 1e-3);  // just under the object's lowest point,
    s->floor.transform(1.0, {od.at.x, 0, od.at.z});              // centred under it
  }
  Material mat = iblcli::object_material(o.albedo, o.gloss, o.exponent, o.lobe, o.texture);
  d.objects = {{&s->object, mat}};
  if (o.floor_size > 0) d.objects.push_back({&s->floor, Material{{0.5, 0.5, 0.5}, {0, 0, 0}, 1}});
}

// The backend that renders: "cpu", or "gl" with its context (current while this lives).
struct Backend {
  std::string name;               // "cpu" or "gl"
  std::string gl_renderer;        // the GL context's renderer string
  std::shared_ptr<void> context;  // the GL context
};

// --backend: cpu, gl, or auto (gl when a context opens, else the CPU).
Backend open_backend(const std::string& wanted) {
  Backend b{wanted, "", nullptr};
#ifdef IBLKIT_HAVE_GL
  if (b.name != "cpu") {
    try {
      auto ctx = std::make_shared<gl::Context>();
      b.gl_renderer = ctx->renderer();
      b.context = ctx;
      b.name = "gl";
    } catch (const Error& e) {
      if (b.name == "gl")
        fail(ErrorKind::Unsupported, "no OpenGL here ({}); --backend cpu or auto renders on the CPU", e.what());
      iblcli::info(fmt::format("no OpenGL here ({}); rendering on the CPU", e.what()));
      b.name = "cpu";
    }
  }
#else
  if (b.name == "gl") fail(ErrorKind::Unsupported, "this build has no OpenGL renderer (libepoxy missing)");
  b.name = "cpu";
#endif
  return b;
}

// One frame on the backend; its timing into j.
RenderResult render_frame(const Opts& o, const FrameDesc& d, const Backend& backend, nlohmann::json& j) {
  RenderResult f;
#ifdef IBLKIT_HAVE_GL
  if (backend.name == "gl") {
    gl::RendererDesc gl_desc;
    gl_desc.sh_table_size = o.sh_table;
    gl::Renderer r(gl_desc);
    gl::GpuTiming t;
    f = r.render(d, o.frames, &t);
    std::vector<double> ms = t.frame_ms;
    std::sort(ms.begin(), ms.end());
    double med = ms[ms.size() / 2];
    j["gl_renderer"] = backend.gl_renderer;
    j["wall_ms_per_frame"] = t.wall_ms_per_frame;
    if (backend.gl_renderer.find("llvmpipe") == std::string::npos) {
      j["gpu_ms_median"] = med;
      j["fps_gpu"] = med > 0 ? 1000.0 / med : 0.0;
    }
    if (f.unshadowed_lights > 0) {
      j["unshadowed_lights"] = f.unshadowed_lights;
      iblcli::info(fmt::format(
          "{} shadow-casting lights got no shadow map (over {}, or point lights inside the object's bounds)",
          f.unshadowed_lights, gl::Renderer::kMaxShadowMaps));
    }
  }
#endif
  if (backend.name == "cpu") {
    auto t0 = std::chrono::steady_clock::now();
    f = render_cpu(d, iblcli::progress_bar());
    iblcli::progress_done();
    j["cpu_ms"] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  j["backend"] = backend.name;
  return f;
}

// The lab photograph and what each rendered frame is compared with.
struct Truth {
  std::optional<iblcli::LabPhotograph> photo;
  io::ToneMapDesc td;  // pictures: auto exposure, or with --truth one exposure for all (the truth's)
  std::vector<std::pair<std::string, Image>> sheet, errors;
};

// Photographs the frame in the --truth scene, once for every lighting.
void photograph(const Opts& o, const FrameDesc& d, Truth* t) {
  t->td.exposure_stops = o.exposure;
  if (o.truth.empty()) return;
  auto t0 = std::chrono::steady_clock::now();
  t->photo = iblcli::photograph_frame(o.truth, d, o.truth_samples, o.truth_bounces, iblcli::progress_bar());
  iblcli::progress_done();
  t->photo->ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  t->td.auto_exposure = false;
  t->td.exposure_stops = o.exposure + std::log2(t->photo->median > 0 ? 0.25 / t->photo->median : 1.0);
  t->sheet.push_back({"lab photograph (truth)", io::tonemap(t->photo->radiance, t->td)});
}

// The frame against the photograph: into j, the contact sheet and the error maps.
void compare_with_truth(const Opts& o, const std::string& light, const RenderResult& f, Truth* t, nlohmann::json& j) {
  iblcli::TruthComparison c = iblcli::compare(*t->photo, f);
  const std::string name = fs::path(light).filename().string();
  t->sheet.push_back({fmt::format("{}: L1 {:.3f}", name, c.rel_l1_first), io::tonemap(f.color, t->td)});
  t->errors.push_back({fmt::format("relative error of {}", name), io::false_colour(c.error, 0.5)});
  j["truth"] = {{"scene", o.truth},
                {"rel_l1_object", c.rel_l1_first},
                {"rel_l1_object_and_floor", c.rel_l1},
                {"median_rel_object", c.median_rel},
                {"mean_luminance_render", c.mean_render},
                {"mean_luminance_truth", c.mean_truth},
                {"object_pixels", c.first_pixels},
                {"photograph_ms", t->photo->ms}};
}

// STEM_truth.exr/.png, STEM_error.png (one --light) and STEM_compare.png: row 1 the truth and each
// render, row 2 a key, then each render's error map. Returns the contact sheet's path.
std::string write_truth_pictures(const Opts& o, const fs::path& stem, int w, int h, Truth* t) {
  io::write_image(stem.string() + "_truth.exr", t->photo->radiance);
  io::write_image(stem.string() + "_truth.png", t->sheet[0].second);
  const int cols = 1 + static_cast<int>(o.lights.size());
  if (o.lights.size() == 1) io::write_image(stem.string() + "_error.png", t->errors[0].second);
  Image key(64, 8, 1);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 64; ++x) key.at(x, y, 0) = static_cast<float>(0.5 * x / 63.0);
  t->sheet.push_back({"relative error 0 .. 0.5 (grey: not compared)", io::false_colour(key, 0.5)});
  for (auto& e : t->errors) t->sheet.push_back(std::move(e));
  std::string pictures = stem.string() + "_compare.png";
  io::write_image(pictures, io::contact_sheet(t->sheet, cols, std::min(480, w), std::min(480, w) * h / w));
  return pictures;
}

void print_renders(const Opts& o, const nlohmann::json& renders, const nlohmann::json& result,
                   const std::string& backend) {
  for (const auto& j : renders) {
    fmt::print("rendered {} ({}, {} backend) lit by {}\n", j["output"].get<std::string>(), o.size, backend,
               j["lighting"].get<std::string>());
    if (j.contains("gpu_ms_median"))
      fmt::print("GPU time {:.3f} ms/frame median of {} ({:.0f} fps) on {}\n", j["gpu_ms_median"].get<double>(),
                 o.frames, j["fps_gpu"].get<double>(), j["gl_renderer"].get<std::string>());
    else if (j.contains("gl_renderer"))
      fmt::print(
          "{:.1f} ms/frame wall clock over {} frames on {} (a software renderer: its GPU timer queries mean nothing)\n",
          j["wall_ms_per_frame"].get<double>(), o.frames, j["gl_renderer"].get<std::string>());
    if (j.contains("cpu_ms")) fmt::print("CPU time {:.0f} ms\n", j["cpu_ms"].get<double>());
    if (j.contains("truth"))
      fmt::print(
          "against the lab photograph in {}: object relative L1 {:.3f} (median pixel {:.3f}; mean luminance {:.4g} vs "
          "{:.4g}), object and floor {:.3f}\n",
          o.truth, j["truth"]["rel_l1_object"].get<double>(), j["truth"]["median_rel_object"].get<double>(),
          j["truth"]["mean_luminance_render"].get<double>(), j["truth"]["mean_luminance_truth"].get<double>(),
          j["truth"]["rel_l1_object_and_floor"].get<double>());
  }
  if (result.contains("truth_pictures")) fmt::print("pictures: {}\n", result["truth_pictures"].get<std::string>());
}

// The name of each --light in OUT_<name>.ext: its file's stem, and where two share a stem (a/probe.exr
// and b/probe.exr, or one file given twice) the stem and the light's place in the list, from 1
// ("probe_1", "probe_2"), so that no two frames write the same file.
std::vector<std::string> light_output_names(const std::vector<std::string>& lights) {
  std::map<std::string, int> count;
  for (const auto& l : lights) ++count[fs::path(l).stem().string()];
  std::vector<std::string> names;
  for (size_t i = 0; i < lights.size(); ++i) {
    std::string stem = fs::path(lights[i]).stem().string();
    names.push_back(count[stem] > 1 ? fmt::format("{}_{}", stem, i + 1) : stem);
  }
  return names;
}

// The frame lit by each --light in turn, written to --out (OUT_<light name>.ext for several).
void run(const Opts& o, const io::EnvReadDesc& rd) {
  Scene s;
  make_scene(o, &s);
  FrameDesc& d = s.d;
  render::LightingReadDesc lopt = o.lighting;
  lopt.glossy_exponent = o.gloss > 0 && o.glossy == "map" ? d.objects[0].material.environment_exponent() : 0.0;
  lopt.read = rd;
  lopt.luminaire.position = iblcli::parse_vec3(o.luminaire, "--luminaire");
  lopt.luminaire.forward = normalize(iblcli::parse_vec3(o.luminaire_dir, "--luminaire-dir"));
  const Backend backend = open_backend(o.backend);
  Truth truth;
  photograph(o, d, &truth);
  const fs::path stem = fs::path(o.out).replace_extension();
  const std::string ext = fs::path(o.out).extension().string();
  nlohmann::json renders = nlohmann::json::array();
  const std::vector<std::string> names = light_output_names(o.lights);
  for (size_t li = 0; li < o.lights.size(); ++li) {
    const std::string& light = o.lights[li];
    d.lighting = Lighting{};
    std::string kind;
    render::read_lighting(light, lopt, &d.lighting, &kind);
    if (std::string w = iblcli::grid_bounds_warning(d.lighting, s.object); !w.empty()) iblcli::info("warning: " + w);
    nlohmann::json j = {{"scene", o.object.scene}, {"light", light}, {"lighting", kind}, {"size", o.size}};
    RenderResult f = render_frame(o, d, backend, j);
    // One --light writes --out; several write OUT_<light name>.ext each.
    std::string out = o.lights.size() == 1 ? o.out : stem.string() + "_" + names[li] + ext;
    if (ext == ".png" || ext == ".jpg")
      io::write_image(out, io::tonemap(f.color, truth.td));
    else
      io::write_image(out, f.color);
    j["output"] = out;
    if (truth.photo) compare_with_truth(o, light, f, &truth, j);
    renders.push_back(j);
  }
  nlohmann::json result = renders.size() == 1 ? renders[0] : nlohmann::json{{"renders", renders}};
  if (truth.photo) result["truth_pictures"] = write_truth_pictures(o, stem, d.camera.width, d.camera.height, &truth);
  iblcli::emit(result, [&] { print_renders(o, renders, result, backend.name); });
}

void setup(CLI::App& app) {
  auto* o = iblcli::app_owned<Opts>();
  add_options(app, o);
  auto& rd = iblcli::add_probe_read_options(app);
  app.callback([o, &rd] { run(*o, rd); });
}

// Demo step: the blob lit by the demo probe's 5-band SH, on the CPU and (where GL exists) on GL,
// with the per-pixel difference between the two.
void demo_step(iblcli::DemoContext& ctx) {
  ibl::make_output_folders(fs::path(fs::path(ctx.out_dir) / "render").string());
  FrameDesc d;
  d.camera.width = 480;
  d.camera.height = 360;
  d.camera.eye = {0, 0.5, 1.6};
  geometry::TriMesh object = geometry::make_blob(60000, 0.8), floor = geometry::make_floor(6, -0.42);
  d.objects = {{&object, Material{{0.75, 0.75, 0.75}, {0.15, 0.15, 0.15}, 20}},
               {&floor, Material{{0.5, 0.5, 0.5}, {0, 0, 0}, 1}}};
  auto probe = io::read_envmap(ctx.probe);
  d.lighting.environment = sh::project(probe, 5);
  d.lighting.glossy_maps.push_back(prefilter_phong(probe, 20));  // the highlight without the SH band limit
  auto t0 = std::chrono::steady_clock::now();
  RenderResult cpu = render_cpu(d);
  double cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  double scale = io::auto_exposure_scale(cpu.color);
  io::ToneMapDesc td;
  td.auto_exposure = false;
  td.exposure_stops = std::log2(scale);
  std::string base = (fs::path(ctx.out_dir) / "render").string();
  io::write_image(base + "/blob_cpu.png", io::tonemap(cpu.color, td));
  io::write_image(base + "/blob_cpu.exr", cpu.color);
  ctx.pictures.push_back({"render: CPU reference", base + "/blob_cpu.png"});
  nlohmann::json j = {{"cpu_ms", cpu_ms}, {"size", "480x360"}, {"triangles", object.triangle_count()}};
#ifdef IBLKIT_HAVE_GL
  try {
    gl::Context glctx;
    gl::Renderer r;
    gl::GpuTiming t;
    RenderResult g = r.render(d, 5, &t);
    io::write_image(base + "/blob_gl.png", io::tonemap(g.color, td));
    ctx.pictures.push_back({"render: OpenGL (" + glctx.renderer().substr(0, 16) + ")", base + "/blob_gl.png"});
    std::vector<double> rel;
    for (int y = 0; y < g.color.height(); ++y)
      for (int x = 0; x < g.color.width(); ++x)
        if (cpu.coverage.at(x, y, 0) > 0 && g.coverage.at(x, y, 0) > 0) {
          double a = luminance(cpu.color.rgb(x, y)), b = luminance(g.color.rgb(x, y));
          rel.push_back(std::abs(a - b) / std::max(a, 1e-3));
        }
    std::sort(rel.begin(), rel.end());
    j["gl_renderer"] = glctx.renderer();
    j["gl_vs_cpu_median_rel_error"] = rel.empty() ? 0.0 : rel[rel.size() / 2];
    j["gl_vs_cpu_p99_rel_error"] = rel.empty() ? 0.0 : rel[rel.size() * 99 / 100];
  } catch (const Error& e) {
    j["gl"] = std::string("not available: ") + e.what();
  }
#endif
  // Löw et al.'s Fig. 9 in miniature: when the ILF step built low-scene2's grids, the blob on a
  // table there, photographed by the lab and lit by each grid (docs/render.md).
  std::vector<std::string> grids;
  for (int n : {8, 16, 32}) {
    fs::path g = fs::path(ctx.out_dir) / "ilf" / fmt::format("grid{}.shgrid", n);
    if (fs::exists(g)) grids.push_back(g.string());
  }
  if (!grids.empty()) {
    FrameDesc f9;
    f9.camera.width = 320;
    f9.camera.height = 240;
    f9.camera.eye = {0, 1.45, 1.5};
    f9.camera.target = {0, 0.8, 0};
    geometry::TriMesh small =
        render::make_object({.scene = "blob", .size = 0.35, .triangles = 30000, .at = {0, 0.85, 0}});
    Vec3 lo, hi;
    small.bounds(&lo, &hi);
    geometry::TriMesh table = geometry::make_floor(0.8, lo.y - 1e-3);
    f9.objects = {{&small, Material{{0.75, 0.75, 0.75}, {0, 0, 0}, 1}},
                  {&table, Material{{0.5, 0.5, 0.5}, {0, 0, 0}, 1}}};
    iblcli::LabPhotograph photo = iblcli::photograph_frame("low-scene2", f9, 3, 1);  // one bounce more than the capture
    io::ToneMapDesc t9;
    t9.auto_exposure = false;
    t9.exposure_stops = std::log2(photo.median > 0 ? 0.25 / photo.median : 1.0);
    std::vector<std::pair<std::string, Image>> sheet = {{"lab photograph", io::tonemap(photo.radiance, t9)}};
    nlohmann::json errs = nlohmann::json::object();
    for (const std::string& g : grids) {
      render::read_lighting(g, {}, &f9.lighting);
      RenderResult r = render_cpu(f9);
      iblcli::TruthComparison c = iblcli::compare(photo, r);
      std::string name = fs::path(g).stem().string();
      errs[name] = c.rel_l1_first;
      sheet.push_back({fmt::format("{}: L1 {:.3f}", name, c.rel_l1_first), io::tonemap(r.color, t9)});
    }
    std::string pic = base + "/fig9.png";
    io::write_image(pic, io::contact_sheet(sheet, static_cast<int>(sheet.size()), 320, 240));
    ctx.pictures.push_back({"render: Fig. 9 in low-scene2 (lab photo, 8^3, 16^3, 32^3 grids)", pic});
    j["fig9_object_rel_l1"] = errs;
  }
  ctx.summary["render"] = j;
}

iblcli::DemoStep demo("render", 80, demo_step);

iblcli::Command reg("render", setup);

}  // namespace
#endif
