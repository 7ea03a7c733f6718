// iblkit lights PROBE: directional lights from a probe (median cut, variance cut, irradiance
// optimisation) as iblkit.lights/1 JSON, glTF 2.0 (KHR_lights_punctual) and an overlay picture.
// iblkit eval PROBE: irradiance error of each method against the exact ground truth at M normals, for
// a list of light counts: table, CSV, the paper's Figure 4 and an irradiance comparison picture.
// The demo step "lights" runs both on the demo probe.
#include <algorithm>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/io/image_io.h"
#include "iblkit/lights/extract.h"
#include "iblkit/lights/gltf.h"
#include "lights_pictures.h"

namespace {

namespace fs = std::filesystem;
using namespace ibl::lights;

nlohmann::json opt_json(const OptimizeReport& r) {
  return {{"iterations", r.iterations},
          {"final_iterations", r.final_iterations},
          {"coarse_iterations", r.coarse_iterations},
          {"initial_cost", r.initial_cost},
          {"final_cost", r.final_cost},
          {"last_decrease", r.last_decrease},
          {"decrement", r.decrement},
          {"dark_lights", r.dark_lights},
          {"seconds", r.seconds},
          {"converged", r.converged},
          {"termination", r.termination}};
}

// ---- iblkit lights ------------------------------------------------------------------------------

struct LightsOpts {
  std::string probe, out, gltf, overlay;
  ExtractDesc ex;  // method, count, min separation, optimiser settings: the library's defaults
  GltfDesc gltf_desc;
  int shadows = 4;
};

void run_lights(const LightsOpts& o, const ibl::io::EnvReadDesc& rd) {
  check_method(o.ex.method);
  auto env = ibl::io::read_envmap(o.probe, rd);
  ExtractDesc ed = o.ex;
  ed.progress = iblcli::progress_bar();
  auto ex = extract(env, ed);
  iblcli::progress_done();
  const auto& set = ex.set;
  if (!o.out.empty()) write_lights(o.out, set);
  if (!o.gltf.empty()) write_gltf(o.gltf, set, o.gltf_desc);
  if (!o.overlay.empty()) ibl::io::write_image(o.overlay, iblcli::light_overlay(env, set, 1024, o.shadows));
  auto total = total_irradiance(set);
  auto integral = env.integral();
  nlohmann::json j = to_json(set);
  j["probe"] = o.probe;
  j["seconds"] = ex.seconds;
  j["shadow_maps"] = std::min<int>(o.shadows, static_cast<int>(set.lights.size()));
  j["total_irradiance"] = {total.x, total.y, total.z};
  j["probe_integral"] = integral;
  if (o.ex.method == "optimize") j["optimizer"] = opt_json(ex.optimizer);
  iblcli::emit(j, [&] {
    fmt::print("{} lights from {} by {} in {:.3f} s\n", set.lights.size(), o.probe, set.method, ex.seconds);
    fmt::print("{:>4} {:>26} {:>33} {:>10} {:>10}  {}\n", "rank", "direction", "irradiance (RGB)", "Ω (sr)",
               "Y radiance", "shadow");
    for (size_t i = 0; i < set.lights.size(); ++i) {
      const auto& l = set.lights[i];
      fmt::print("{:>4} {:>8.4f} {:>8.4f} {:>8.4f} {:>10.4g} {:>10.4g} {:>10.4g} {:>10.4g} {:>10.4g}  {}\n", i + 1,
                 l.direction.x, l.direction.y, l.direction.z, l.irradiance.x, l.irradiance.y, l.irradiance.z,
                 l.solid_angle, ibl::luminance(l.radiance()), static_cast<int>(i) < o.shadows ? "yes" : "");
    }
    fmt::print("Σ irradiance {:.6g} {:.6g} {:.6g}   probe ∫L dω {:.6g} {:.6g} {:.6g}\n", total.x, total.y, total.z,
               integral[0], integral.size() > 1 ? integral[1] : integral[0],
               integral.size() > 2 ? integral[2] : integral[0]);
    if (o.ex.method == "optimize")
      fmt::print(
          "optimiser: {} iterations ({} on the coarse normals, {} on all {}), cost {:.6g} -> {:.6g}, {:.2f} s, {}\n",
          ex.optimizer.iterations, ex.optimizer.coarse_iterations, ex.optimizer.final_iterations, ex.normals,
          ex.optimizer.initial_cost, ex.optimizer.final_cost, ex.optimizer.seconds, ex.optimizer.termination);
    for (auto* f : {&o.out, &o.gltf, &o.overlay})
      if (!f->empty()) fmt::print("wrote {}\n", *f);
  });
}

// --iterations and --tolerance, which `lights` and `eval` share.
void add_optimiser_options(CLI::App& app, int* iterations, double* tolerance) {
  app.add_option("--iterations", *iterations,
                 "optimize: safety cap on Levenberg–Marquardt steps per stage (the stopping rule is --tolerance)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--tolerance", *tolerance,
                 "optimize: converged when the last step and a full Gauss–Newton step each lower the cost by less "
                 "than this fraction")
      ->check(CLI::Range(1e-15, 0.1))
      ->capture_default_str();
}

// --normals-level, in the optimiser's range.
CLI::Option* add_normals_level_option(CLI::App& app, int* level, const std::string& help) {
  return app.add_option("--normals-level", *level, help)
      ->check(CLI::Range(kMinNormalsLevel, kMaxNormalsLevel))
      ->capture_default_str();
}

void setup_lights(CLI::App& app) {
  auto* o = iblcli::app_owned<LightsOpts>();
  auto& ex = o->ex;
  app.add_option("probe", o->probe, "HDR probe image")->required();
  app.add_option("-m,--method", ex.method, "extraction method: " + extraction_method_list())->capture_default_str();
  app.add_option("-n,--count", ex.count, "number of lights N (median-cut-2k: a power of two)")->capture_default_str();
  app.add_option("--min-separation", ex.min_separation_deg,
                 "merge lights closer than this many degrees, then cut further (0: off)");
  app.add_option("-o,--out", o->out, "write the lights as iblkit.lights/1 JSON");
  app.add_option("--gltf", o->gltf, "write the lights as a glTF 2.0 scene (KHR_lights_punctual)");
  iblcli::outputs(app, {"--gltf"});  // besides --out (cli.h)
  app.add_option("--lux-per-unit", o->gltf_desc.lux_per_unit, "glTF: lux per unit of probe irradiance")
      ->capture_default_str();
  app.add_option("--overlay", o->overlay, "write a PNG of the probe with every light and its region marked");
  app.add_option("--shadows", o->shadows, "how many lights (in priority order) deserve shadow maps")
      ->capture_default_str();
  add_normals_level_option(app, &ex.optimize.normals_level,
                           "optimize: icosphere level of the fitted normals (5: 20480)");
  add_optimiser_options(app, &ex.optimize.max_iterations, &ex.optimize.tolerance);
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer(
      "Example:\n  iblkit lights forest.exr --method median-cut --count 16 --out lights.json --gltf lights.gltf "
      "--overlay lights.png");
  app.callback([o, &rd] { run_lights(*o, rd); });
}

iblcli::Command reg_lights("lights", setup_lights);

// ---- iblkit eval --------------------------------------------------------------------------------

std::string join_ints(const std::vector<int>& v) {
  std::string s;
  for (int n : v) s += (s.empty() ? "" : ",") + std::to_string(n);
  return s;
}

struct EvalOpts {
  MethodsEvalDesc ev;  // the library's defaults; methods and counts come from the two strings below
  std::string probe, methods, counts = join_ints(MethodsEvalDesc{}.counts), lights, out = "eval";
  bool no_pictures = false;
};

std::vector<iblcli::ErrorCurve> curves_of(const EvalResult& r) {
  std::vector<iblcli::ErrorCurve> curves;
  for (const auto& row : r.rows) {
    if (row.count < 1 || row.method.find("(file)") != std::string::npos) continue;
    auto it = std::find_if(curves.begin(), curves.end(), [&](const auto& c) { return c.name == row.method; });
    if (it == curves.end()) {
      curves.push_back({row.method, {}, {}, {}});
      it = curves.end() - 1;
    }
    it->counts.push_back(row.count);
    it->mean.push_back(row.err.mean_rel);
    it->max.push_back(row.err.max_rel);
  }
  return curves;
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string part;
  while (std::getline(ss, part, ','))
    if (!part.empty()) out.push_back(part);
  return out;
}

// The optimiser's columns of a table row: "K it (J on all normals), cost ×r, converged".
std::string optimiser_note(const OptimizeReport& r) {
  return fmt::format("{} it ({} on all normals), cost ×{:.3g}, {}", r.iterations, r.final_iterations,
                     r.final_cost / std::max(1e-300, r.initial_cost), r.converged ? "converged" : r.termination);
}

// PREFIX_fig4.png and PREFIX_irradiance.png.
void write_eval_pictures(const ibl::sphere::EnvMap& env, const EvalResult& r, const std::string& probe,
                         const std::string& plot, const std::string& cmp) {
  iblcli::ErrorPlotDesc pd;
  pd.title = fmt::format("{}: irradiance error at {} normals", fs::path(probe).filename().string(), r.normals);
  if (r.have_sh) {
    pd.reference_mean = r.sh.mean_rel;
    pd.reference_max = r.sh.max_rel;
  }
  ibl::io::write_image(plot, iblcli::error_plot(curves_of(r), pd));
  ibl::Image sheet;
  for (const auto& [m, set] : r.picture_sets) {
    auto pic = iblcli::irradiance_comparison(env, set);
    if (sheet.empty()) sheet = ibl::Image(pic.width(), 0, 3);
    ibl::Image grown(pic.width(), sheet.height() + pic.height(), 3);
    std::copy(sheet.data(), sheet.data() + sheet.size(), grown.data());
    std::copy(pic.data(), pic.data() + pic.size(), grown.data() + sheet.size());
    sheet = std::move(grown);
  }
  if (!sheet.empty() && sheet.height() > 0) ibl::io::write_image(cmp, sheet);
}

void run_eval(const EvalOpts& o, const ibl::io::EnvReadDesc& rd) {
  MethodsEvalDesc ev = o.ev;
  if (!o.methods.empty()) ev.methods = split_list(o.methods);
  for (const auto& m : ev.methods) check_method(m);
  ev.counts = iblcli::parse_int_list(o.counts, "--counts");
  auto env = ibl::io::read_envmap(o.probe, rd);
  if (!o.lights.empty()) ev.given = read_lights(o.lights);
  ev.progress = iblcli::progress_bar();
  auto r = evaluate_methods(env, ev);
  iblcli::progress_done();
  std::string csv = o.out + ".csv", plot = o.out + "_fig4.png", cmp = o.out + "_irradiance.png";
  write_eval_csv(csv, r);
  if (!o.no_pictures) write_eval_pictures(env, r, o.probe, plot, cmp);
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& row : r.rows) {
    nlohmann::json jr = {{"method", row.method},       {"count", row.count},         {"mean_rel", row.err.mean_rel},
                         {"max_rel", row.err.max_rel}, {"rms_rel", row.err.rms_rel}, {"rms_abs", row.err.rms_abs},
                         {"seconds", row.seconds}};
    if (row.optimizer) jr["optimizer"] = opt_json(*row.optimizer);
    rows.push_back(jr);
  }
  nlohmann::json j = {{"probe", o.probe},
                      {"normals", r.normals},
                      {"ground_truth_seconds", r.ground_truth_seconds},
                      {"rows", rows},
                      {"csv", csv}};
  if (r.have_sh)
    j["sh"] = {
        {"bands", r.sh_bands}, {"mean_rel", r.sh.mean_rel}, {"max_rel", r.sh.max_rel}, {"rms_rel", r.sh.rms_rel}};
  if (!o.no_pictures) j["pictures"] = {plot, cmp};
  iblcli::emit(j, [&] {
    fmt::print("{}: ground truth at {} normals in {:.2f} s\n", o.probe, r.normals, r.ground_truth_seconds);
    fmt::print("{:<16} {:>5} {:>9} {:>9} {:>9} {:>9}  {}\n", "method", "N", "mean %", "max %", "rms %", "time s",
               "optimiser");
    for (const auto& row : r.rows)
      fmt::print("{:<16} {:>5} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.3f}  {}\n", row.method, row.count,
                 100 * row.err.mean_rel, 100 * row.err.max_rel, 100 * row.err.rms_rel, row.seconds,
                 row.optimizer ? optimiser_note(*row.optimizer) : "");
    if (r.have_sh)
      fmt::print("{:<16} {:>5} {:>9.3f} {:>9.3f} {:>9.3f}  (reference: {}-band SH irradiance)\n", "sh",
                 r.sh_bands * r.sh_bands, 100 * r.sh.mean_rel, 100 * r.sh.max_rel, 100 * r.sh.rms_rel, r.sh_bands);
    fmt::print("wrote {}{}\n", csv, o.no_pictures ? "" : fmt::format(", {}, {}", plot, cmp));
  });
}

void setup_eval(CLI::App& app) {
  auto* o = iblcli::app_owned<EvalOpts>();
  auto& ev = o->ev;
  app.add_option("probe", o->probe, "HDR probe image")->required();
  app.add_option("--methods", o->methods, "comma-separated methods (default: all built): " + extraction_method_list());
  app.add_option("--counts", o->counts, "comma-separated light counts N")->capture_default_str();
  app.add_option("--lights", o->lights, "also evaluate this iblkit.lights/1 file");
  add_normals_level_option(app, &ev.normals_level, "icosphere level of the normals (5: 20480, as the paper)");
  add_optimiser_options(app, &ev.optimize.max_iterations, &ev.optimize.tolerance);
  app.add_option("--sh-bands", ev.sh_bands, "SH reference line bands (0: none)")->capture_default_str();
  app.add_option("--min-separation", ev.min_separation_deg, "minimum angular separation of lights in degrees (0: off)");
  app.add_option("--picture-count", ev.picture_count, "N of the sets drawn in the irradiance comparison")
      ->capture_default_str();
  app.add_option("-o,--out", o->out, "output prefix: PREFIX.csv, PREFIX_fig4.png, PREFIX_irradiance.png")
      ->capture_default_str();
  app.add_flag("--no-pictures", o->no_pictures, "write only the CSV");
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer(
      "Example:\n  iblkit eval forest.exr --methods median-cut,variance-cut,optimize --counts 1,4,16 --out forest");
  app.callback([o, &rd] { run_eval(*o, rd); });
}

iblcli::Command reg_eval("eval", setup_eval);

// ---- demo step ----------------------------------------------------------------------------------

void demo_step(iblcli::DemoContext& ctx) {
  auto env = ibl::io::read_envmap(ctx.probe);
  ibl::make_output_folders(fs::path(fs::path(ctx.out_dir) / "lights").string());
  std::string base = (fs::path(ctx.out_dir) / "lights").string();
  MethodsEvalDesc ev;
  ev.counts = {1, 2, 4, 8, 16, 32, 64};
  ev.normals_level = 4;  // level-4 normals (5120) keep the demo quick; `iblkit eval` uses the paper's 20480
  ev.progress = iblcli::progress_bar();
  auto r = evaluate_methods(env, ev);
  iblcli::progress_done();
  write_eval_csv(base + "/eval.csv", r);
  iblcli::ErrorPlotDesc pd;
  pd.title = fmt::format("{}: irradiance error at {} normals", fs::path(ctx.probe).filename().string(), r.normals);
  if (r.have_sh) {
    pd.reference_mean = r.sh.mean_rel;
    pd.reference_max = r.sh.max_rel;
  }
  ibl::io::write_image(base + "/fig4.png", iblcli::error_plot(curves_of(r), pd));
  ctx.pictures.push_back({"lights: error vs N", base + "/fig4.png"});
  for (const auto& [m, set] : r.picture_sets) {
    std::string p = base + "/" + m + "_16.png";
    ibl::io::write_image(p, iblcli::light_overlay(env, set, 1024, 4));
    ctx.pictures.push_back({m + " 16 lights", p});
    write_lights(base + "/" + m + "_16.json", set);
    write_gltf(base + "/" + m + "_16.gltf", set);
  }
  nlohmann::json sum = nlohmann::json::object();
  for (const auto& row : r.rows)
    sum[row.method][std::to_string(row.count)] = {{"mean_rel", row.err.mean_rel}, {"max_rel", row.err.max_rel}};
  if (r.have_sh) sum[sh_reference_name(r.sh_bands)] = {{"mean_rel", r.sh.mean_rel}, {"max_rel", r.sh.max_rel}};
  ctx.summary["lights"] = sum;
}

iblcli::DemoStep demo("lights", 40, demo_step);

}  // namespace
