#include "iblkit/lights/optimize.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "iblkit/core/parallel.h"
#include "iblkit/lights/cut.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/lights/nnls.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::lights {

namespace {

/*
 * The least-squares problem and its variable projection
 * ------------------------------------------------------
 * Light i has direction d_i (unit) and RGB irradiance E_i ≥ 0. For normal n_k and channel c,
 *
 *     r_kc = w_kc · ( Σ_i E_ic · max(0, n_k·d_i) − E_gt,kc ),     w_kc = 1 / max(E_gt,kc, floor_c),
 *
 * and we minimise ½ Σ r². Per channel r_c = W_c (K(D) E_c − g_c) with K_ki = max(0, n_k·d_i): linear in
 * E_c. Variable projection [1] minimises the reduced cost φ(D) = min_{E ≥ 0} ½ Σ_c ‖r_c‖² instead: for
 * the current directions, E_c is the exact non-negative least-squares solution (nnls.h, on the N×N
 * Gram matrix K_cᵀK_c with K_c = W_c K), and LM moves the directions only. Light i moves on its tangent
 * plane, d_i(a, b) = normalize(d_i + a t_i + b s_i) with (t_i, s_i) an orthonormal tangent frame, so
 * with T_c, S_c the matrices of w_kc (n_k·t_i), w_kc (n_k·s_i) where n_k·d_i > 0 (0 elsewhere):
 *
 *     ∂r_c/∂a_i = E_ic T_c[:, i],    ∂r_c/∂b_i = E_ic S_c[:, i]      (A_c: the direction Jacobian)
 *
 * Kaufman's approximation [2] of the reduced Jacobian, P⊥ A_c with P⊥ the projector off the columns of
 * K_c that are free (E_ic > 0), has the Gauss–Newton matrix and gradient
 *
 *     ┌──────────────────────────────────────────────────────────────────────────────┐
 *     │ H = Σ_c [ A_cᵀA_c − A_cᵀK_cF (K_cFᵀK_cF)⁻¹ K_cFᵀA_c ],    g = Σ_c A_cᵀ r_c     │
 *     └──────────────────────────────────────────────────────────────────────────────┘
 *
 * (the Schur complement of the irradiance block of the full Gauss–Newton matrix; g needs no projection
 * because K_cFᵀ r_c = 0 at the NNLS solution, and bound E_ic = 0 stay bound under small moves).
 * Every block is a block of one Gram matrix per channel, G_c = [K T S g]ᵀ W_c² [K T S g] (3N+1
 * columns), scaled by E afterwards — so one pass over the normals per iteration gives everything, and
 * the pass never needs E. A light is in front of only about half the normals: the pass works on
 * patches of 64 neighbouring normals (sorted by the level-2 icosphere face they fall in), takes only
 * the lights in front of some normal of the patch, and rank-updates that compact block (Eigen, AVX2)
 * before scattering it into G_c. The cost and g are computed directly from the residuals (no
 * cancellation in Gram differences near convergence).
 *
 * The horizon term
 * ----------------
 * Gauss–Newton drops Σ r ∇²r. For the clamped cosine that term is zero in the smooth part at the NNLS
 * solution (∂²/∂a² of n·d is −n·d, and Σ_k r_kc w_kc (n_k·d_i)⁺ = 0 for a free light), but the kink of
 * max(0, ·) contributes a δ on each light's horizon: ∂²(n·d)⁺/∂a² ∋ δ(n·d)(n·t)². Steps of a few
 * normal spacings cross many horizon normals, so this curvature is real at the scale LM moves (without
 * it, steps gained 1.5–2× what the model predicted and took hundreds of iterations). With the δ
 * smoothed over a band |n·d| < h/2, h = two normal spacings (2√(4π/M)):
 *
 *     ┌───────────────────────────────────────────────────────────────────────────────┐
 *     │ H_hor,i = (1/h) Σ_c E_ic Σ_{|n_k·d_i|<h/2} w_kc r_kc [n_k·t_i, n_k·s_i]ᵀ[n_k·t_i, n_k·s_i] │
 *     └───────────────────────────────────────────────────────────────────────────────┘
 *
 * a 2×2 block per light, added to H for the step (it may be indefinite: LM damps until H + λD is
 * positive definite); the Marquardt scaling D and the convergence decrement use the Gauss–Newton H.
 */

constexpr int kPatch = 64;  // normals per patch
constexpr int kRanges = 4;  // fixed partition of the patches: sums do not depend on the thread count

struct Problem {
  std::vector<Vec3> n, gt, w;  // normals (patch order), ground truth, residual weights
  std::vector<int64_t> patch;  // patch p is [patch[p], patch[p+1])
};

Problem make_problem(const std::vector<Vec3>& normals, const std::vector<Vec3>& gt, double floor_fraction) {
  Problem P;
  const size_t M = normals.size();
  // Sort the normals by their nearest level-2 icosphere face centre (320 cells of ~11°): any input order
  // gives compact patches; the icosphere's own order (children follow parents) is kept within a cell.
  auto cells = sphere::icosphere_face_centres(2);
  std::vector<int> cell(M);
  parallel_for(
      0, static_cast<int64_t>(M),
      [&](int64_t k) {
        int best = 0;
        double bc = -2;
        for (int c = 0; c < static_cast<int>(cells.size()); ++c) {
          double d = dot(normals[k], cells[c]);
          if (d > bc) {
            bc = d;
            best = c;
          }
        }
        cell[k] = best;
      },
      256);
  std::vector<size_t> order(M);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return cell[a] < cell[b]; });
  Vec3 mean;
  for (const auto& e : gt) mean += e;
  mean = mean / static_cast<double>(M);
  constexpr double kTiny = 1e-300;  // a channel that is 0 everywhere keeps a finite weight
  Vec3 floor{std::max(mean.x * floor_fraction, kTiny), std::max(mean.y * floor_fraction, kTiny),
             std::max(mean.z * floor_fraction, kTiny)};
  P.n.resize(M);
  P.gt.resize(M);
  P.w.resize(M);
  for (size_t j = 0; j < M; ++j) {
    P.n[j] = normals[order[j]];
    P.gt[j] = gt[order[j]];
    for (int c = 0; c < 3; ++c) P.w[j][c] = 1.0 / std::max(P.gt[j][c], floor[c]);
  }
  for (int64_t b = 0; b < static_cast<int64_t>(M); b += kPatch) P.patch.push_back(b);
  P.patch.push_back(static_cast<int64_t>(M));
  return P;
}

struct Frames {
  std::vector<Vec3> d, t, s;
};

Frames frames_of(const std::vector<Vec3>& dirs) {
  Frames f;
  for (const auto& d : dirs) {
    Frame fr = Frame::from_normal(d);
    f.d.push_back(fr.n);
    f.t.push_back(fr.t);
    f.s.push_back(fr.b);
  }
  return f;
}

// Lights in front of at least one normal of patch [lo, hi), with the patch's dot products (rows: normals).
void patch_lights(const Problem& P, const Frames& F, int64_t lo, int64_t hi, std::vector<int>& U,
                  Eigen::MatrixXd& dots) {
  const int m = static_cast<int>(hi - lo), N = static_cast<int>(F.d.size());
  dots.resize(m, N);
  U.clear();
  for (int i = 0; i < N; ++i) {
    bool front = false;
    for (int r = 0; r < m; ++r) {
      double c = dot(P.n[lo + r], F.d[i]);
      dots(r, i) = c;
      front = front || c > 0;
    }
    if (front) U.push_back(i);
  }
}

// G_c (lower triangles), columns [K_0..K_{N−1}, T_0.., S_0.., g].
std::array<Eigen::MatrixXd, 3> gram_pass(const Problem& P, const Frames& F) {
  const int N = static_cast<int>(F.d.size()), C = 3 * N + 1;
  const int64_t patches = static_cast<int64_t>(P.patch.size()) - 1;
  std::vector<std::array<Eigen::MatrixXd, 3>> part(kRanges);
  parallel_for(0, kRanges, [&](int64_t q) {
    for (auto& g : part[q]) g = Eigen::MatrixXd::Zero(C, C);
    std::vector<int> U, col;
    Eigen::MatrixXd dots, geo, B, local;
    Eigen::VectorXd wv;
    for (int64_t p = patches * q / kRanges; p < patches * (q + 1) / kRanges; ++p) {
      const int64_t lo = P.patch[p], hi = P.patch[p + 1];
      const int m = static_cast<int>(hi - lo);
      patch_lights(P, F, lo, hi, U, dots);
      const int u = static_cast<int>(U.size()), c3 = 3 * u + 1;
      // Column by column (Eigen is column-major): the patch's geometry for each light in front.
      geo.setZero(m, c3);
      for (int a = 0; a < u; ++a) {
        const int i = U[a];
        const Vec3 t = F.t[i], sdir = F.s[i];
        double* gc = geo.col(a).data();
        double* gt_ = geo.col(u + a).data();
        double* gs = geo.col(2 * u + a).data();
        const double* dc = dots.col(i).data();
        for (int r = 0; r < m; ++r) {
          const double c = dc[r];
          if (c <= 0) continue;
          const Vec3& n = P.n[lo + r];
          gc[r] = c;
          gt_[r] = dot(n, t);
          gs[r] = dot(n, sdir);
        }
      }
      col.resize(c3);
      for (int a = 0; a < u; ++a) {
        col[a] = U[a];
        col[u + a] = N + U[a];
        col[2 * u + a] = 2 * N + U[a];
      }
      col[3 * u] = 3 * N;
      for (int ch = 0; ch < 3; ++ch) {
        wv.resize(m);
        B.resize(m, c3);
        for (int r = 0; r < m; ++r) {
          wv(r) = P.w[lo + r][ch];
          B(r, 3 * u) = wv(r) * P.gt[lo + r][ch];
        }
        B.leftCols(3 * u).noalias() = wv.asDiagonal() * geo.leftCols(3 * u);
        local.setZero(c3, c3);
        local.selfadjointView<Eigen::Lower>().rankUpdate(B.transpose());
        // col[] ascends (U does, then the T, S and g blocks follow), so a ≥ b maps to the global lower
        // triangle: scatter column by column through raw pointers.
        auto& G = part[q][ch];
        for (int b = 0; b < c3; ++b) {
          double* gcol = G.data() + static_cast<size_t>(col[b]) * C;
          const double* lcol = local.data() + static_cast<size_t>(b) * c3;
          for (int a = b; a < c3; ++a) gcol[col[a]] += lcol[a];
        }
      }
    }
  });
  for (int q = 1; q < kRanges; ++q)
    for (int ch = 0; ch < 3; ++ch) part[0][ch] += part[q][ch];
  return part[0];
}

// Cost ½ Σ r² and the direction gradient g (light-major: a_i at 2i, b_i at 2i+1), straight from residuals.
double cost_and_gradient(const Problem& P, const Frames& F, const std::vector<Vec3>& E, Eigen::VectorXd* grad,
                         Eigen::VectorXd* hor = nullptr) {
  const int N = static_cast<int>(F.d.size());
  const double band = 2 * std::sqrt(4 * kPi / static_cast<double>(P.n.size()));
  std::vector<Eigen::VectorXd> hq(kRanges);
  const int64_t patches = static_cast<int64_t>(P.patch.size()) - 1;
  std::vector<double> cost(kRanges, 0.0);
  std::vector<Eigen::VectorXd> g(kRanges);
  parallel_for(0, kRanges, [&](int64_t q) {
    g[q] = Eigen::VectorXd::Zero(2 * N);
    hq[q] = Eigen::VectorXd::Zero(3 * N);
    std::vector<int> U;
    Eigen::MatrixXd dots;
    double cq = 0;
    for (int64_t p = patches * q / kRanges; p < patches * (q + 1) / kRanges; ++p) {
      const int64_t lo = P.patch[p], hi = P.patch[p + 1];
      patch_lights(P, F, lo, hi, U, dots);
      for (int r = 0; r < hi - lo; ++r) {
        Vec3 e;
        for (int i : U)
          if (dots(r, i) > 0) e += E[i] * dots(r, i);
        const Vec3& w = P.w[lo + r];
        Vec3 res{w.x * (e.x - P.gt[lo + r].x), w.y * (e.y - P.gt[lo + r].y), w.z * (e.z - P.gt[lo + r].z)};
        cq += dot(res, res);
        if (!grad) continue;
        Vec3 rw = res * w;
        const Vec3& n = P.n[lo + r];
        for (int i : U) {
          if (hor && std::abs(dots(r, i)) < band / 2) {
            double s = dot(rw, E[i]) / band, nt = dot(n, F.t[i]), ns = dot(n, F.s[i]);
            hq[q](3 * i) += s * nt * nt;
            hq[q](3 * i + 1) += s * nt * ns;
            hq[q](3 * i + 2) += s * ns * ns;
          }
          if (dots(r, i) <= 0) continue;
          double s = dot(rw, E[i]);
          g[q](2 * i) += s * dot(n, F.t[i]);
          g[q](2 * i + 1) += s * dot(n, F.s[i]);
        }
      }
    }
    cost[q] = cq;
  });
  double c = 0;
  for (int q = 0; q < kRanges; ++q) c += cost[q];
  if (hor) {
    *hor = hq[0];
    for (int q = 1; q < kRanges; ++q) *hor += hq[q];
  }
  if (grad) {
    *grad = g[0];
    for (int q = 1; q < kRanges; ++q) *grad += g[q];
  }
  return 0.5 * c;
}

// Everything LM needs at one set of directions.
struct State {
  std::vector<Vec3> dirs;
  Frames F;
  std::array<Eigen::MatrixXd, 3> G;
  std::vector<Vec3> E;
  double cost = 0;
  Eigen::VectorXd grad, hor;
};

// Builds the state at `dirs`: Gram pass, NNLS per channel (warm-started from E_warm), cost and gradient.
State evaluate_state(const Problem& P, const std::vector<Vec3>& dirs, const std::vector<Vec3>& E_warm) {
  State S;
  S.dirs = dirs;
  S.F = frames_of(dirs);
  S.G = gram_pass(P, S.F);
  const int N = static_cast<int>(dirs.size());
  S.E.assign(N, Vec3{});
  for (int ch = 0; ch < 3; ++ch) {
    Eigen::VectorXd x(N);
    for (int i = 0; i < N; ++i) x(i) = E_warm[i][ch];
    Eigen::MatrixXd H = S.G[ch].topLeftCorner(N, N);
    Eigen::VectorXd b = S.G[ch].block(3 * N, 0, 1, N).transpose();
    nnls(H, b, x);
    for (int i = 0; i < N; ++i) S.E[i][ch] = x(i);
  }
  S.cost = cost_and_gradient(P, S.F, S.E, &S.grad, &S.hor);
  return S;
}

// The reduced Gauss–Newton matrix H (2N×2N, light-major) of the box above.
Eigen::MatrixXd reduced_hessian(const State& S) {
  const int N = static_cast<int>(S.dirs.size());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2 * N, 2 * N);
  for (int ch = 0; ch < 3; ++ch) {
    const Eigen::MatrixXd G = S.G[ch].selfadjointView<Eigen::Lower>();
    auto gcol = [&](int p) { return (1 + p % 2) * N + p / 2; };  // direction parameter → Gram column
    Eigen::VectorXd scale(2 * N);
    for (int p = 0; p < 2 * N; ++p) scale(p) = S.E[p / 2][ch];
    Eigen::MatrixXd Add(2 * N, 2 * N);
    for (int p = 0; p < 2 * N; ++p)
      for (int q = 0; q < 2 * N; ++q) Add(p, q) = scale(p) * scale(q) * G(gcol(p), gcol(q));
    std::vector<int> Fr;
    for (int i = 0; i < N; ++i)
      if (S.E[i][ch] > 0) Fr.push_back(i);
    const int f = static_cast<int>(Fr.size());
    if (f > 0) {
      Eigen::MatrixXd Gff(f, f), Gfd(f, 2 * N);
      for (int a = 0; a < f; ++a) {
        for (int b = 0; b < f; ++b) Gff(a, b) = G(Fr[a], Fr[b]);
        for (int p = 0; p < 2 * N; ++p) Gfd(a, p) = G(Fr[a], gcol(p)) * scale(p);
      }
      constexpr double kRidge = 1e-13;  // relative; as in nnls.cpp, so the projection matches its solution
      Gff.diagonal().array() += kRidge * Gff.diagonal().maxCoeff() + 1e-300;
      Eigen::LLT<Eigen::MatrixXd> llt(Gff);
      Eigen::MatrixXd X = llt.matrixL().solve(Gfd);
      Add.noalias() -= X.transpose() * X;
    }
    H += Add;
  }
  return H;
}

struct StageResult {
  std::vector<Vec3> dirs, E;
  double cost = 0, last_decrease = 0, decrement = 0;
  int iterations = 0;
  bool converged = false;
  std::string termination;
};

// Levenberg–Marquardt on the directions [3], from `dirs` with irradiance warm start `E`. One iteration is
// one trial step (one Gram pass), accepted or not.
StageResult solve_stage(const Problem& P, const std::vector<Vec3>& dirs, const std::vector<Vec3>& E, double tol,
                        int max_iterations) {
  const int N = static_cast<int>(dirs.size());
  State S = evaluate_state(P, dirs, E);
  StageResult R;
  double lambda = 1e-3, nu = 2;        // damping relative to diag(H_GN); Nielsen's update [3]
  constexpr double kMinLambda = 1e-7;  // keeps one rejection from needing dozens of retries to re-damp
  constexpr double kMaxLambda = 1e12;  // a step damped this much moves lights by ~1e-12 rad: nothing left to gain
  constexpr int kWindow = 3;           // accepted steps of the kink-limited stopping test
  double last = std::numeric_limits<double>::infinity();
  std::vector<double> history = {S.cost};  // cost after every accepted step
  std::vector<int> live;
  Eigen::MatrixXd Hgn, Hfull;
  Eigen::VectorXd gl, D;
  bool fresh = true;  // S changed: rebuild the model
  while (true) {
    if (fresh) {
      fresh = false;
      Eigen::MatrixXd H = reduced_hessian(S);
      // Live parameters: lights with some irradiance (a dark light's direction does not change the cost).
      live.clear();
      for (int p = 0; p < 2 * N; ++p)
        if (max_component(S.E[p / 2]) > 0) live.push_back(p);
      const int L = static_cast<int>(live.size());
      Hgn.resize(L, L);
      gl.resize(L);
      for (int a = 0; a < L; ++a) {
        gl(a) = S.grad(live[a]);
        for (int b = 0; b < L; ++b) Hgn(a, b) = H(live[a], live[b]);
      }
      double hmax = L > 0 ? Hgn.diagonal().maxCoeff() : 0;
      // Gauss–Newton decrement ½ gᵀH⁻¹g: the decrease a full Gauss–Newton step would bring if the model held.
      double dec = 0;
      if (L > 0 && hmax > 0) {
        Eigen::MatrixXd Hr = Hgn;
        Hr.diagonal().array() += 1e-12 * hmax;  // tiny ridge: H is semi-definite where lights do not matter
        dec = 0.5 * gl.dot(Eigen::LDLT<Eigen::MatrixXd>(Hr).solve(gl));
      }
      R.decrement = S.cost > 0 ? std::max(0.0, dec) / S.cost : 0;
      D = Hgn.diagonal().cwiseMax(1e-12 * hmax);  // Marquardt scaling, floored for flat directions
      // The step's model adds the horizon curvature (2×2 per light) to the Gauss–Newton matrix.
      Hfull = Hgn;
      for (int a = 0; a < L; ++a)
        for (int b = 0; b < L; ++b)
          if (live[a] / 2 == live[b] / 2) Hfull(a, b) += S.hor(3 * (live[a] / 2) + live[a] % 2 + live[b] % 2);
    }
    R.last_decrease = last;
    if (S.cost == 0 || live.empty() || gl.squaredNorm() == 0) {
      R.converged = true;
      R.termination = S.cost == 0 ? "converged: exact fit" : "converged: zero gradient";
      break;
    }
    // Stopping rule (see optimize.h): the smooth test — the last step and a full Gauss–Newton step each
    // gain less than tol — or the kink-limited one: the last kWindow accepted steps together gained less than tol.
    const int h = static_cast<int>(history.size());
    const double window_gain = h > kWindow ? (history[h - 1 - kWindow] - S.cost) / S.cost : 1.0;
    const bool smooth = last < tol && R.decrement < tol;
    if (smooth || window_gain < tol) {
      R.converged = true;
      R.termination = smooth ? fmt::format(
                                   "converged: last step gained {:.2g} and a Gauss–Newton step would gain {:.2g} "
                                   "of the cost (< {:.0e})",
                                   last, R.decrement, tol)
                             : fmt::format(
                                   "converged: the last {} steps gained {:.2g} of the cost (< {:.0e}); "
                                   "Gauss–Newton decrement {:.2g}",
                                   kWindow, window_gain, tol, R.decrement);
      break;
    }
    if (R.iterations >= max_iterations) {
      R.termination = fmt::format("iteration cap {} (the last {} steps gained {:.2g} of the cost)", max_iterations,
                                  kWindow, window_gain);
      break;
    }
    if (lambda > kMaxLambda) {
      R.converged = R.decrement < tol;
      R.termination = fmt::format("{}: no step lowers the cost (damping {:.0e}); Gauss–Newton decrement {:.2g}",
                                  R.converged ? "converged" : "stalled", lambda, R.decrement);
      break;
    }
    Eigen::MatrixXd A = Hfull;
    A.diagonal() += lambda * D;
    Eigen::LLT<Eigen::MatrixXd> llt(A);
    if (llt.info() != Eigen::Success) {
      lambda *= nu;
      nu *= 2;
      continue;
    }  // indefinite model: damp more
    Eigen::VectorXd step = -llt.solve(gl);
    double pred = -(gl.dot(step) + 0.5 * step.dot(Hfull * step));
    std::vector<Vec3> nd = S.dirs;
    for (size_t a = 0; a < live.size(); ++a) {
      int i = live[a] / 2;
      nd[i] += (live[a] % 2 == 0 ? S.F.t[i] : S.F.s[i]) * step(a);
    }
    for (auto& d : nd) d = normalize(d);
    State T = evaluate_state(P, nd, S.E);
    ++R.iterations;
    double actual = S.cost - T.cost;
    if (actual > 0 && pred > 0) {
      double rho = actual / pred;
      lambda = std::max(kMinLambda, lambda * std::max(1.0 / 3.0, 1.0 - std::pow(2 * rho - 1, 3)));
      nu = 2;
      last = actual / S.cost;
      S = std::move(T);
      fresh = true;
      history.push_back(S.cost);
    } else {
      lambda *= nu;
      nu *= 2;
    }
  }
  R.dirs = S.dirs;
  R.E = S.E;
  R.cost = S.cost;
  return R;
}

double cost_of(const Problem& P, const std::vector<Light>& lights) {
  std::vector<Vec3> d, E;
  for (const auto& l : lights) {
    d.push_back(normalize(l.direction));
    E.push_back(l.irradiance);
  }
  return cost_and_gradient(P, frames_of(d), E, nullptr);
}

std::vector<Light> to_lights(const StageResult& s) {
  std::vector<Light> out(s.dirs.size());
  for (size_t i = 0; i < out.size(); ++i) {
    out[i].direction = normalize(s.dirs[i]);
    out[i].irradiance = s.E[i];
  }
  return out;
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
        if (c > bc) {
          bc = c;
          best = i;
        }
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
  if (desc.max_iterations < 1)
    fail(ErrorKind::Value, "optimiser: max_iterations must be ≥ 1 (got {})", desc.max_iterations);
  if (!(desc.tolerance > 0) || !(desc.coarse_tolerance > 0))
    fail(ErrorKind::Value, "optimiser: tolerances must be positive (got {}, {})", desc.tolerance,
         desc.coarse_tolerance);
  for (const auto& l : initial)
    if (!(length(l.direction) > 0) || !(l.irradiance.x >= 0 && l.irradiance.y >= 0 && l.irradiance.z >= 0))
      fail(ErrorKind::Value, "optimiser: an initial light has a zero direction or negative irradiance");
  auto t0 = std::chrono::steady_clock::now();
  OptimizeReport rep;
  const int N = static_cast<int>(initial.size());
  Problem full = make_problem(normals, ground_truth, desc.floor_fraction);
  rep.initial_cost = cost_of(full, initial);
  std::vector<Light> lights = initial;
  double best = rep.initial_cost;
  // Coarse to fine: levels 3 and 4 (1280 and 5120 normals), each converged to the coarse tolerance from
  // the last, where the level is ≥ 10× over-determined (3M residuals ≥ 10 · 2N direction parameters…
  // counted as 5N with the irradiance) and smaller than half the full set; a stage is kept only if it
  // lowers the cost on the full set.
  if (desc.coarse_to_fine) {
    for (int level : {3, 4}) {
      auto coarse = sphere::icosphere_face_centres(level);
      if (2 * coarse.size() > normals.size() || 3 * coarse.size() < 10 * 5 * static_cast<size_t>(N)) continue;
      Problem cp = make_problem(coarse, irradiance_ground_truth(env, coarse), desc.floor_fraction);
      std::vector<Vec3> d, E;
      for (const auto& l : lights) {
        d.push_back(normalize(l.direction));
        E.push_back(l.irradiance);
      }
      auto s = solve_stage(cp, d, E, desc.coarse_tolerance, desc.max_iterations);
      rep.coarse_iterations += s.iterations;
      auto cand = to_lights(s);
      double c = cost_of(full, cand);
      if (c < best) {
        best = c;
        lights = cand;
      }
      report(desc.progress, "optimise", level == 3 ? 0.3 : 0.6);
    }
  }
  StageResult fin;
  for (int round = 0; round < 4; ++round) {
    std::vector<Vec3> d, E;
    for (const auto& l : lights) {
      d.push_back(normalize(l.direction));
      E.push_back(l.irradiance);
    }
    fin = solve_stage(full, d, E, desc.tolerance, desc.max_iterations);
    rep.final_iterations += fin.iterations;
    lights = to_lights(fin);
    if (desc.min_separation_deg <= 0) break;
    LightSet tmp;
    tmp.lights = lights;
    if (merge_close_lights(tmp, desc.min_separation_deg * kPi / 180.0) == 0) break;
    lights = tmp.lights;
  }
  LightSet set;
  set.method = "optimize";
  set.lights = lights;
  rep.iterations = rep.coarse_iterations + rep.final_iterations;
  rep.final_cost = fin.cost;
  rep.last_decrease = fin.last_decrease;
  rep.decrement = fin.decrement;
  rep.converged = fin.converged;
  rep.termination = fin.termination;
  for (const auto& l : lights) rep.dark_lights += max_component(l.irradiance) <= 0;
  voronoi_regions(env, set);
  rank_for_shadows(set);
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  report(desc.progress, "optimise", 1.0);
  if (out_report) *out_report = rep;
  return set;
}

void check_normals_level(int level) {
  if (level < kMinNormalsLevel || level > kMaxNormalsLevel)
    fail(ErrorKind::Value, "optimiser: normals level must be in [{}, {}] (got {})", kMinNormalsLevel, kMaxNormalsLevel,
         level);
}

LightSet initial_lights(const sphere::EnvMap& env, const OptimizeDesc& desc) {
  CutDesc cd;
  cd.count = desc.count;
  if (desc.init == "variance-cut") return variance_cut(env, cd);
  if (desc.init == "median-cut") return median_cut(env, cd);
  fail(ErrorKind::Value, "optimiser: unknown initialisation \"{}\" (variance-cut, median-cut)", desc.init);
}

LightSet optimize_lights(const sphere::EnvMap& env, const OptimizeDesc& desc, OptimizeReport* out_report) {
  validate_probe(env, desc.count);
  check_normals_level(desc.normals_level);
  auto normals = sphere::icosphere_face_centres(desc.normals_level);
  auto gt = irradiance_ground_truth(env, normals);
  LightSet init = initial_lights(env, desc);
  return optimize_lights_from(env, normals, gt, init.lights, desc, out_report);
}

}  // namespace ibl::lights
