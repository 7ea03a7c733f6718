// iblkit lights PROBE: directional lights from a probe (median cut, variance cut, irradiance
// optimisation) as iblkit.lights/1 JSON, glTF 2.0 (KHR_lights_punctual) and an overlay picture.
// iblkit eval PROBE: irradiance error of each method against the exact ground truth at M normals, for
// a list of light counts: table, CSV, the paper's Figure 4 and an irradiance comparison picture.
// The demo step "lights" runs both on the demo probe.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"
#include "iblkit/lights/cut.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/lights/gltf.h"
#include "iblkit/lights/optimize.h"
#include "iblkit/sh/convolve.h"
#include "iblkit/sh/project.h"
#include "iblkit/sphere/pointset.h"
#include "lights_pictures.h"

namespace {

namespace fs = std::filesystem;
using namespace ibl::lights;

const char* kMethods = "median-cut, median-cut-2k, variance-cut, optimize";

void check_method(const std::string& m) {
  if (m == "median-cut" || m == "median-cut-2k" || m == "variance-cut" || m == "optimize") return;
  ibl::fail(ibl::ErrorKind::Value, "unknown method '{}': use {}", m, kMethods);
}

struct Extraction {
  LightSet set;
  double seconds = 0;
  OptimizeReport opt;  // filled for "optimize"
};

// One method at one count. `normals`/`gt` are the optimiser's targets (and initial cut is variance cut).
Extraction extract(const ibl::sphere::EnvMap& env, const std::string& method, int count, double sep_deg,
                   const std::vector<ibl::Vec3>& normals, const std::vector<ibl::Vec3>& gt, const OptimizeDesc& od0) {
  Extraction ex;
  auto t0 = std::chrono::steady_clock::now();
  CutDesc cd;
  cd.count = count;
  cd.min_separation_deg = sep_deg;
  if (method == "median-cut") ex.set = median_cut(env, cd);
  else if (method == "median-cut-2k") {
    cd.power_of_two = true;
    ex.set = median_cut(env, cd);
    ex.set.method = "median-cut-2k";
  } else if (method == "variance-cut") ex.set = variance_cut(env, cd);
  else {
    OptimizeDesc od = od0;
    od.count = count;
    od.min_separation_deg = sep_deg;
    CutDesc init_cd;
    init_cd.count = count;
    LightSet init = od.init == "median-cut" ? median_cut(env, init_cd) : variance_cut(env, init_cd);
    ex.set = optimize_lights_from(env, normals, gt, init.lights, od, &ex.opt);
  }
  ex.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return ex;
}

nlohmann::json opt_json(const OptimizeReport& r) {
  return {{"iterations", r.iterations}, {"final_iterations", r.final_iterations},
          {"coarse_iterations", r.coarse_iterations}, {"initial_cost", r.initial_cost}, {"final_cost", r.final_cost},
          {"last_decrease", r.last_decrease}, {"decrement", r.decrement}, {"dark_lights", r.dark_lights},
          {"seconds", r.seconds}, {"converged", r.converged}, {"termination", r.termination}};
}

// ---- iblkit lights ------------------------------------------------------------------------------

struct LightsOpts {
  std::string probe, method = "median-cut", out, gltf, overlay;
  int count = 16, shadows = 4, level = 5, iterations = 1000;
  double sep = 0, lux = 1.0, tolerance = 1e-6;
};

void run_lights(const LightsOpts& o, const ibl::io::EnvReadDesc& rd) {
  check_method(o.method);
  auto env = ibl::io::read_envmap(o.probe, rd);
  validate_probe(env, o.count);
  std::vector<ibl::Vec3> normals, gt;
  OptimizeDesc od;
  od.progress = iblcli::progress_bar();
  od.max_iterations = o.iterations;
  od.tolerance = o.tolerance;
  if (o.method == "optimize") {
    if (o.level < 1 || o.level > 7) ibl::fail(ibl::ErrorKind::Value, "--normals-level must be in 1..7 (got {})", o.level);
    normals = ibl::sphere::icosphere_face_centres(o.level);
    GroundTruthDesc gd;
    gd.progress = iblcli::progress_bar();
    gt = irradiance_ground_truth(env, normals, gd);
  }
  auto ex = extract(env, o.method, o.count, o.sep, normals, gt, od);
  iblcli::progress_done();
  const auto& set = ex.set;
  if (!o.out.empty()) write_lights(o.out, set);
  if (!o.gltf.empty()) {
    GltfDesc gd;
    gd.lux_per_unit = o.lux;
    write_gltf(o.gltf, set, gd);
  }
  if (!o.overlay.empty()) ibl::io::write_image(o.overlay, iblcli::light_overlay(env, set, 1024, o.shadows));
  auto total = total_irradiance(set);
  auto integral = env.integral();
  nlohmann::json j = to_json(set);
  j["probe"] = o.probe;
  j["seconds"] = ex.seconds;
  j["shadow_maps"] = std::min<int>(o.shadows, static_cast<int>(set.lights.size()));
  j["total_irradiance"] = {total.x, total.y, total.z};
  j["probe_integral"] = integral;
  if (o.method == "optimize") j["optimizer"] = opt_json(ex.opt);
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
               integral[0], integral.size() > 1 ? integral[1] : integral[0], integral.size() > 2 ? integral[2] : integral[0]);
    if (o.method == "optimize")
      fmt::print("optimiser: {} iterations ({} on the coarse normals, {} on all {}), cost {:.6g} -> {:.6g}, {:.2f} s, {}\n",
                 ex.opt.iterations, ex.opt.coarse_iterations, ex.opt.final_iterations, normals.size(),
                 ex.opt.initial_cost, ex.opt.final_cost, ex.opt.seconds, ex.opt.termination);
    for (auto* f : {&o.out, &o.gltf, &o.overlay})
      if (!f->empty()) fmt::print("wrote {}\n", *f);
  });
}

// --iterations and --tolerance, which `lights` and `eval` share.
void add_optimiser_options(CLI::App& app, int* iterations, double* tolerance) {
  app.add_option("--iterations", *iterations,
                 "optimize: safety cap on Levenberg–Marquardt steps per stage (the stopping rule is --tolerance)")
      ->check(CLI::Range(1, 100000))->capture_default_str();
  app.add_option("--tolerance", *tolerance,
                 "optimize: converged when the last step and a full Gauss–Newton step each lower the cost by less "
                 "than this fraction")->check(CLI::Range(1e-15, 0.1))->capture_default_str();
}

void setup_lights(CLI::App& app) {
  auto* o = new LightsOpts();
  app.add_option("probe", o->probe, "HDR probe image")->required();
  app.add_option("-m,--method", o->method, std::string("extraction method: ") + kMethods)->capture_default_str();
  app.add_option("-n,--count", o->count, "number of lights N (median-cut-2k: a power of two)")->capture_default_str();
  app.add_option("--min-separation", o->sep, "merge lights closer than this many degrees, then cut further (0: off)");
  app.add_option("-o,--out", o->out, "write the lights as iblkit.lights/1 JSON");
  app.add_option("--gltf", o->gltf, "write the lights as a glTF 2.0 scene (KHR_lights_punctual)");
  app.add_option("--lux-per-unit", o->lux, "glTF: lux per unit of probe irradiance")->capture_default_str();
  app.add_option("--overlay", o->overlay, "write a PNG of the probe with every light and its region marked");
  app.add_option("--shadows", o->shadows, "how many lights (in priority order) deserve shadow maps")->capture_default_str();
  app.add_option("--normals-level", o->level, "optimize: icosphere level of the fitted normals (5: 20480)")->capture_default_str();
  add_optimiser_options(app, &o->iterations, &o->tolerance);
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer("Example:\n  iblkit lights forest.exr --method median-cut --count 16 --out lights.json --gltf lights.gltf --overlay lights.png");
  app.callback([o, &rd] { run_lights(*o, rd); });
}

iblcli::Command reg_lights("lights", setup_lights);

// ---- iblkit eval --------------------------------------------------------------------------------

struct EvalOpts {
  std::string probe, methods, counts = "1,2,4,8,16,32,64,128,256", lights, out = "eval";
  int level = 5, sh_bands = 3, picture_count = 16, iterations = 1000;
  double sep = 0, tolerance = 1e-6;
  bool no_pictures = false;
};

struct EvalRow {
  std::string method;
  int count;
  ErrorStats err;
  double seconds;
  nlohmann::json opt;
};

struct EvalResult {
  std::vector<EvalRow> rows;
  ErrorStats sh;
  bool have_sh = false;
  double gt_seconds = 0;
  std::map<std::string, LightSet> picture_sets;  // the set drawn in the comparison, per method
};

EvalResult evaluate(const ibl::sphere::EnvMap& env, const std::vector<std::string>& methods, const std::vector<int>& counts,
                    int level, int sh_bands, double sep, int picture_count, const std::string& lights_file,
                    int iterations = 1000, double tolerance = 1e-6) {
  EvalResult res;
  auto normals = ibl::sphere::icosphere_face_centres(level);
  auto t0 = std::chrono::steady_clock::now();
  GroundTruthDesc gd;
  gd.progress = iblcli::progress_bar();
  auto gt = irradiance_ground_truth(env, normals, gd);
  iblcli::progress_done();
  res.gt_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (sh_bands > 0) {
    auto coeffs = ibl::sh::project(env, sh_bands);
    std::vector<ibl::Vec3> est(normals.size());
    for (size_t k = 0; k < normals.size(); ++k) {
      auto e = ibl::sh::irradiance_at(coeffs, normals[k]);
      est[k] = {e[0], e[1], e[2]};
    }
    res.sh = compare_irradiance(est, gt);
    res.have_sh = true;
  }
  if (!lights_file.empty()) {
    auto set = read_lights(lights_file);
    res.rows.push_back({set.method + " (file)", static_cast<int>(set.lights.size()),
                        compare_irradiance(irradiance_from_lights(set.lights, normals), gt), 0.0, nullptr});
    res.picture_sets[set.method] = set;
  }
  OptimizeDesc od;
  od.max_iterations = iterations;
  od.tolerance = tolerance;
  int done = 0, total = static_cast<int>(methods.size() * counts.size());
  auto bar = iblcli::progress_bar();
  for (const auto& m : methods)
    for (int n : counts) {
      if (m == "median-cut-2k" && (n & (n - 1)) != 0) { ++done; continue; }
      auto ex = extract(env, m, n, sep, normals, gt, od);
      auto err = compare_irradiance(irradiance_from_lights(ex.set.lights, normals), gt);
      res.rows.push_back({m, n, err, ex.seconds, m == "optimize" ? opt_json(ex.opt) : nlohmann::json()});
      if (n == picture_count) res.picture_sets[m] = ex.set;
      if (bar) bar("eval", static_cast<double>(++done) / total);
    }
  iblcli::progress_done();
  return res;
}

std::vector<iblcli::ErrorCurve> curves_of(const EvalResult& r) {
  std::vector<iblcli::ErrorCurve> curves;
  for (const auto& row : r.rows) {
    if (row.count < 1 || row.method.find("(file)") != std::string::npos) continue;
    auto it = std::find_if(curves.begin(), curves.end(), [&](const auto& c) { return c.name == row.method; });
    if (it == curves.end()) { curves.push_back({row.method, {}, {}, {}}); it = curves.end() - 1; }
    it->counts.push_back(row.count);
    it->mean.push_back(row.err.mean_rel);
    it->max.push_back(row.err.max_rel);
  }
  return curves;
}

void write_csv(const std::string& path, const EvalResult& r) {
  std::ofstream f(path);
  if (!f) ibl::fail(ibl::ErrorKind::Io, "cannot write {}", path);
  f << "method,count,mean_rel,max_rel,rms_rel,rms_abs,mean_irradiance_Y,seconds,iterations,final_iterations,converged,initial_cost,final_cost\n";
  for (const auto& row : r.rows)
    f << fmt::format("{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4f},{},{},{},{},{}\n", row.method, row.count,
                     row.err.mean_rel, row.err.max_rel, row.err.rms_rel, row.err.rms_abs,
                     ibl::luminance(row.err.mean_est), row.seconds,
                     row.opt.is_null() ? "" : std::to_string(row.opt["iterations"].get<int>()),
                     row.opt.is_null() ? "" : std::to_string(row.opt["final_iterations"].get<int>()),
                     row.opt.is_null() ? "" : (row.opt["converged"].get<bool>() ? "yes" : "no"),
                     row.opt.is_null() ? "" : fmt::format("{:.6g}", row.opt["initial_cost"].get<double>()),
                     row.opt.is_null() ? "" : fmt::format("{:.6g}", row.opt["final_cost"].get<double>()));
  if (r.have_sh)
    f << fmt::format("sh-3band,9,{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},,,,,,\n", r.sh.mean_rel, r.sh.max_rel, r.sh.rms_rel,
                     r.sh.rms_abs, ibl::luminance(r.sh.mean_est));
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string part;
  while (std::getline(ss, part, ','))
    if (!part.empty()) out.push_back(part);
  return out;
}

void run_eval(const EvalOpts& o, const ibl::io::EnvReadDesc& rd) {
  std::vector<std::string> methods;
  if (o.methods.empty()) {
    methods = {"median-cut", "variance-cut"};
    methods.push_back("optimize");
  } else {
    methods = split_list(o.methods);
  }
  for (const auto& m : methods) check_method(m);
  auto counts = iblcli::parse_int_list(o.counts, "--counts");
  if (o.level < 1 || o.level > 7) ibl::fail(ibl::ErrorKind::Value, "--normals-level must be in 1..7 (got {})", o.level);
  auto env = ibl::io::read_envmap(o.probe, rd);
  for (int n : counts) validate_probe(env, n);
  auto r = evaluate(env, methods, counts, o.level, o.sh_bands, o.sep, o.picture_count, o.lights, o.iterations, o.tolerance);
  std::string csv = o.out + ".csv", plot = o.out + "_fig4.png", cmp = o.out + "_irradiance.png";
  write_csv(csv, r);
  if (!o.no_pictures) {
    iblcli::ErrorPlotDesc pd;
    pd.title = fmt::format("{}: irradiance error at {} normals", fs::path(o.probe).filename().string(),
                           ibl::sphere::icosphere_face_centres(o.level).size());
    if (r.have_sh) { pd.reference_mean = r.sh.mean_rel; pd.reference_max = r.sh.max_rel; }
    ibl::io::write_image(plot, iblcli::error_plot(curves_of(r), pd));
    std::vector<std::pair<std::string, ibl::Image>> rows;
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
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& row : r.rows) {
    nlohmann::json jr = {{"method", row.method}, {"count", row.count}, {"mean_rel", row.err.mean_rel},
                         {"max_rel", row.err.max_rel}, {"rms_rel", row.err.rms_rel}, {"rms_abs", row.err.rms_abs},
                         {"seconds", row.seconds}};
    if (!row.opt.is_null()) jr["optimizer"] = row.opt;
    rows.push_back(jr);
  }
  nlohmann::json j = {{"probe", o.probe}, {"normals", ibl::sphere::icosphere_face_centres(o.level).size()},
                      {"ground_truth_seconds", r.gt_seconds}, {"rows", rows}, {"csv", csv}};
  if (r.have_sh) j["sh"] = {{"bands", o.sh_bands}, {"mean_rel", r.sh.mean_rel}, {"max_rel", r.sh.max_rel}, {"rms_rel", r.sh.rms_rel}};
  if (!o.no_pictures) j["pictures"] = {plot, cmp};
  iblcli::emit(j, [&] {
    fmt::print("{}: ground truth at {} normals in {:.2f} s\n", o.probe, ibl::sphere::icosphere_face_centres(o.level).size(), r.gt_seconds);
    fmt::print("{:<16} {:>5} {:>9} {:>9} {:>9} {:>9}  {}\n", "method", "N", "mean %", "max %", "rms %", "time s", "optimiser");
    for (const auto& row : r.rows) {
      std::string extra;
      if (!row.opt.is_null())
        extra = fmt::format("{} it ({} on all normals), cost ×{:.3g}, {}", row.opt["iterations"].get<int>(),
                            row.opt["final_iterations"].get<int>(),
                            row.opt["final_cost"].get<double>() / std::max(1e-300, row.opt["initial_cost"].get<double>()),
                            row.opt["converged"].get<bool>() ? "converged" : row.opt["termination"].get<std::string>());
      fmt::print("{:<16} {:>5} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.3f}  {}\n", row.method, row.count, 100 * row.err.mean_rel,
                 100 * row.err.max_rel, 100 * row.err.rms_rel, row.seconds, extra);
    }
    if (r.have_sh)
      fmt::print("{:<16} {:>5} {:>9.3f} {:>9.3f} {:>9.3f}  (reference: {}-band SH irradiance)\n", "sh", o.sh_bands * o.sh_bands,
                 100 * r.sh.mean_rel, 100 * r.sh.max_rel, 100 * r.sh.rms_rel, o.sh_bands);
    fmt::print("wrote {}{}\n", csv, o.no_pictures ? "" : fmt::format(", {}, {}", plot, cmp));
  });
}

void setup_eval(CLI::App& app) {
  auto* o = new EvalOpts();
  app.add_option("probe", o->probe, "HDR probe image")->required();
  app.add_option("--methods", o->methods, std::string("comma-separated methods (default: all built): ") + kMethods);
  app.add_option("--counts", o->counts, "comma-separated light counts N")->capture_default_str();
  app.add_option("--lights", o->lights, "also evaluate this iblkit.lights/1 file");
  app.add_option("--normals-level", o->level, "icosphere level of the normals (5: 20480, as the paper)")->capture_default_str();
  add_optimiser_options(app, &o->iterations, &o->tolerance);
  app.add_option("--sh-bands", o->sh_bands, "SH reference line bands (0: none)")->capture_default_str();
  app.add_option("--min-separation", o->sep, "minimum angular separation of lights in degrees (0: off)");
  app.add_option("--picture-count", o->picture_count, "N of the sets drawn in the irradiance comparison")->capture_default_str();
  app.add_option("-o,--out", o->out, "output prefix: PREFIX.csv, PREFIX_fig4.png, PREFIX_irradiance.png")->capture_default_str();
  app.add_flag("--no-pictures", o->no_pictures, "write only the CSV");
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer("Example:\n  iblkit eval forest.exr --methods median-cut,variance-cut,optimize --counts 1,2,4,8,16,32,64 --out forest");
  app.callback([o, &rd] { run_eval(*o, rd); });
}

iblcli::Command reg_eval("eval", setup_eval);

// ---- demo step ----------------------------------------------------------------------------------

void demo_step(iblcli::DemoContext& ctx) {
  auto env = ibl::io::read_envmap(ctx.probe);
  fs::create_directories(fs::path(ctx.out_dir) / "lights");
  std::string base = (fs::path(ctx.out_dir) / "lights").string();
  std::vector<std::string> methods = {"median-cut", "variance-cut"};
  methods.push_back("optimize");
  // Level-4 normals (5120) keep the demo quick; `iblkit eval` uses the paper's 20480.
  auto r = evaluate(env, methods, {1, 2, 4, 8, 16, 32, 64}, 4, 3, 0.0, 16, "");
  write_csv(base + "/eval.csv", r);
  iblcli::ErrorPlotDesc pd;
  pd.title = fmt::format("{}: irradiance error at 5120 normals", fs::path(ctx.probe).filename().string());
  if (r.have_sh) { pd.reference_mean = r.sh.mean_rel; pd.reference_max = r.sh.max_rel; }
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
  for (const auto& row : r.rows) sum[row.method][std::to_string(row.count)] = {{"mean_rel", row.err.mean_rel}, {"max_rel", row.err.max_rel}};
  if (r.have_sh) sum["sh-3band"] = {{"mean_rel", r.sh.mean_rel}, {"max_rel", r.sh.max_rel}};
  ctx.summary["lights"] = sum;
}

iblcli::DemoStep demo("lights", 40, demo_step);

}  // namespace
