#include "iblkit/nearfield/basis.h"

#include <Eigen/Dense>
#include <cmath>

#include "iblkit/core/error.h"

namespace ibl::nearfield {

namespace {

double hat(double x) { return std::max(0.0, 1.0 - std::abs(x)); }

constexpr int kQ = 4;  // dual nodes per spacing

// Number of unknowns a_0 … a_{n−1}: nodes k/kQ with |k| < kQ·(half width).
int dual_unknowns(Basis b) { return static_cast<int>(kQ * dual_half_width(b)); }

// ∫ β1(kQ·x − k) β(x − j) dx, exactly: both factors are polynomials on every quarter-integer interval
// (degree ≤ 3 in total), so 3-point Gauss–Legendre on each is exact.
double gram(Basis b, int k, int j) {
  static const double gx[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, gw[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  const double step = 1.0 / kQ;
  double lo = std::max((k - 1) * step, j - primal_half_width(b)),
         hi = std::min((k + 1) * step, j + primal_half_width(b));
  double acc = 0;
  for (double a = lo; a < hi - 1e-12; a += step) {
    double c = a + 0.5 * step, r = 0.5 * step;
    for (int q = 0; q < 3; ++q) {
      double x = c + r * gx[q];
      acc += r * gw[q] * hat(kQ * x - k) * primal(b, x - j);
    }
  }
  return acc;
}

std::vector<double> solve_dual(Basis b) {
  const int n = dual_unknowns(b), K = n - 1;
  const int nj = static_cast<int>(std::ceil(dual_half_width(b) + primal_half_width(b)));  // shifts that overlap
  // Rows: biorthogonality Σ_k a_|k| G(k, j) = δ_j0 for j = 0..nj−1, then the partition of unity
  // Σ_m φ'(x − m) = 1 at the node offsets r/kQ, r = 0..kQ−1 (which makes Σ_mn E_mn the irradiance
  // behind an open aperture, so that the reconstruction keeps the power of any light field).
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(nj + kQ, n);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nj + kQ);
  rhs(0) = 1;
  for (int j = 0; j < nj; ++j)
    for (int k = -K; k <= K; ++k) M(j, std::abs(k)) += gram(b, k, j);
  for (int r = 0; r < kQ; ++r) {
    for (int k = -K; k <= K; ++k)
      if (((k - r) % kQ + kQ) % kQ == 0) M(nj + r, std::abs(k)) += 1;
    rhs(nj + r) = 1;
  }
  // Underdetermined: the minimum-norm solution.
  Eigen::VectorXd a = M.completeOrthogonalDecomposition().solve(rhs);
  if ((M * a - rhs).norm() > 1e-10)
    fail(ErrorKind::Internal, "dual filter of the {} basis: inconsistent conditions", basis_name(b));
  return std::vector<double>(a.data(), a.data() + a.size());
}

}  // namespace

double primal(Basis b, double x) {
  x = std::abs(x);
  if (b == Basis::Bilinear) return x < 1 ? 1 - x : 0;
  if (x <= 0.5) return 0.75 - x * x;
  if (x < 1.5) return 0.5 * (x - 1.5) * (x - 1.5);
  return 0;
}

double primal_half_width(Basis b) { return b == Basis::Bilinear ? 1.0 : 1.5; }
double dual_half_width(Basis b) { return b == Basis::Bilinear ? 1.5 : 2.0; }

const std::vector<double>& dual_coefficients(Basis b) {
  static const std::vector<double> lin = solve_dual(Basis::Bilinear), quad = solve_dual(Basis::Biquadratic);
  return b == Basis::Bilinear ? lin : quad;
}

double dual(Basis b, double x) {
  const auto& a = dual_coefficients(b);
  const int K = dual_unknowns(b) - 1;
  // Only the two hats whose nodes bracket x are non-zero.
  double y = kQ * x;
  int k0 = static_cast<int>(std::floor(y));
  double acc = 0;
  for (int k = k0; k <= k0 + 1; ++k)
    if (k >= -K && k <= K) acc += a[static_cast<size_t>(std::abs(k))] * hat(y - k);
  return acc;
}

double shift_invariance_error(double theta0, double w, bool two_d) {
  // cos⁴θ of the ray from the origin of S to (u, v) on the plane at distance 1: 1/(1 + u² + v²)².
  auto g = [](double u, double v) {
    double r = 1 + u * u + v * v;
    return 1 / (r * r);
  };
  const double u0 = std::tan(theta0);
  const double ulo = u0 - w / 2, uhi = u0 + w / 2;
  // g decreases with |u| and |v|: the maximum is at the point of F closest to the axis, the minimum
  // at the farthest corner (or end).
  const double unear = (ulo <= 0 && uhi >= 0) ? 0 : std::min(std::abs(ulo), std::abs(uhi));
  const double ufar = std::max(std::abs(ulo), std::abs(uhi));
  const double vfar = two_d ? w / 2 : 0;
  return (g(unear, 0) - g(ufar, vfar)) / g(u0, 0);
}

}  // namespace ibl::nearfield
