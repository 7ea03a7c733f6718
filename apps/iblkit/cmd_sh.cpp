// iblkit sh PROBE: spherical-harmonic coefficients of a probe (iblkit.sh/1 JSON, or three.js,
// Filament or glTF layouts), optional windowing, and the SH irradiance as an image. Also the demo's
// SH step.
#include <chrono>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/engine/gltf_ibl.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sh/convolve.h"
#include "iblkit/sh/export.h"
#include "iblkit/sh/project.h"

namespace {

namespace fs = std::filesystem;
using namespace ibl;

// Irradiance E(n) of radiance coefficients as a 2H×H lat-long image.
Image irradiance_image(const sh::Coeffs& radiance, int height) {
  sphere::Mapping m(sphere::MappingKind::LatLong, 2 * height, height);
  return sh::reconstruct(sh::irradiance(radiance), m);
}

nlohmann::json rgb(Vec3 v) { return {v.x, v.y, v.z}; }

void setup(CLI::App& app) {
  struct Opts {
    std::string probe, window = "none", format = "iblkit", out, irradiance_map, specular_images;
    int bands = 3, irradiance_size = 64;
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("probe", o->probe, "HDR probe image (or a folder of six cube faces)")->required();
  app.add_option("-b,--bands", o->bands, fmt::format("number of bands L+1 (1..{}; 3 = 9 coefficients)", sh::kMaxBands))
      ->capture_default_str();
  app.add_option("-w,--window", o->window, "ringing window: none, hanning, lanczos, deringing")->capture_default_str();
  app.add_option("-f,--format", o->format, "output layout: iblkit (iblkit.sh/1 JSON), threejs, filament (sh.txt), gltf")
      ->capture_default_str();
  app.add_option("-o,--out", o->out, "write the coefficients here (default: print them on stdout)");
  app.add_option("--irradiance-map", o->irradiance_map,
                 "also render the SH irradiance E(n) as a lat-long image (.exr …)");
  iblcli::outputs(app, {"--irradiance-map"});  // besides --out (cli.h)
  app.add_option("--irradiance-size", o->irradiance_size, "height of the irradiance map (width is twice)")
      ->capture_default_str();
  app.add_option(
      "--specular-images", o->specular_images,
      "--format gltf: the prefiltered cube's HDR faces as a pattern with {level} and {face} (px nx py ny pz nz), e.g. "
      "spec/m{level}_{face}.exr from `iblkit specular --faces spec`; levels 0, 1, … while all six exist. Each face is "
      "written beside --out as the extension's RGBD PNG (OUT-STEM_m<level>_<face>.png, flipped as it specifies)");
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer(
      "Examples:\n"
      "  iblkit sh /usr/share/blender/datafiles/studiolights/world/forest.exr --bands 5 --out forest_sh.json\n"
      "  iblkit sh probe.exr --format filament --window deringing --out sh.txt --irradiance-map irr.exr\n"
      "  iblkit specular /usr/share/blender/datafiles/studiolights/world/forest.exr --size 64 --faces forest_spec\n"
      "  iblkit sh /usr/share/blender/datafiles/studiolights/world/forest.exr --format gltf --specular-images "
      "'forest_spec/m{level}_{face}.exr' --out forest_ibl.gltf");
  app.callback([o, &rd] {
    if (o->bands < 1 || o->bands > sh::kMaxBands)
      fail(ErrorKind::Value, "--bands must be in 1..{} (got {})", sh::kMaxBands, o->bands);
    if (o->irradiance_size < 1 || o->irradiance_size > 8192)
      fail(ErrorKind::Value, "--irradiance-size must be in 1..8192 (got {})", o->irradiance_size);
    sh::ExportFormat format = sh::parse_export_format(o->format);
    sh::WindowDesc wd;
    wd.kind = sh::parse_window(o->window);
    if (format != sh::ExportFormat::Iblkit && o->bands != 3)
      fail(ErrorKind::Value, "--format {} stores 3 bands (9 coefficients); use --bands 3 (got {})", o->format,
           o->bands);

    io::ReadReport rep;
    sphere::EnvMap env = io::read_envmap(o->probe, rd, &rep);
    if (rep.sanitized) iblcli::info(fmt::format("sanitized {} NaN/Inf/negative values", rep.sanitized));
    auto t0 = std::chrono::steady_clock::now();
    sh::Coeffs c = sh::project(env, o->bands, iblcli::progress_bar());
    double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    iblcli::progress_done();
    if (luminance(c.c[0]) <= 0) fail(ErrorKind::Value, "{}: the probe is black (no light to project)", o->probe);
    sh::WindowReport wr;
    c = sh::apply_window(c, wd, &wr);

    std::string text = sh::export_text(c, format, sh::filament_frame(env.mapping.kind()));
    std::vector<std::string> specular_files;
    if (!o->specular_images.empty()) {
      if (format != sh::ExportFormat::Gltf) fail(ErrorKind::Value, "--specular-images goes with --format gltf");
      if (o->out.empty())
        fail(ErrorKind::Value, "--specular-images needs --out (the PNGs are written beside the glTF)");
      specular_files = engine::write_gltf_ibl(o->out, c, engine::read_cube_faces(o->specular_images));
      specular_files.pop_back();  // the document itself
    } else if (!o->out.empty()) {
      write_file_atomically(o->out, text);
    }
    if (!o->irradiance_map.empty()) io::write_image(o->irradiance_map, irradiance_image(c, o->irradiance_size));

    nlohmann::json j = {{"probe", o->probe},
                        {"mapping", sphere::mapping_name(env.mapping.kind())},
                        {"bands", c.bands},
                        {"window", sh::window_name(wd.kind)},
                        {"window_weights", wr.weights},
                        {"format", sh::export_format_name(format)},
                        {"projection_ms", ms},
                        {"min_irradiance_ratio_before", wr.min_irradiance_before},
                        {"min_irradiance_ratio_after", wr.min_irradiance_after},
                        {"irradiance_up", rgb(sh::irradiance_at(c, {0, 1, 0}))},
                        {"coefficients", sh::to_json(c)["coefficients"]}};
    if (wd.kind == sh::Window::Deringing) j["deringing_lambda"] = wr.lambda;
    if (!o->out.empty()) j["out"] = o->out;
    if (!o->irradiance_map.empty()) j["irradiance_map"] = o->irradiance_map;
    if (!specular_files.empty()) j["specular_images"] = specular_files;
    if (format != sh::ExportFormat::Iblkit && o->out.empty()) j["export"] = text;
    iblcli::emit(j, [&] {
      if (o->out.empty()) {
        fmt::print("{}", text);
        return;
      }
      fmt::print("{}: {} bands ({} coefficients) from {} {}x{} in {:.1f} ms, window {}\n", o->out, c.bands,
                 sh::coeff_count(c.bands), sphere::mapping_name(env.mapping.kind()), env.image.width(),
                 env.image.height(), ms, sh::window_name(wd.kind));
      Vec3 e = sh::irradiance_at(c, {0, 1, 0});
      fmt::print("E(+Y) = {:.6g} {:.6g} {:.6g}; min E / mean E = {:.4f} before window, {:.4f} after\n", e.x, e.y, e.z,
                 wr.min_irradiance_before, wr.min_irradiance_after);
      if (!o->irradiance_map.empty()) fmt::print("irradiance map: {}\n", o->irradiance_map);
      if (!specular_files.empty())
        fmt::print("specular images: {} RGBD PNGs ({} levels) beside {}\n", specular_files.size(),
                   specular_files.size() / 6, o->out);
    });
  });
}

iblcli::Command reg("sh", setup);

// Demo: the probe to 3 and 5 bands, the exports, and the 3- and 5-band irradiance as pictures.
void demo_step(iblcli::DemoContext& ctx) {
  sphere::EnvMap env = io::read_envmap(ctx.probe);
  fs::path dir = fs::path(ctx.out_dir) / "sh";
  ibl::make_output_folders(fs::path(dir).string());
  auto t0 = std::chrono::steady_clock::now();
  sh::Coeffs c5 = sh::project(env, 5);
  double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  sh::Coeffs c3 = sh::project(env, 3);
  sh::write_coeffs((dir / "sh.json").string(), c5);
  sh::write_coeffs((dir / "sh3.json").string(), c3);
  write_file_atomically((dir / "sh_threejs.json").string(), sh::export_text(c3, sh::ExportFormat::ThreeJs));
  write_file_atomically((dir / "sh.txt").string(), sh::export_text(c3, sh::ExportFormat::Filament));
  write_file_atomically((dir / "sh_gltf.json").string(), sh::export_text(c3, sh::ExportFormat::Gltf));

  // Pictures share the probe's exposure; irradiance is shown as the radiance of a white Lambertian
  // surface, E/π.
  io::ToneMapDesc td;
  td.auto_exposure = false;
  td.exposure_stops = std::log2(io::auto_exposure_scale(env.image));
  auto picture = [&](const std::string& name, const std::string& caption, Image img, bool over_pi) {
    // SH ringing can go below zero; light cannot, and the tone mapper expects ≥ 0.
    for (size_t i = 0; i < img.size(); ++i)
      img.data()[i] = std::max(0.0f, over_pi ? static_cast<float>(img.data()[i] / kPi) : img.data()[i]);
    io::write_image((dir / (name + ".exr")).string(), img);
    std::string png = (dir / (name + ".png")).string();
    io::write_image(png, io::tonemap(img, td));
    ctx.pictures.push_back({caption, png});
  };
  sphere::Mapping ll(sphere::MappingKind::LatLong, 256, 128);
  picture("irradiance3", "SH irradiance E/pi, 3 bands", irradiance_image(c3, 128), true);
  picture("irradiance5", "SH irradiance E/pi, 5 bands", irradiance_image(c5, 128), true);
  // Raw 5-band radiance of a probe with a sun rings far below zero; a Hanning window gives a
  // picture a person can read, exposed on its own (the sun's energy spreads over the whole sky).
  sh::WindowDesc hann;
  hann.kind = sh::Window::Hanning;
  {
    Image r = sh::reconstruct(sh::apply_window(c5, hann), ll);
    for (size_t i = 0; i < r.size(); ++i) r.data()[i] = std::max(0.0f, r.data()[i]);
    io::write_image((dir / "radiance5.exr").string(), r);
    std::string png = (dir / "radiance5.png").string();
    io::write_image(png, io::tonemap(r));
    ctx.pictures.push_back({"SH radiance, 5 bands, Hanning window", png});
  }

  // How far 3 bands are from 5 over the sphere, relative to the peak irradiance.
  double peak = 0, worst = 0;
  for (Vec3 n : sh::fibonacci_directions(2000)) {
    double e5 = luminance(sh::irradiance_at(c5, n)), e3 = luminance(sh::irradiance_at(c3, n));
    peak = std::max(peak, e5);
    worst = std::max(worst, std::abs(e5 - e3));
  }
  sh::WindowDesc wd;
  wd.kind = sh::Window::Deringing;
  sh::WindowReport wr;
  sh::apply_window(c5, wd, &wr);
  ctx.summary["sh"] = {{"projection_ms_5_bands", ms},
                       {"c00", rgb(c5.c[0])},
                       {"irradiance_up_3_bands", rgb(sh::irradiance_at(c3, {0, 1, 0}))},
                       {"irradiance_up_5_bands", rgb(sh::irradiance_at(c5, {0, 1, 0}))},
                       {"max_irradiance_diff_3_vs_5_over_peak", peak > 0 ? worst / peak : 0.0},
                       {"min_irradiance_over_mean_5_bands", wr.min_irradiance_before},
                       {"deringing_lambda_5_bands", wr.lambda},
                       {"files", {"sh/sh.json", "sh/sh3.json", "sh/sh_threejs.json", "sh/sh.txt", "sh/sh_gltf.json"}}};
}

iblcli::DemoStep step("sh", 20, demo_step);

}  // namespace
