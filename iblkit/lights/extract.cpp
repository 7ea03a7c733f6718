#include "iblkit/lights/extract.h"

#include <chrono>
#include <sstream>

#include <fmt/format.h>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/lights/cut.h"
#include "iblkit/sh/convolve.h"
#include "iblkit/sh/project.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::lights {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

const std::vector<std::string>& extraction_methods() {
  static const std::vector<std::string> names = {"median-cut", "median-cut-2k", "variance-cut", "optimize"};
  return names;
}

std::string extraction_method_list() {
  std::string s;
  for (const auto& m : extraction_methods()) s += (s.empty() ? "" : ", ") + m;
  return s;
}

void check_method(const std::string& method) {
  for (const auto& m : extraction_methods())
    if (m == method) return;
  fail(ErrorKind::Value, "unknown method '{}': use {}", method, extraction_method_list());
}

Extraction extract(const sphere::EnvMap& env, const ExtractDesc& desc, const std::vector<Vec3>& normals_in,
                   const std::vector<Vec3>& gt_in) {
  check_method(desc.method);
  if (!(desc.min_separation_deg >= 0 && desc.min_separation_deg < 180))
    fail(ErrorKind::Value, "minimum separation must be in [0, 180) degrees (got {})", desc.min_separation_deg);
  Extraction ex;
  std::vector<Vec3> normals_own, gt_own;
  const std::vector<Vec3>* normals = &normals_in;
  const std::vector<Vec3>* gt = &gt_in;
  if (desc.method == "optimize") {
    if (normals_in.size() != gt_in.size())
      fail(ErrorKind::Value, "extract: {} normals but {} ground-truth values", normals_in.size(), gt_in.size());
    if (normals_in.empty()) {
      validate_probe(env, desc.count);  // before the ground truth, which takes a while
      check_normals_level(desc.optimize.normals_level);
      normals_own = sphere::icosphere_face_centres(desc.optimize.normals_level);
      GroundTruthDesc gd;
      gd.progress = desc.progress;
      gt_own = irradiance_ground_truth(env, normals_own, gd);
      normals = &normals_own;
      gt = &gt_own;
    }
    ex.normals = static_cast<int>(normals->size());
  }
  auto t0 = Clock::now();
  CutDesc cd;
  cd.count = desc.count;
  cd.min_separation_deg = desc.min_separation_deg;
  if (desc.method == "median-cut") {
    ex.set = median_cut(env, cd);
  } else if (desc.method == "median-cut-2k") {
    cd.power_of_two = true;
    ex.set = median_cut(env, cd);
    ex.set.method = "median-cut-2k";
  } else if (desc.method == "variance-cut") {
    ex.set = variance_cut(env, cd);
  } else {
    OptimizeDesc od = desc.optimize;
    od.count = desc.count;
    od.min_separation_deg = desc.min_separation_deg;
    od.progress = desc.progress;
    LightSet init = initial_lights(env, od);
    ex.set = optimize_lights_from(env, *normals, *gt, init.lights, od, &ex.optimizer);
  }
  ex.seconds = since(t0);
  return ex;
}

// ---- methods × counts ---------------------------------------------------------------------------

std::string sh_reference_name(int bands) { return fmt::format("sh-{}band", bands); }

namespace {

// The SH reference line: the irradiance of the probe's `bands`-band projection at the normals.
ErrorStats sh_reference(const sphere::EnvMap& env, int bands, const std::vector<Vec3>& normals,
                        const std::vector<Vec3>& gt) {
  auto coeffs = sh::project(env, bands);
  std::vector<Vec3> est(normals.size());
  for (size_t k = 0; k < normals.size(); ++k) {
    auto e = sh::irradiance_at(coeffs, normals[k]);
    est[k] = {e[0], e[1], e[2]};
  }
  return compare_irradiance(est, gt);
}

}  // namespace

EvalResult evaluate_methods(const sphere::EnvMap& env, const MethodsEvalDesc& desc) {
  for (const auto& m : desc.methods) check_method(m);
  check_normals_level(desc.normals_level);
  for (int n : desc.counts) validate_probe(env, n);
  EvalResult res;
  auto normals = sphere::icosphere_face_centres(desc.normals_level);
  res.normals = static_cast<int>(normals.size());
  auto t0 = Clock::now();
  GroundTruthDesc gd;
  gd.progress = desc.progress;
  auto gt = irradiance_ground_truth(env, normals, gd);
  res.ground_truth_seconds = since(t0);
  if (desc.sh_bands > 0) {
    res.sh = sh_reference(env, desc.sh_bands, normals, gt);
    res.sh_bands = desc.sh_bands;
    res.have_sh = true;
  }
  if (desc.given) {
    const LightSet& set = *desc.given;
    res.rows.push_back({set.method + " (file)", static_cast<int>(set.lights.size()),
                        compare_irradiance(irradiance_from_lights(set.lights, normals), gt), 0.0, std::nullopt});
    res.picture_sets[set.method] = set;
  }
  ExtractDesc ed;
  ed.min_separation_deg = desc.min_separation_deg;
  ed.optimize = desc.optimize;
  int done = 0, total = static_cast<int>(desc.methods.size() * desc.counts.size());
  for (const auto& m : desc.methods)
    for (int n : desc.counts) {
      if (m == "median-cut-2k" && (n & (n - 1)) != 0) {
        ++done;
        continue;
      }
      ed.method = m;
      ed.count = n;
      auto ex = extract(env, ed, normals, gt);
      auto err = compare_irradiance(irradiance_from_lights(ex.set.lights, normals), gt);
      std::optional<OptimizeReport> opt;
      if (m == "optimize") opt = ex.optimizer;
      res.rows.push_back({m, n, err, ex.seconds, opt});
      if (n == desc.picture_count) res.picture_sets[m] = ex.set;
      if (desc.progress) report(desc.progress, "eval", static_cast<double>(++done) / total);
    }
  return res;
}

void write_eval_csv(const std::string& path, const EvalResult& r) {
  std::ostringstream f;
  f << "method,count,mean_rel,max_rel,rms_rel,rms_abs,mean_irradiance_Y,seconds,iterations,final_iterations,converged,"
       "initial_cost,final_cost\n";
  for (const auto& row : r.rows) {
    const auto& o = row.optimizer;
    f << fmt::format("{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4f},{},{},{},{},{}\n", row.method, row.count,
                     row.err.mean_rel, row.err.max_rel, row.err.rms_rel, row.err.rms_abs, luminance(row.err.mean_est),
                     row.seconds, o ? std::to_string(o->iterations) : "", o ? std::to_string(o->final_iterations) : "",
                     o ? (o->converged ? "yes" : "no") : "", o ? fmt::format("{:.6g}", o->initial_cost) : "",
                     o ? fmt::format("{:.6g}", o->final_cost) : "");
  }
  if (r.have_sh)
    f << fmt::format("{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},,,,,,\n", sh_reference_name(r.sh_bands),
                     r.sh_bands * r.sh_bands, r.sh.mean_rel, r.sh.max_rel, r.sh.rms_rel, r.sh.rms_abs,
                     luminance(r.sh.mean_est));
  write_file_atomically(path, f.str());
}

}  // namespace ibl::lights
