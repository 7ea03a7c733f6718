#include "iblkit/sh/convolve.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/enum_names.h"
#include "iblkit/core/error.h"
#include "iblkit/sh/basis.h"

namespace ibl::sh {

namespace {
void check_bands(int bands) {
  if (bands < 1 || bands > kMaxBands) fail(ErrorKind::Value, "SH bands must be in 1..{} (got {})", kMaxBands, bands);
}
}  // namespace

std::vector<double> clamped_cosine_zh(int bands) {
  check_bands(bands);
  std::vector<double> a(bands, 0.0);
  for (int l = 0; l < bands; ++l) {
    if (l == 0)
      a[l] = kPi;
    else if (l == 1)
      a[l] = 2.0 * kPi / 3.0;
    else if (l % 2 == 0) {
      // l! / (2^l ((l/2)!)²) through log-gamma.
      double r = std::exp(std::lgamma(l + 1.0) - l * std::log(2.0) - 2.0 * std::lgamma(l / 2 + 1.0));
      double sign = ((l / 2 - 1) % 2 == 0) ? 1.0 : -1.0;
      a[l] = 2.0 * kPi * sign / ((l + 2.0) * (l - 1.0)) * r;
    }
  }
  return a;
}

std::vector<double> phong_zh(int bands, double s) {
  check_bands(bands);
  if (!std::isfinite(s) || s < 0) fail(ErrorKind::Value, "Phong exponent must be finite and ≥ 0 (got {})", s);
  // I[j][l] = I_l(s + j) for j + l < bands: row j needs I_{l}(s+j+1) and I_{l−1}(s+j).
  std::vector<std::vector<double>> I(bands, std::vector<double>(bands, 0.0));
  for (int j = 0; j < bands; ++j) {
    I[j][0] = 1.0 / (s + j + 1.0);
    if (bands > 1) I[j][1] = 1.0 / (s + j + 2.0);
  }
  for (int l = 1; l + 1 < bands; ++l)
    for (int j = 0; j + l + 1 < bands; ++j) I[j][l + 1] = ((2.0 * l + 1.0) * I[j + 1][l] - l * I[j][l - 1]) / (l + 1.0);
  std::vector<double> out(bands);
  for (int l = 0; l < bands; ++l) out[l] = (s + 1.0) * I[0][l];
  return out;
}

Coeffs convolve_zonal(const Coeffs& c, const std::vector<double>& k) {
  if (static_cast<int>(k.size()) < c.bands)
    fail(ErrorKind::Value, "zonal kernel has {} bands, coefficients {}", k.size(), c.bands);
  Coeffs out = c;
  for (int l = 0; l < c.bands; ++l)
    for (int m = -l; m <= l; ++m) out.c[index(l, m)] = c.c[index(l, m)] * k[l];
  return out;
}

Coeffs irradiance(const Coeffs& radiance) { return convolve_zonal(radiance, clamped_cosine_zh(radiance.bands)); }

Vec3 irradiance_at(const Coeffs& radiance, Vec3 n) {
  if (radiance.bands <= 0) return {};
  double y[kMaxBands * kMaxBands];
  eval_basis(radiance.bands, n, y);
  auto a = clamped_cosine_zh(radiance.bands);
  Vec3 e;
  for (int l = 0; l < radiance.bands; ++l)
    for (int m = -l; m <= l; ++m) e += radiance.c[index(l, m)] * (a[l] * y[index(l, m)]);
  return e;
}

namespace {
constexpr EnumName<Window> kWindowNames[] = {{Window::None, "none"},
                                             {Window::Hanning, "hanning"},
                                             {Window::Lanczos, "lanczos"},
                                             {Window::Deringing, "deringing"}};
}  // namespace

std::string window_name(Window w) { return name_of(kWindowNames, w); }
Window parse_window(const std::string& name) { return parse_enum(kWindowNames, name, "SH window"); }

std::vector<double> window_weights(Window w, int bands, double width) {
  check_bands(bands);
  if (width < 0 || !std::isfinite(width)) fail(ErrorKind::Value, "window width must be ≥ 0 (got {})", width);
  double W = width > 0 ? width : bands;
  std::vector<double> h(bands, 1.0);
  for (int l = 0; l < bands; ++l) {
    double t = l / W;
    switch (w) {
      case Window::None:
        break;
      case Window::Hanning:
        h[l] = t >= 1 ? 0.0 : 0.5 * (1.0 + std::cos(kPi * t));
        break;
      case Window::Lanczos:
        h[l] = l == 0 ? 1.0 : (t >= 1 ? 0.0 : std::sin(kPi * t) / (kPi * t));
        break;
      case Window::Deringing:
        fail(ErrorKind::Value, "the deringing window depends on the coefficients: use apply_window");
    }
  }
  return h;
}

std::vector<Vec3> fibonacci_directions(int n) {
  std::vector<Vec3> d(n);
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = golden * i;
    d[i] = {r * std::cos(phi), r * std::sin(phi), z};
  }
  return d;
}

namespace {

// Minimum over test directions and channels of the irradiance of `radiance` windowed by h,
// given the basis values at the directions (K per direction).
double min_irradiance(const Coeffs& radiance, const std::vector<double>& h, const std::vector<double>& basis,
                      int npts) {
  const int K = coeff_count(radiance.bands);
  auto a = clamped_cosine_zh(radiance.bands);
  std::vector<Vec3> e(K);
  for (int l = 0; l < radiance.bands; ++l)
    for (int m = -l; m <= l; ++m) e[index(l, m)] = radiance.c[index(l, m)] * (a[l] * h[l]);
  double lo = 1e300;
  for (int i = 0; i < npts; ++i) {
    Vec3 s;
    const double* y = basis.data() + static_cast<size_t>(i) * K;
    for (int k = 0; k < K; ++k) s += e[k] * y[k];
    lo = std::min({lo, s.x, s.y, s.z});
  }
  return lo;
}

}  // namespace

Coeffs apply_window(const Coeffs& radiance, const WindowDesc& desc, WindowReport* report) {
  radiance.validate("SH coefficients");
  const int bands = radiance.bands;
  std::vector<double> h;
  double lambda = 0;
  if (desc.kind != Window::Deringing) {
    h = window_weights(desc.kind, bands, desc.width);
  } else {
    if (desc.test_points < 16) fail(ErrorKind::Value, "deringing needs ≥ 16 test points (got {})", desc.test_points);
    const int K = coeff_count(bands), n = desc.test_points;
    auto dirs = fibonacci_directions(n);
    std::vector<double> basis(static_cast<size_t>(n) * K);
    for (int i = 0; i < n; ++i) eval_basis(bands, dirs[i], basis.data() + static_cast<size_t>(i) * K);
    auto filter = [&](double lam) {
      std::vector<double> f(bands);
      for (int l = 0; l < bands; ++l) f[l] = 1.0 / (1.0 + lam * l * l * (l + 1.0) * (l + 1.0));
      return f;
    };
    // Only the DC term survives as λ → ∞, whose irradiance π c₀₀ Y₀₀ is ≥ 0 when c₀₀ ≥ 0.
    h = filter(0);
    if (min_irradiance(radiance, h, basis, n) < 0 && bands > 1) {
      double lo = 1e-12, hi = 1e-12;
      while (min_irradiance(radiance, filter(hi), basis, n) < 0 && hi < 1e12) hi *= 10;
      for (int it = 0; it < 60; ++it) {  // bisection on log λ to a relative 1e-5 or so
        double mid = std::sqrt(lo * hi);
        if (min_irradiance(radiance, filter(mid), basis, n) < 0)
          lo = mid;
        else
          hi = mid;
        if (hi / lo < 1.00001) break;
      }
      lambda = hi;
      h = filter(hi);
    }
  }
  Coeffs out = convolve_zonal(radiance, h);
  if (report) {
    report->weights = h;
    report->lambda = lambda;
    auto dirs = fibonacci_directions(std::max(16, desc.test_points));
    const int K = coeff_count(bands);
    std::vector<double> basis(dirs.size() * K);
    for (size_t i = 0; i < dirs.size(); ++i) eval_basis(bands, dirs[i], basis.data() + i * K);
    double mean = std::max(1e-300, kPi * luminance(radiance.c[0]) / std::sqrt(kFourPi) * 1.0);
    std::vector<double> ones(bands, 1.0);
    report->min_irradiance_before = min_irradiance(radiance, ones, basis, static_cast<int>(dirs.size())) / mean;
    report->min_irradiance_after = min_irradiance(radiance, h, basis, static_cast<int>(dirs.size())) / mean;
  }
  return out;
}

}  // namespace ibl::sh
