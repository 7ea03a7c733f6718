// Non-negative least squares on the normal equations: minimise ½ xᵀHx − bᵀx subject to x ≥ 0, for a
// symmetric positive semi-definite H (the Gram matrix AᵀA of a least-squares problem ‖Ax − y‖², with
// b = Aᵀy). The irradiance optimiser solves one per colour channel and iteration for the lights'
// irradiance at fixed directions (variable projection, optimize.cpp).
//
// References
//  [1] Lawson & Hanson, "Solving Least Squares Problems", 1974, ch. 23 (the active-set NNLS algorithm).
#pragma once
#include <Eigen/Core>

namespace ibl::lights {

struct NnlsReport {
  int solves = 0;    // linear solves on the free set (the algorithm's cost unit)
  bool kkt = false;  // ended with the Karush–Kuhn–Tucker conditions met (else: solve cap)
};

// Lawson–Hanson active set [1], warm-started from `x` (clipped to ≥ 0; its positive entries are the
// first free set, so a previous solution of a nearby problem takes one or two solves). H: n×n, only
// its lower triangle is read. On return x ≥ 0 and the KKT conditions hold to a relative tolerance:
// (b − Hx)_j = 0 where x_j > 0 and (b − Hx)_j ≤ 1e-11 · max|b| where x_j = 0.
NnlsReport nnls(const Eigen::MatrixXd& H, const Eigen::VectorXd& b, Eigen::VectorXd& x);

}  // namespace ibl::lights
