#include "iblkit/lights/optimize.h"

#include <array>
#include <chrono>
#include <thread>
#include <cmath>
#include <memory>

#include <Eigen/Cholesky>
#include <Eigen/Core>
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

/*
 * Square-root compression of the 3M residuals
 * --------------------------------------------
 * Ceres' Levenberg–Marquardt uses r and J only through JᵀJ, Jᵀr and ‖r‖² (with Jacobi scaling from the
 * column norms of J, i.e. diag JᵀJ). Let G = [J r]ᵀ[J r], size (5N+1)², and S any square matrix with
 * SᵀS = G. With r̃ = S's last column and J̃ = its first 5N columns,
 *
 *     ┌───────────────────────────────────────────────────────────────────┐
 *     │ J̃ᵀJ̃ = JᵀJ,  J̃ᵀr̃ = Jᵀr,  ‖r̃‖² = ‖r‖²,  ‖J̃δ + r̃‖ = ‖Jδ + r‖ ∀δ    │
 *     └───────────────────────────────────────────────────────────────────┘
 *
 * so LM takes exactly the steps it would take on the 3M residuals, while Ceres' own dense linear algebra
 * works on 5N+1 rows instead of 61440. G is built here from the sparsity of J: a row (k, c) touches only
 * the two angles and channel c's q of the lights in front of n_k, so each channel's rows form a dense
 * (3N+1)-column block whose Gram matrix Eigen accumulates (rank updates on chunks of 64 normals, threads
 * over four fixed ranges of normals, summed in a fixed order). S comes from the Cholesky factor of the
 * JᵀJ block (a 10⁻¹² relative ridge keeps it definite: a negligible extra damping) and the last column
 * from one triangular solve: S = [[Lᵀ, l], [0, s]], L l = Jᵀr, s = √max(0, ‖r‖² − ‖l‖²).
 * Evaluations without a Jacobian return (‖r‖, 0, …, 0): only the cost is used there.
 */
class CompressedIrradianceCost final : public ceres::CostFunction {
 public:
  CompressedIrradianceCost(const Data* data, int nlights) : data_(data), n_(nlights) {
    set_num_residuals(5 * nlights + 1);
    for (int i = 0; i < nlights; ++i) mutable_parameter_block_sizes()->push_back(5);
  }

  bool Evaluate(double const* const* params, double* residuals, double** jac) const override {
    std::vector<LightEval> le(n_);
    for (int i = 0; i < n_; ++i) le[i] = eval_light(params[i], data_->frames[i]);
    const int P = 5 * n_, R = P + 1;
    if (!jac) {
      std::fill(residuals, residuals + R, 0.0);
      residuals[0] = std::sqrt(sum_squares(le));
      return std::isfinite(residuals[0]);
    }
    Eigen::MatrixXd G = gram(le);  // lower triangle, Ceres' parameter order, r last
    Eigen::MatrixXd A = G.topLeftCorner(P, P).selfadjointView<Eigen::Lower>();
    double maxd = A.diagonal().maxCoeff();
    constexpr double kRidge = 1e-12;  // relative to the largest diagonal entry of JᵀJ
    A.diagonal().array() += kRidge * maxd + 1e-300;
    Eigen::LLT<Eigen::MatrixXd> llt(A);
    if (llt.info() != Eigen::Success) return false;
    Eigen::MatrixXd L = llt.matrixL();
    Eigen::VectorXd g = G.block(P, 0, 1, P).transpose();  // Jᵀr
    Eigen::VectorXd l = llt.matrixL().solve(g);
    double s = std::sqrt(std::max(0.0, G(P, P) - l.squaredNorm()));
    // S = [[Lᵀ, l], [0, s]]: row `row` of J̃ is row `row` of Lᵀ, i.e. column `row` of L.
    for (int row = 0; row < R; ++row) {
      residuals[row] = row < P ? l(row) : s;
      for (int i = 0; i < n_; ++i) {
        if (!jac[i]) continue;
        for (int j = 0; j < 5; ++j) {
          int col = 5 * i + j;
          jac[i][row * 5 + j] = (row < P && col >= row) ? L(col, row) : 0.0;
        }
      }
    }
    return true;
  }

 private:
  static constexpr int kRanges = 4;   // fixed partition of the normals: deterministic sums
  static constexpr int kChunk = 64;   // normals per rank update

  double sum_squares(const std::vector<LightEval>& le) const {
    const auto& normals = *data_->normals;
    return parallel_reduce_fixed<double>(0, static_cast<int64_t>(normals.size()), 512, 0.0,
      [&](int64_t lo, int64_t hi) {
        double ss = 0;
        for (int64_t k = lo; k < hi; ++k) {
          Vec3 e;
          for (const auto& l : le) {
            double c = dot(normals[k], l.d);
            if (c > 0) e += l.e * c;
          }
          for (int ch = 0; ch < 3; ++ch) {
            double r = data_->weight[k][ch] * (e[ch] - data_->gt[k][ch]);
            ss += r * r;
          }
        }
        return ss;
      },
      [](double a, double b) { return a + b; });
  }

  // G = [J r]ᵀ[J r] (lower triangle) in Ceres' order: light i's q_r, q_g, q_b, a, b at 5i..5i+4; r last.
  Eigen::MatrixXd gram(const std::vector<LightEval>& le) const {
    const auto& normals = *data_->normals;
    const int N = n_, C = 3 * N + 1;  // per-channel block: a,b of every light (2N), q_c (N), r
    const int64_t M = static_cast<int64_t>(normals.size());
    std::vector<std::array<Eigen::MatrixXd, 3>> part(kRanges);
    parallel_for(0, kRanges, [&](int64_t p) {
      for (auto& g : part[p]) g = Eigen::MatrixXd::Zero(C, C);
      int64_t lo = M * p / kRanges, hi = M * (p + 1) / kRanges;
      std::array<Eigen::MatrixXd, 3> B;
      for (auto& b : B) b.resize(kChunk, C);
      for (int64_t k0 = lo; k0 < hi; k0 += kChunk) {
        int rows = static_cast<int>(std::min<int64_t>(kChunk, hi - k0));
        for (auto& b : B) b.setZero();
        for (int rr = 0; rr < rows; ++rr) {
          int64_t k = k0 + rr;
          const Vec3& n = normals[k];
          const Vec3& w = data_->weight[k];
          Vec3 e;
          for (int i = 0; i < N; ++i) {
            double c = dot(n, le[i].d);
            if (c <= 0) continue;
            e += le[i].e * c;
            double ga = dot(n, le[i].da), gb = dot(n, le[i].db);
            for (int ch = 0; ch < 3; ++ch) {
              double sc = w[ch] * le[i].e[ch];
              B[ch](rr, 2 * i) = sc * ga;
              B[ch](rr, 2 * i + 1) = sc * gb;
              B[ch](rr, 2 * N + i) = sc * c;
            }
          }
          for (int ch = 0; ch < 3; ++ch) B[ch](rr, 3 * N) = w[ch] * (e[ch] - data_->gt[k][ch]);
        }
        for (int ch = 0; ch < 3; ++ch)
          part[p][ch].selfadjointView<Eigen::Lower>().rankUpdate(B[ch].topRows(rows).transpose());
      }
    });
    // Map a per-channel column to Ceres' order.
    auto global = [&](int ch, int col) {
      if (col < 2 * N) return 5 * (col / 2) + 3 + (col % 2);
      if (col < 3 * N) return 5 * (col - 2 * N) + ch;
      return 5 * N;
    };
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(5 * N + 1, 5 * N + 1);
    for (int p = 0; p < kRanges; ++p)
      for (int ch = 0; ch < 3; ++ch) {
        const auto& g = part[p][ch];
        for (int cj = 0; cj < C; ++cj)
          for (int ci = cj; ci < C; ++ci) {
            int a = global(ch, ci), b = global(ch, cj);
            if (a >= b) G(a, b) += g(ci, cj); else G(b, a) += g(ci, cj);
          }
      }
    return G;
  }

  const Data* data_;
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
  problem.AddResidualBlock(new CompressedIrradianceCost(&data, n), nullptr, blocks);
  ceres::Solver::Options opt;
  opt.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  opt.minimizer_type = ceres::TRUST_REGION;
  opt.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  opt.max_num_iterations = max_iterations;
  opt.num_threads = 1;  // one residual block; the Gram matrix is built with oneTBB threads
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
      auto s = solve_stage(coarse, coarse_gt, lights, desc, level == 3 ? desc.max_iterations : desc.mid_iterations);
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
