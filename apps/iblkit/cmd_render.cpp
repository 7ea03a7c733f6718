// iblkit render: a mesh scene lit by an iblkit representation, on the CPU (reference) or with
// OpenGL (real time, headless EGL). Prints per-frame GPU time and fps for the GL backend.
#ifdef IBLKIT_HAVE_GEOMETRY
#include <chrono>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "cli.h"
#include "render_truth.h"
#include "iblkit/io/draw.h"
#include "iblkit/core/error.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/render/cpu_renderer.h"
#include "iblkit/render/mesh.h"
#include "iblkit/render/prefilter.h"
#include "iblkit/sh/project.h"
#ifdef IBLKIT_HAVE_GL
#include "iblkit/render/gl/context.h"
#include "iblkit/render/gl/renderer.h"
#endif

namespace {

namespace fs = std::filesystem;
using namespace ibl;
using namespace ibl::render;

// Reads --light: an SH grid (.shgrid), an iblkit.lights/1 or iblkit.sh/1 JSON file, or a probe image
// (projected to SH).
void load_lighting(const std::string& path, int bands, int shadows, const io::EnvReadDesc& rd, double glossy_exponent, Lighting* L,
                   std::string* kind) {
  std::string ext = fs::path(path).extension().string();
  if (ext == ".shgrid") {
    ilf::SHGrid g = ilf::read_shgrid(path);
    SHGridData d;
    d.bands = g.bands();
    d.nx = g.grid().nx;
    d.ny = g.grid().ny;
    d.nz = g.grid().nz;
    d.min = g.grid().volume.min;
    d.max = g.grid().volume.max;
    d.data = g.data();
    L->grid = std::move(d);
    *kind = fmt::format("SH grid {}x{}x{}, {} bands", g.grid().nx, g.grid().ny, g.grid().nz, g.bands());
    return;
  }
  if (ext == ".json") {
    std::ifstream in(path);
    if (!in) fail(ErrorKind::Io, "{}: cannot open", path);
    nlohmann::json j;
    try {
      in >> j;
    } catch (const std::exception& e) {
      fail(ErrorKind::Format, "{}: not valid JSON ({})", path, e.what());
    }
    std::string format = j.value("format", "");
    if (format == "iblkit.lights/1") {
      lights::LightSet set = lights::from_json(j, path);
      // Lights come in shadow-map priority order (docs/formats.md): the first `shadows` get maps,
      // unless a light says "shadow" itself. A light with a position (fusion's localised lights)
      // is a point light of intensity irradiance·|position − origin|².
      int points = 0;
      for (size_t i = 0; i < set.lights.size(); ++i) {
        const lights::Light& l = set.lights[i];
        bool shadow = static_cast<int>(i) < shadows;
        if (j["lights"][i].contains("shadow")) shadow = j["lights"][i]["shadow"].get<bool>();
        if (l.position && set.origin) {
          Vec3 q = *l.position - *set.origin;
          L->point_lights.push_back({*l.position, l.irradiance * dot(q, q), shadow});
          ++points;
        } else {
          L->lights.push_back({normalize(l.direction), l.irradiance, shadow});
        }
      }
      *kind = points ? fmt::format("{} point lights and {} directional lights", points, set.lights.size() - points)
                     : fmt::format("{} directional lights", set.lights.size());
      return;
    }
    if (format == "iblkit.sh/1") {
      sh::Coeffs c;
      c.bands = j.at("bands").get<int>();
      for (const auto& v : j.at("coefficients")) c.c.push_back({v[0].get<double>(), v[1].get<double>(), v[2].get<double>()});
      if (static_cast<int>(c.c.size()) != c.bands * c.bands)
        fail(ErrorKind::Format, "{}: {} bands need {} coefficients, found {}", path, c.bands, c.bands * c.bands, c.c.size());
      L->environment = c;
      *kind = fmt::format("SH environment, {} bands", c.bands);
      return;
    }
    fail(ErrorKind::Format, "{}: \"format\" is '{}'; expected iblkit.lights/1 or iblkit.sh/1", path, format);
  }
  auto env = io::read_envmap(path, rd);
  L->environment = sh::project(env, bands);
  *kind = fmt::format("probe projected to {} SH bands", bands);
  if (glossy_exponent > 0) {
    L->glossy_maps.push_back(prefilter_phong(env, glossy_exponent));
    const Image& g = L->glossy_maps.back().latlong;
    *kind += fmt::format(", glossy from a prefiltered {}x{} Phong map (s = {:g})", g.width(), g.height(), glossy_exponent);
  }
}

void setup(CLI::App& app) {
  struct Opts {
    std::string scene = "blob", light, out = "frame.png", backend = "auto", size = "1024x768", eye = "0,0.5,1.6",
                target = "0,0,0", at = "0,0,0";
    double object_size = 0.8;
    int frames = 1, bands = 5, triangles = 100000, shadows = 4;
    double gloss = 0, exponent = 20;
    std::string glossy = "map";
    std::string truth;
    int truth_samples = 4, truth_bounces = 1;
    double floor_size = 6;
  };
  auto* o = new Opts();
  app.add_option("scene", o->scene,
                 "the object: blob (a bunny-sized procedural object), sphere, or a mesh file (OBJ, PLY, glTF), "
                 "scaled to --object-size and placed at --at, on a floor")
      ->capture_default_str();
  app.add_option("-l,--light", o->light, "lighting: a probe image, an SH grid (.shgrid), iblkit.sh/1 or iblkit.lights/1 JSON")->required();
  app.add_option("--at", o->at, "place the object's centre here, x,y,z (e.g. inside an SH grid's volume)")->capture_default_str();
  app.add_option("--object-size", o->object_size, "object size in metres")->check(CLI::Range(0.001, 1000.0))->capture_default_str();
  app.add_option("-o,--out", o->out, "output .png (tone mapped) or .exr (linear)")->capture_default_str();
  app.add_option("--backend", o->backend, "cpu, gl or auto (gl when available)")->check(CLI::IsMember({"cpu", "gl", "auto"}))->capture_default_str();
  app.add_option("--size", o->size, "frame size WxH")->capture_default_str();
  app.add_option("--frames", o->frames, "GL: render this many frames and report the median GPU time")->check(CLI::Range(1, 10000));
  app.add_option("--shadows", o->shadows, "lights (in the file's priority order) that cast shadows")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  app.add_option("--bands", o->bands, "SH bands when projecting a probe")->check(CLI::Range(1, 9))->capture_default_str();
  app.add_option("--triangles", o->triangles, "triangles of the blob")->check(CLI::Range(100, 5000000))->capture_default_str();
  app.add_option("--gloss", o->gloss, "weight of the glossy Phong lobe (0..1)")->check(CLI::Range(0.0, 1.0));
  app.add_option("--exponent", o->exponent, "Phong exponent of the glossy lobe")->check(CLI::Range(1.0, 10000.0));
  app.add_option("--glossy", o->glossy,
                 "probe lighting with --gloss > 0: the glossy lobe from a prefiltered Phong map of the probe (map) "
                 "or from its --bands SH (sh, band-limited)")
      ->check(CLI::IsMember({"map", "sh"}))
      ->capture_default_str();
  app.add_option("--floor-size", o->floor_size, "side of the square floor under the object, metres (a table top when small)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  app.add_option("--truth", o->truth,
                 "a lab scene (iblkit.scene/1, e.g. examples/low-scene2.json): also photograph the object and floor in it "
                 "with its real emitters (lab path tracing) and report the frame's error against that photograph");
  app.add_option("--truth-samples", o->truth_samples, "--truth: n×n rays per pixel")->check(CLI::Range(1, 64))->capture_default_str();
  app.add_option("--truth-bounces", o->truth_bounces, "--truth: indirect bounces (the scene's stray light reaches the object through them)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  app.add_option("--eye", o->eye, "camera position x,y,z")->capture_default_str();
  app.add_option("--target", o->target, "camera target x,y,z")->capture_default_str();
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer("Examples:\n  iblkit render blob --light probe.exr --out blob.png --backend cpu --size 400x300\n"
             "  iblkit render blob --light lights.json --backend gl --frames 100 --out blob.exr\n"
             "  iblkit render blob --light grid.shgrid --at 0.5,0.3,0.5 --object-size 0.3 --eye 0.5,0.6,1.6 --target 0.5,0.3,0.5");
  app.callback([o, &rd] {
    int w = 0, h = 0;
    if (std::sscanf(o->size.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > 16384 || h > 16384)
      fail(ErrorKind::Value, "--size '{}': expected WxH, e.g. 1024x768", o->size);
    FrameDesc d;
    d.camera.width = w;
    d.camera.height = h;
    d.camera.eye = iblcli::parse_vec3(o->eye, "--eye");
    d.camera.target = iblcli::parse_vec3(o->target, "--target");
    Vec3 at = iblcli::parse_vec3(o->at, "--at");
    Mesh object;
    if (o->scene == "blob") {
      object = make_blob(o->triangles, o->object_size);
    } else if (o->scene == "sphere") {
      object = make_sphere(o->object_size / 2, 128, 256);
    } else {
      object = from_trimesh(geometry::read_mesh(o->scene));
      // Centre the file's mesh on the origin and scale its largest extent to --object-size.
      Vec3 lo, hi;
      object.bounds(&lo, &hi);
      double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
      if (!(extent > 0)) fail(ErrorKind::Value, "{}: the mesh has no extent", o->scene);
      object.transform(1.0, (lo + hi) * -0.5);
      object.transform(o->object_size / extent, {0, 0, 0});
    }
    object.transform(1.0, at);
    Vec3 lo, hi;
    object.bounds(&lo, &hi);
    Mesh floor = make_floor(o->floor_size, lo.y - 1e-3);  // just under the object's lowest point
    Material mat{{0.75, 0.75, 0.75}, Vec3{1, 1, 1} * o->gloss, o->exponent};
    d.objects = {{&object, mat}, {&floor, Material{{0.5, 0.5, 0.5}, {0, 0, 0}, 1}}};
    std::string kind;
    load_lighting(o->light, o->bands, o->shadows, rd, o->gloss > 0 && o->glossy == "map" ? o->exponent : 0.0, &d.lighting, &kind);
    std::string backend = o->backend;
    nlohmann::json j = {{"scene", o->scene}, {"light", o->light}, {"lighting", kind}, {"size", o->size}};
    RenderResult f;
#ifdef IBLKIT_HAVE_GL
    std::unique_ptr<gl::Context> ctx;
    if (backend != "cpu") {
      try {
        ctx = std::make_unique<gl::Context>();
        backend = "gl";
      } catch (const Error& e) {
        if (backend == "gl") throw;
        iblcli::info(fmt::format("no OpenGL here ({}); rendering on the CPU", e.what()));
        backend = "cpu";
      }
    }
    if (backend == "gl") {
      gl::Renderer r;
      gl::GpuTiming t;
      f = r.render(d, o->frames, &t);
      std::vector<double> ms = t.frame_ms;
      std::sort(ms.begin(), ms.end());
      double med = ms[ms.size() / 2];
      j["gl_renderer"] = ctx->renderer();
      j["wall_ms_per_frame"] = t.wall_ms_per_frame;
      if (ctx->renderer().find("llvmpipe") == std::string::npos) {
        j["gpu_ms_median"] = med;
        j["fps_gpu"] = med > 0 ? 1000.0 / med : 0.0;
      }
    }
#else
    if (backend == "gl") fail(ErrorKind::Unsupported, "this build has no OpenGL renderer (libepoxy missing)");
    backend = "cpu";
#endif
    if (backend == "cpu") {
      auto t0 = std::chrono::steady_clock::now();
      f = render_cpu(d, iblcli::progress_bar());
      iblcli::progress_done();
      j["cpu_ms"] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
    j["backend"] = backend;
    std::string ext = fs::path(o->out).extension().string();
    if (ext == ".png" || ext == ".jpg") io::write_image(o->out, io::tonemap(f.color));
    else io::write_image(o->out, f.color);
    j["output"] = o->out;
    if (!o->truth.empty()) {
      auto t0 = std::chrono::steady_clock::now();
      iblcli::TruthComparison c = iblcli::compare_with_lab(o->truth, d, f, o->truth_samples, o->truth_bounces, iblcli::progress_bar());
      iblcli::progress_done();
      fs::path stem = fs::path(o->out).replace_extension();
      io::ToneMapDesc td;  // one exposure for both pictures: the truth's
      td.auto_exposure = false;
      td.exposure_stops = std::log2(io::auto_exposure_scale(c.truth));
      Image truth_png = io::tonemap(c.truth, td), render_png = io::tonemap(f.color, td);
      Image error_png = io::false_colour(c.error, 0.5);
      io::write_image(stem.string() + "_truth.exr", c.truth);
      io::write_image(stem.string() + "_truth.png", truth_png);
      io::write_image(stem.string() + "_error.png", error_png);
      io::write_image(stem.string() + "_compare.png",
                      io::contact_sheet({{"lab photograph (truth)", truth_png},
                                         {fmt::format("render ({}): L1 {:.3f}", backend, c.rel_l1_first), render_png},
                                         {"relative error, 0 (black) .. 0.5 (red)", error_png}},
                                        3, std::min(480, w), std::min(480, w) * h / w));
      j["truth"] = {{"scene", o->truth},
                    {"rel_l1_object", c.rel_l1_first},
                    {"rel_l1_object_and_floor", c.rel_l1},
                    {"median_rel_object", c.median_rel},
                    {"mean_luminance_render", c.mean_render},
                    {"mean_luminance_truth", c.mean_truth},
                    {"object_pixels", c.first_pixels},
                    {"ms", std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count()},
                    {"pictures", stem.string() + "_compare.png"}};
    }
    iblcli::emit(j, [&] {
      fmt::print("rendered {} ({}, {} backend) lit by {}\n", o->out, o->size, backend, kind);
      if (j.contains("gpu_ms_median"))
        fmt::print("GPU time {:.3f} ms/frame median of {} ({:.0f} fps) on {}\n", j["gpu_ms_median"].get<double>(), o->frames,
                   j["fps_gpu"].get<double>(), j["gl_renderer"].get<std::string>());
      else if (j.contains("gl_renderer"))
        fmt::print("{:.1f} ms/frame wall clock over {} frames on {} (a software renderer: its GPU timer queries mean nothing)\n",
                   j["wall_ms_per_frame"].get<double>(), o->frames, j["gl_renderer"].get<std::string>());
      if (j.contains("cpu_ms")) fmt::print("CPU time {:.0f} ms\n", j["cpu_ms"].get<double>());
      if (j.contains("truth"))
        fmt::print("against the lab photograph in {}: object relative L1 {:.3f} (median pixel {:.3f}; mean luminance {:.4g} vs {:.4g}), "
                   "object and floor {:.3f}; pictures {}\n",
                   o->truth, j["truth"]["rel_l1_object"].get<double>(), j["truth"]["median_rel_object"].get<double>(),
                   j["truth"]["mean_luminance_render"].get<double>(), j["truth"]["mean_luminance_truth"].get<double>(),
                   j["truth"]["rel_l1_object_and_floor"].get<double>(), j["truth"]["pictures"].get<std::string>());
    });
  });
}

// Demo step: the blob lit by the demo probe's 5-band SH, on the CPU and (where GL exists) on GL,
// with the per-pixel difference between the two.
void demo_step(iblcli::DemoContext& ctx) {
  fs::create_directories(fs::path(ctx.out_dir) / "render");
  FrameDesc d;
  d.camera.width = 480;
  d.camera.height = 360;
  d.camera.eye = {0, 0.5, 1.6};
  Mesh object = make_blob(60000, 0.8), floor = make_floor(6, -0.42);
  d.objects = {{&object, Material{{0.75, 0.75, 0.75}, {0.15, 0.15, 0.15}, 20}}, {&floor, Material{{0.5, 0.5, 0.5}, {0, 0, 0}, 1}}};
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
  ctx.summary["render"] = j;
}

iblcli::DemoStep demo("render", 80, demo_step);

iblcli::Command reg("render", "Render a scene lit by a probe, SH or lights (CPU reference or OpenGL)", setup, 80);

}  // namespace
#endif
