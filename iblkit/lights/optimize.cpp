#include "iblkit/lights/optimize.h"

#include <array>
#include <chrono>
#include <thread>
#include <cmath>
#include <memory>

#include <ceres/ceres.h>

#include "iblkit/core/parallel.h"
#include "iblkit/lights/cut.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::lights {

namespace {

/*
 * The least-squares problem
 * -------------------------
 * Light i has parameters p_i = (q_r, q_g, q_b, a, b): irradiance E_ic = exp(q_ic) and direction
 *
 *     d_i(a, b) = cos b (cos a · f_i + sin a · t_i) + sin b · s_i
 *
 * in a frame (t_i, s_i, f_i) whose f_i is the light's initial direction (core/vec.h Frame), so a = b = 0
 * starts every light far from the parameterisation's poles (b = ±π/2). For normal n_k and channel c,
 *
 *     r_kc = w_kc · ( Σ_i E_ic · max(0, n_k·d_i) − E_gt,kc ),     w_kc = 1 / max(E_gt,kc, floor_c)
 *
 * and Ceres minimises ½ Σ r² by Levenberg–Marquardt with the analytic Jacobian (where n_k·d_i > 0)
 *
 *     ┌──────────────────────────────────────────────────────────────────────┐
 *     │ ∂r_kc/∂q_ic = w_kc E_ic (n_k·d_i)                                     │
 *     │ ∂r_kc/∂a_i  = w_kc E_ic n_k·[cos b (−sin a f_i + cos a t_i)]          │
 *     │ ∂r_kc/∂b_i  = w_kc E_ic n_k·[−sin b (cos a f_i + sin a t_i) + cos b s_i] │
 *     └──────────────────────────────────────────────────────────────────────┘
 *
 * and 0 where the light is behind the normal (the kink of max(0, ·) has measure zero).
 */

struct LightFrame {
  Vec3 f, t, s;  // initial direction and two tangents
};

struct Data {
  const std::vector<Vec3>* normals;
  std::vector<Vec3> gt;      // ground truth per normal
  std::vector<Vec3> weight;  // w_kc
  std::vector<LightFrame> frames;
};

struct LightEval {
  Vec3 e, d, da, db;
};

LightEval eval_light(const double* p, const LightFrame& fr) {
  LightEval le;
  le.e = {std::exp(p[0]), std::exp(p[1]), std::exp(p[2])};
  double ca = std::cos(p[3]), sa = std::sin(p[3]), cb = std::cos(p[4]), sb = std::sin(p[4]);
  Vec3 h = fr.f * ca + fr.t * sa;
  le.d = h * cb + fr.s * sb;
  le.da = (fr.f * -sa + fr.t * ca) * cb;
  le.db = h * -sb + fr.s * cb;
  return le;
}

class IrradianceCost final : public ceres::CostFunction {
 public:
  IrradianceCost(const Data* data, size_t lo, size_t hi, int nlights) : data_(data), lo_(lo), hi_(hi), n_(nlights) {
    set_num_residuals(static_cast<int>(3 * (hi - lo)));
    for (int i = 0; i < nlights; ++i) mutable_parameter_block_sizes()->push_back(5);
  }

  bool Evaluate(double const* const* params, double* residuals, double** jac) const override {
    std::vector<LightEval> le(n_);
    for (int i = 0; i < n_; ++i) le[i] = eval_light(params[i], data_->frames[i]);
    int rows = num_residuals();
    if (jac)
      for (int i = 0; i < n_; ++i)
        if (jac[i]) std::fill(jac[i], jac[i] + rows * 5, 0.0);
    const auto& normals = *data_->normals;
    for (size_t k = lo_; k < hi_; ++k) {
      const Vec3& n = normals[k];
      const Vec3& w = data_->weight[k];
      Vec3 e;
      int row = static_cast<int>(3 * (k - lo_));
      for (int i = 0; i < n_; ++i) {
        double c = dot(n, le[i].d);
        if (c <= 0) continue;
        e += le[i].e * c;
        if (jac && jac[i]) {
          double ga = dot(n, le[i].da), gb = dot(n, le[i].db);
          for (int ch = 0; ch < 3; ++ch) {
            double s = w[ch] * le[i].e[ch];
            double* J = jac[i] + (row + ch) * 5;
            J[ch] = s * c;
            J[3] = s * ga;
            J[4] = s * gb;
          }
        }
      }
      for (int ch = 0; ch < 3; ++ch) residuals[row + ch] = w[ch] * (e[ch] - data_->gt[k][ch]);
    }
    return true;
  }

 private:
  const Data* data_;
  size_t lo_, hi_;
  int n_;
};

Data make_data(const std::vector<Vec3>& normals, const std::vector<Vec3>& gt, double floor_fraction) {
  Data d;
  d.normals = &normals;
  d.gt = gt;
  Vec3 mean;
  for (const auto& e : gt) mean += e;
  mean = mean / static_cast<double>(gt.size());
  constexpr double kTiny = 1e-300;  // a channel that is 0 everywhere keeps a finite weight
  Vec3 floor{std::max(mean.x * floor_fraction, kTiny), std::max(mean.y * floor_fraction, kTiny),
             std::max(mean.z * floor_fraction, kTiny)};
  d.weight.resize(gt.size());
  for (size_t k = 0; k < gt.size(); ++k)
    for (int c = 0; c < 3; ++c) d.weight[k][c] = 1.0 / std::max(gt[k][c], floor[c]);
  return d;
}

// ½ Σ r² of lights (not parameters) on a data set.
double cost_of(const Data& d, const std::vector<Light>& lights) {
  auto est = irradiance_from_lights(lights, *d.normals);
  double s = 0;
  for (size_t k = 0; k < est.size(); ++k)
    for (int c = 0; c < 3; ++c) {
      double r = d.weight[k][c] * (est[k][c] - d.gt[k][c]);
      s += r * r;
    }
  return 0.5 * s;
}

struct StageResult {
  std::vector<Light> lights;
  int iterations = 0;
  bool converged = false;
  std::string message;
};

StageResult solve_stage(const std::vector<Vec3>& normals, const std::vector<Vec3>& gt, const std::vector<Light>& init,
                        const OptimizeDesc& desc, int max_iterations) {
  Data data = make_data(normals, gt, desc.floor_fraction);
  int n = static_cast<int>(init.size());
  // Floor for log(0): a channel a light does not carry starts 10⁻⁶ of the mean light's irradiance.
  Vec3 total;
  for (const auto& l : init) total += l.irradiance;
  constexpr double kLogFloorFraction = 1e-6;
  std::vector<std::array<double, 5>> p(n);
  data.frames.resize(n);
  for (int i = 0; i < n; ++i) {
    Frame fr = Frame::from_normal(init[i].direction);
    data.frames[i] = {fr.n, fr.t, fr.b};
    for (int c = 0; c < 3; ++c)
      p[i][c] = std::log(std::max(init[i].irradiance[c], std::max(total[c], 1e-30) / n * kLogFloorFraction));
    p[i][3] = p[i][4] = 0;
  }
  ceres::Problem problem;
  std::vector<double*> blocks(n);
  for (int i = 0; i < n; ++i) blocks[i] = p[i].data();
  // Residual blocks of 128 normals: Ceres evaluates them in parallel.
  constexpr size_t kChunk = 128;
  for (size_t lo = 0; lo < normals.size(); lo += kChunk)
    problem.AddResidualBlock(new IrradianceCost(&data, lo, std::min(normals.size(), lo + kChunk), n), nullptr, blocks);
  ceres::Solver::Options opt;
  opt.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  opt.minimizer_type = ceres::TRUST_REGION;
  opt.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  opt.max_num_iterations = max_iterations;
  opt.num_threads = desc.threads > 0 ? desc.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  opt.function_tolerance = desc.function_tolerance;
  opt.parameter_tolerance = 1e-8;
  opt.gradient_tolerance = 1e-10;
  opt.logging_type = ceres::SILENT;
  opt.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(opt, &problem, &summary);
  StageResult r;
  r.iterations = static_cast<int>(summary.iterations.size()) - 1;
  r.converged = summary.termination_type == ceres::CONVERGENCE;
  r.message = summary.message;
  r.lights.resize(n);
  for (int i = 0; i < n; ++i) {
    LightEval le = eval_light(p[i].data(), data.frames[i]);
    r.lights[i].direction = normalize(le.d);
    r.lights[i].irradiance = le.e;
  }
  return r;
}

// Solid angle and region of each light: the probe pixels nearer to it than to any other light
// (a spherical Voronoi cell on the lat-long grid).
void voronoi_regions(const sphere::EnvMap& env, LightSet& set) {
  LatLongGrid g = to_latlong_grid(env);
  set.regions.width = g.width;
  set.regions.height = g.height;
  set.regions.label.assign(static_cast<size_t>(g.width) * g.height, -1);
  int n = static_cast<int>(set.lights.size());
  std::vector<std::vector<double>> omega(g.height, std::vector<double>(n, 0.0));
  parallel_for(0, g.height, [&](int64_t y) {
    for (int x = 0; x < g.width; ++x) {
      Vec3 w = g.direction(x + 0.5, y + 0.5);
      int best = 0;
      double bc = -2;
      for (int i = 0; i < n; ++i) {
        double c = dot(w, set.lights[i].direction);
        if (c > bc) { bc = c; best = i; }
      }
      set.regions.label[static_cast<size_t>(y) * g.width + x] = best;
      omega[y][best] += g.row_solid_angle[y];
    }
  });
  for (auto& l : set.lights) l.solid_angle = 0;
  for (const auto& row : omega)
    for (int i = 0; i < n; ++i) set.lights[i].solid_angle += row[i];
}

}  // namespace

LightSet optimize_lights_from(const sphere::EnvMap& env, const std::vector<Vec3>& normals,
                              const std::vector<Vec3>& ground_truth, const std::vector<Light>& initial,
                              const OptimizeDesc& desc, OptimizeReport* out_report) {
  if (initial.empty()) fail(ErrorKind::Value, "optimiser: no initial lights");
  if (normals.size() != ground_truth.size() || normals.empty())
    fail(ErrorKind::Value, "optimiser: {} normals but {} ground-truth values", normals.size(), ground_truth.size());
  if (desc.max_iterations < 1) fail(ErrorKind::Value, "optimiser: max_iterations must be ≥ 1");
  auto t0 = std::chrono::steady_clock::now();
  OptimizeReport rep;
  Data final_data = make_data(normals, ground_truth, desc.floor_fraction);
  rep.initial_cost = cost_of(final_data, initial);
  std::vector<Light> lights = initial;
  // Coarse to fine: levels 3 and 4 (1280 and 5120 normals) before the full set, each stage starting
  // from the last; a stage is kept only if it lowers the cost on the full set.
  bool coarse_ran = false;
  if (desc.coarse_to_fine) {
    for (int level : {3, 4}) {
      auto coarse = sphere::icosphere_face_centres(level);
      if (2 * coarse.size() > normals.size()) break;
      auto coarse_gt = irradiance_ground_truth(env, coarse);
      auto s = solve_stage(coarse, coarse_gt, lights, desc, desc.max_iterations);
      rep.iterations += s.iterations;
      coarse_ran = true;
      if (cost_of(final_data, s.lights) < cost_of(final_data, lights)) lights = s.lights;
      report(desc.progress, "optimise", level == 3 ? 0.3 : 0.6);
    }
  }
  StageResult fin;
  for (int round = 0; round < 4; ++round) {
    fin = solve_stage(normals, ground_truth, lights, desc, coarse_ran ? desc.final_iterations : desc.max_iterations);
    rep.iterations += fin.iterations;
    lights = fin.lights;
    if (desc.min_separation_deg <= 0) break;
    LightSet tmp;
    tmp.lights = lights;
    if (merge_close_lights(tmp, desc.min_separation_deg * kPi / 180.0) == 0) break;
    lights = tmp.lights;
  }
  LightSet set;
  set.method = "optimize";
  set.lights = lights;
  rep.final_cost = cost_of(final_data, lights);
  rep.converged = fin.converged;
  rep.termination = fin.message;
  voronoi_regions(env, set);
  rank_for_shadows(set);
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  report(desc.progress, "optimise", 1.0);
  if (out_report) *out_report = rep;
  return set;
}

LightSet optimize_lights(const sphere::EnvMap& env, const OptimizeDesc& desc, OptimizeReport* out_report) {
  validate_probe(env, desc.count);
  if (desc.normals_level < 0 || desc.normals_level > 7)
    fail(ErrorKind::Value, "optimiser: normals level must be in [0, 7] (got {})", desc.normals_level);
  auto normals = sphere::icosphere_face_centres(desc.normals_level);
  auto gt = irradiance_ground_truth(env, normals);
  CutDesc cd;
  cd.count = desc.count;
  LightSet init;
  if (desc.init == "variance-cut") init = variance_cut(env, cd);
  else if (desc.init == "median-cut") init = median_cut(env, cd);
  else fail(ErrorKind::Value, "optimiser: unknown initialisation \"{}\" (variance-cut, median-cut)", desc.init);
  return optimize_lights_from(env, normals, gt, init.lights, desc, out_report);
}

}  // namespace ibl::lights
