#include "iblkit/sh/basis.h"

#include <cmath>

#include "iblkit/core/error.h"

namespace ibl::sh {

namespace {

void check_bands(int bands) {
  if (bands < 1 || bands > kMaxBands) fail(ErrorKind::Value, "SH bands must be in 1..{} (got {})", kMaxBands, bands);
}

// K_lm for m ≥ 0 from log-gamma, so that l up to kMaxBands − 1 stays accurate.
double norm_constant_uncached(int l, int m) {
  double k = std::sqrt((2.0 * l + 1.0) / kFourPi * std::exp(std::lgamma(l - m + 1.0) - std::lgamma(l + m + 1.0)));
  return m == 0 ? k : std::sqrt(2.0) * k;
}

struct NormTable {
  double k[kMaxBands][kMaxBands] = {};
  NormTable() {
    for (int l = 0; l < kMaxBands; ++l)
      for (int m = 0; m <= l; ++m) k[l][m] = norm_constant_uncached(l, m);
  }
};
const NormTable& norms() {
  static const NormTable t;
  return t;
}

// Column m of P̃_lm(z) for l = m … bands−1 by the recurrence above, given pmm = P̃_mm = (2m−1)!!;
// emit(l, P̃_lm) receives each value.
template <typename Emit>
void legendre_column(int bands, int m, double z, double pmm, Emit&& emit) {
  double p2 = 0.0, p1 = 0.0, p0 = pmm;
  for (int l = m; l < bands; ++l) {
    if (l == m + 1) {
      p1 = p0;
      p0 = (2.0 * m + 1.0) * z * pmm;
    } else if (l > m + 1) {
      p2 = p1;
      p1 = p0;
      p0 = ((2.0 * l - 1.0) * z * p1 - (l + m - 1.0) * p2) / (l - m);
    }
    emit(l, p0);
  }
}

template <typename T>
void eval_basis_t(int bands, Vec3 d, T* out) {
  check_bands(bands);
  const NormTable& K = norms();
  const double x = d.x, y = d.y, z = d.z;
  // (C, S) = Re, Im (x + i y)^m; pmm = P̃_mm = (2m−1)!!.
  double C = 1.0, S = 0.0, pmm = 1.0;
  for (int m = 0; m < bands; ++m) {
    if (m > 0) {
      double c = C * x - S * y;
      S = C * y + S * x;
      C = c;
      pmm *= 2.0 * m - 1.0;
    }
    legendre_column(bands, m, z, pmm, [&](int l, double p) {
      double kp = K.k[l][m] * p;
      if (m == 0) {
        out[index(l, 0)] = static_cast<T>(kp);
      } else {
        out[index(l, m)] = static_cast<T>(kp * C);
        out[index(l, -m)] = static_cast<T>(kp * S);
      }
    });
  }
}

}  // namespace

void eval_basis(int bands, Vec3 d, double* out) { eval_basis_t(bands, d, out); }
void eval_basis(int bands, Vec3 d, float* out) { eval_basis_t(bands, d, out); }
std::vector<double> eval_basis(int bands, Vec3 d) {
  check_bands(bands);
  std::vector<double> y(coeff_count(bands));
  eval_basis(bands, d, y.data());
  return y;
}

double norm_constant(int l, int m) {
  if (l < 0 || l >= kMaxBands || m < 0 || m > l) fail(ErrorKind::Value, "no SH constant for l={} m={}", l, m);
  return norms().k[l][m];
}

void legendre_table(int bands, double z, double* out) {
  check_bands(bands);
  double pmm = 1.0;
  for (int m = 0; m < bands; ++m) {
    if (m > 0) pmm *= 2.0 * m - 1.0;
    legendre_column(bands, m, z, pmm, [&](int l, double p) { out[l * bands + m] = p; });
  }
}

void gauss_legendre(int n, std::vector<double>* nodes, std::vector<double>* weights) {
  if (n < 1) fail(ErrorKind::Value, "Gauss–Legendre needs n ≥ 1 (got {})", n);
  nodes->assign(n, 0.0);
  weights->assign(n, 0.0);
  for (int i = 0; i < (n + 1) / 2; ++i) {
    // Chebyshev-like first guess, then Newton on P_n [3].
    // P_n(z) and its derivative, by Bonnet's recurrence.
    auto pn_and_derivative = [n](double z, double* dp) {
      double p0 = 1.0, p1 = 0.0;
      for (int j = 1; j <= n; ++j) {
        double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * j - 1.0) * z * p1 - (j - 1.0) * p2) / j;
      }
      *dp = n * (z * p0 - p1) / (z * z - 1.0);
      return p0;
    };
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double dz = pn_and_derivative(z, &dp) / dp;
      z -= dz;
      if (std::abs(dz) < 1e-16) break;
    }
    pn_and_derivative(z, &dp);  // the derivative at the converged node, for the weight
    double w = 2.0 / ((1.0 - z * z) * dp * dp);
    (*nodes)[i] = -z;
    (*nodes)[n - 1 - i] = z;
    (*weights)[i] = (*weights)[n - 1 - i] = w;
  }
  if (n % 2 == 1) (*nodes)[n / 2] = 0.0;
}

SphereQuadrature exact_quadrature(int degree) {
  if (degree < 0) fail(ErrorKind::Value, "quadrature degree must be ≥ 0 (got {})", degree);
  // n Gauss points integrate z^k exactly for k ≤ 2n − 1; degree + 1 equally spaced φ integrate
  // cos(mφ), sin(mφ) exactly for |m| ≤ degree.
  int nz = degree / 2 + 1, nphi = degree + 1;
  std::vector<double> z, wz;
  gauss_legendre(nz, &z, &wz);
  SphereQuadrature q;
  for (int i = 0; i < nz; ++i) {
    double s = std::sqrt(std::max(0.0, 1.0 - z[i] * z[i]));
    for (int j = 0; j < nphi; ++j) {
      double phi = kTwoPi * (j + 0.5) / nphi;
      q.directions.push_back({s * std::cos(phi), s * std::sin(phi), z[i]});
      q.weights.push_back(wz[i] * kTwoPi / nphi);
    }
  }
  return q;
}

}  // namespace ibl::sh
