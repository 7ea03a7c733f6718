#include "iblkit/sh/rotate.h"

#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/sh/basis.h"

namespace ibl::sh {

RotationMatrix rotation_matrix(int bands, const Mat3& R) {
  if (bands < 1 || bands > kMaxBands) fail(ErrorKind::Value, "SH bands must be in 1..{} (got {})", kMaxBands, bands);
  RotationMatrix M;
  M.bands = bands;
  M.blocks.resize(bands);
  for (int l = 0; l < bands; ++l) M.blocks[l].assign((2 * l + 1) * (2 * l + 1), 0.0);
  const SphereQuadrature q = exact_quadrature(2 * (bands - 1));
  const Mat3 Rt = R.transposed();
  std::vector<double> y(coeff_count(bands)), yr(coeff_count(bands));
  for (size_t i = 0; i < q.directions.size(); ++i) {
    const Vec3 d = q.directions[i];
    eval_basis(bands, d, y.data());
    eval_basis(bands, normalize(Rt * d), yr.data());
    const double w = q.weights[i];
    for (int l = 0; l < bands; ++l) {
      const int n = 2 * l + 1, base = l * l;
      double* B = M.blocks[l].data();
      for (int a = 0; a < n; ++a) {
        const double ya = w * y[base + a];
        for (int b = 0; b < n; ++b) B[a * n + b] += ya * yr[base + b];
      }
    }
  }
  return M;
}

Coeffs rotate(const Coeffs& c, const RotationMatrix& M) {
  if (M.bands < c.bands) fail(ErrorKind::Value, "rotation matrix has {} bands, coefficients {}", M.bands, c.bands);
  Coeffs out(c.bands);
  for (int l = 0; l < c.bands; ++l) {
    const int n = 2 * l + 1, base = l * l;
    const double* B = M.blocks[l].data();
    for (int a = 0; a < n; ++a) {
      Vec3 s;
      for (int b = 0; b < n; ++b) s += c.c[base + b] * B[a * n + b];
      out.c[base + a] = s;
    }
  }
  return out;
}

Coeffs rotate(const Coeffs& c, const Mat3& R) { return rotate(c, rotation_matrix(c.bands, R)); }

std::vector<double> rotate_zh(const std::vector<double>& zh, Vec3 axis) {
  const int bands = static_cast<int>(zh.size());
  std::vector<double> y = eval_basis(bands, normalize(axis));
  std::vector<double> out(coeff_count(bands));
  for (int l = 0; l < bands; ++l) {
    const double s = std::sqrt(kFourPi / (2 * l + 1)) * zh[l];
    for (int m = -l; m <= l; ++m) out[index(l, m)] = s * y[index(l, m)];
  }
  return out;
}

Mat3 rotation_from_z(Vec3 axis) {
  Vec3 a = normalize(axis);
  Vec3 z{0, 0, 1};
  Vec3 v = cross(z, a);
  double s = length(v), c = dot(z, a);
  if (s < 1e-12) return c > 0 ? Mat3::identity() : Mat3::rotation({1, 0, 0}, kPi);
  return Mat3::rotation(v, std::atan2(s, c));
}

}  // namespace ibl::sh
