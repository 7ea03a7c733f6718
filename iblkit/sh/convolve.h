// Convolution of SH radiance with zonal kernels (irradiance, Phong lobes) and windowing against
// ringing.
//
// References
//  [1] Ramamoorthi & Hanrahan, "An efficient representation for irradiance environment maps",
//      SIGGRAPH 2001, eq. 8–9: Â_l of the clamped cosine.
//  [2] Ramamoorthi & Hanrahan, "A signal-processing framework for reflection", ACM TOG 2004, §5:
//      the normalised Phong lobe's coefficients.
//  [3] Sloan, "Stupid spherical harmonics (SH) tricks", GDC 2008, §"Windowing": Hanning and
//      Lanczos (σ-factor) windows.
//  [4] Sloan, "Deringing spherical harmonics", SIGGRAPH Asia 2017 technical brief: the smallest
//      smoothing that removes the negative lobes of the reconstructed irradiance.
#pragma once
#include <string>
#include <vector>

#include "iblkit/sh/coeffs.h"

namespace ibl::sh {

// Convolution factors Λ_l (one per band): convolving f with a zonal kernel h multiplies f_lm by
//   Λ_l = √(4π/(2l+1)) h_l = 2π ∫_{-1}^{1} h(t) P_l(t) dt     (Funk–Hecke).

// Clamped cosine max(cos θ, 0) [1]:
//   Â_0 = π, Â_1 = 2π/3, Â_l = 0 for odd l > 1, and for even l
//   Â_l = 2π (−1)^{l/2−1} / ((l+2)(l−1)) · l! / (2^l ((l/2)!)²)   (π/4, −π/24, π/64, …).
std::vector<double> clamped_cosine_zh(int bands);

// Normalised Phong lobe (s+1)/(2π) max(cos θ, 0)^s, which integrates to 1 over the sphere [2]:
//   Λ_l = (s+1) I_l(s),  I_l(s) = ∫₀¹ t^s P_l(t) dt,
// with I_0(s) = 1/(s+1), I_1(s) = 1/(s+2) and, from (l+1)P_{l+1} = (2l+1) t P_l − l P_{l−1},
//   I_{l+1}(s) = ((2l+1) I_l(s+1) − l I_{l−1}(s)) / (l+1).
// Λ_0 = 1 for every s; s = 1 gives Â_l/π. Throws for s < 0 or non-finite s.
std::vector<double> phong_zh(int bands, double exponent);

// f_lm · kernel[l] for l < c.bands (kernel needs at least c.bands entries).
Coeffs convolve_zonal(const Coeffs& c, const std::vector<double>& zh_or_filter);

// Irradiance E(n) = ∫ L(ω) max(n·ω, 0) dω as SH: radiance convolved with Â_l.
Coeffs irradiance(const Coeffs& radiance);
// E(n) straight from radiance coefficients.
Vec3 irradiance_at(const Coeffs& radiance, Vec3 n);

// ---- windowing -------------------------------------------------------------------------------

enum class Window {
  None,       // w_l = 1
  Hanning,    // w_l = (1 + cos(π l / W)) / 2 [3]
  Lanczos,    // w_l = sin(π l / W) / (π l / W) [3]
  Deringing,  // w_l = 1 / (1 + λ l²(l+1)²), the smallest λ with non-negative irradiance [4]
};
std::string window_name(Window w);
// "none", "hanning", "lanczos", "deringing"; throws ibl::Error on anything else.
Window parse_window(const std::string& name);

struct WindowDesc {
  Window kind = Window::None;
  double width = 0;        // Hanning/Lanczos W; 0 picks W = bands (the last band keeps a small weight)
  int test_points = 4096;  // deringing: Fibonacci directions where irradiance must be ≥ 0
};

struct WindowReport {
  std::vector<double> weights;       // w_l applied
  double lambda = 0;                 // deringing's λ (0 when nothing had to be smoothed)
  double min_irradiance_before = 0;  // min over test points and channels of E(n)/mean E, before
  double min_irradiance_after = 0;   // … and after the window
};

// Per-band weights of a Hanning or Lanczos window (Deringing needs the coefficients: use apply_window).
std::vector<double> window_weights(Window w, int bands, double width = 0);

// Windows radiance coefficients. Deringing derivation: among filters h_l applied to f, the one that
// minimises ‖h∗f − f‖² + λ‖∇²(h∗f)‖² (∇² Y_lm = −l(l+1) Y_lm) is
//   ┌──────────────────────────────┐
//   │ h_l = 1 / (1 + λ l²(l+1)²)   │
//   └──────────────────────────────┘
// and λ is found by bisection on log λ as the smallest value for which the irradiance of the
// windowed radiance is ≥ 0 (per channel) at every test point.
Coeffs apply_window(const Coeffs& radiance, const WindowDesc& desc, WindowReport* report = nullptr);

// The same Fibonacci directions the deringing search tests (n points, nearly equal areas).
std::vector<Vec3> fibonacci_directions(int n);

}  // namespace ibl::sh
