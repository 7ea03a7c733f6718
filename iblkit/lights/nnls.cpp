#include "iblkit/lights/nnls.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

namespace ibl::lights {

namespace {

// x_F = argmin on the free set F (x_B = 0): H_FF x_F = b_F, by LDLᵀ with a tiny ridge so that two
// identical columns (two lights in one direction) do not make it singular.
Eigen::VectorXd solve_free(const Eigen::MatrixXd& H, const Eigen::VectorXd& b, const std::vector<int>& F,
                           double ridge) {
  const int m = static_cast<int>(F.size());
  Eigen::MatrixXd A(m, m);
  Eigen::VectorXd r(m);
  for (int a = 0; a < m; ++a) {
    r(a) = b(F[a]);
    for (int c = 0; c <= a; ++c) A(a, c) = H(F[a], F[c]);  // F ascending: (F[a], F[c]) is in the lower triangle
    A(a, a) += ridge;
  }
  return Eigen::LDLT<Eigen::MatrixXd, Eigen::Lower>(A).solve(r);
}

}  // namespace

NnlsReport nnls(const Eigen::MatrixXd& H, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  const int n = static_cast<int>(b.size());
  NnlsReport rep;
  if (x.size() != n) x = Eigen::VectorXd::Zero(n);
  x = x.cwiseMax(0.0);
  if (n == 0) {
    rep.kkt = true;
    return rep;
  }
  const double hmax = H.diagonal().cwiseAbs().maxCoeff();
  constexpr double kRidge = 1e-13;  // relative to the largest diagonal entry: far below any real curvature
  const double ridge = kRidge * hmax + 1e-300;
  constexpr double kKkt = 1e-11;  // relative KKT tolerance on the gradient of the bound variables
  const double tol = kKkt * std::max(b.cwiseAbs().maxCoeff(), 1e-300);
  const int max_solves = 3 * n + 20;  // Lawson–Hanson ends in finitely many steps; this only guards round-off cycling
  std::vector<char> free(n), skip(n, 0);
  for (int i = 0; i < n; ++i) free[i] = x(i) > 0;
  int just_added = -1;
  while (rep.solves < max_solves) {
    // Inner loop: the minimiser z on the free set; while it is not positive, step from x (feasible) towards
    // it as far as feasibility allows and move the blocking variables to the bound set.
    while (rep.solves < max_solves) {
      std::vector<int> F;
      for (int i = 0; i < n; ++i)
        if (free[i]) F.push_back(i);
      if (F.empty()) {
        x.setZero();
        break;
      }
      Eigen::VectorXd z = solve_free(H, b, F, ridge);
      ++rep.solves;
      const int m = static_cast<int>(F.size());
      int blocking = -1;
      double alpha = 1;
      for (int a = 0; a < m; ++a)
        if (z(a) <= 0) {
          double t = x(F[a]) / (x(F[a]) - z(a));
          if (blocking < 0 || t < alpha) {
            alpha = t;
            blocking = a;
          }
        }
      if (blocking < 0) {
        x.setZero();
        for (int a = 0; a < m; ++a) x(F[a]) = z(a);
        if (just_added >= 0)
          std::fill(skip.begin(), skip.end(), 0);  // progress made: every bound variable may enter again
        just_added = -1;
        break;
      }
      if (just_added >= 0 && F[blocking] == just_added && x(just_added) == 0) {
        // Round-off: the variable just freed cannot enter although its gradient was positive. Leave x
        // as it was and let the next-best bound variable try.
        free[just_added] = 0;
        skip[just_added] = 1;
        just_added = -1;
        break;
      }
      for (int a = 0; a < m; ++a) {
        int i = F[a];
        x(i) += alpha * (z(a) - x(i));
        if (a == blocking || x(i) <= 0) {
          x(i) = 0;
          free[i] = 0;
        }
      }
      just_added = -1;
    }
    // KKT: w = b − Hx; the bound variable with the largest positive w enters.
    Eigen::VectorXd w = b - H.selfadjointView<Eigen::Lower>() * x;
    int best = -1;
    double bw = tol;
    for (int i = 0; i < n; ++i)
      if (!free[i] && !skip[i] && w(i) > bw) {
        bw = w(i);
        best = i;
      }
    if (best < 0) {
      rep.kkt = true;
      return rep;
    }
    free[best] = 1;
    just_added = best;
  }
  return rep;
}

}  // namespace ibl::lights
