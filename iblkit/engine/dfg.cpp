#include "iblkit/engine/dfg.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::engine {

Vec2 dfg(double mu, double roughness, int n) {
  mu = std::clamp(mu, 1e-6, 1.0);
  const double a = roughness * roughness, a2 = a * a, sv = std::sqrt(1 - mu * mu);
  const Vec3 v{sv, 0, mu};
  const int nt = std::max(2, n), np = std::max(1, n / 2);
  const double gv = std::sqrt(mu * mu * (1 - a2) + a2);
  double scale = 0, bias = 0;
  for (int j = 0; j < nt; ++j) {
    // u2 = 1 − (1 − s)⁴ with s on the midpoint grid: the GGX inverse CDF squeezes the near-horizon
    // half vectors (which reflect grazing v into the hemisphere, with the weight 1/(n·h)) into
    // 1 − u2 ~ α²(n·h)²; the substitution puts grid points there. du2/ds = 4(1 − s)³.
    const double sj = (j + 0.5) / nt, u2 = 1 - std::pow(1 - sj, 4), jac = 4 * std::pow(1 - sj, 3);
    const double cos2 = (1 - u2) / (1 + (a2 - 1) * u2), nh = std::sqrt(cos2), sh = std::sqrt(std::max(0.0, 1 - cos2));
    // n·l = 2(v·h)(n·h) − μ > 0 ⇔ cos φ > μ(1 − 2 nh²)/(2 nh sv sh): the row's φ ∈ [0, φ_max]. The
    // midpoint rule runs over that interval only, where the integrand is smooth.
    double phi_max = kPi;
    if (sv * sh > 1e-12) {
      const double c = mu * (1 - 2 * cos2) / (2 * nh * sv * sh);
      if (c >= 1) continue;
      if (c > -1) phi_max = std::acos(c);
    } else if (2 * mu * nh * nh - mu <= 0) {
      continue;
    }
    double rs = 0, rb = 0;
    for (int i = 0; i < np; ++i) {
      const double phi = phi_max * (i + 0.5) / np;
      const Vec3 h{sh * std::cos(phi), sh * std::sin(phi), nh};
      const double vh = dot(v, h);
      const double nl = 2 * vh * nh - mu;  // l = 2(v·h)h − v, n·l = l.z
      if (nl <= 0 || vh <= 0) continue;
      const double V = 0.5 / (nl * gv + mu * std::sqrt(nl * nl * (1 - a2) + a2));
      const double w = 4 * V * nl * vh / nh;
      const double fc = std::pow(1 - vh, 5);
      rs += w * (1 - fc);
      rb += w * fc;
    }
    const double share = jac * phi_max / kPi / np;  // the row's φ measure over the full [0, π]
    scale += rs * share;
    bias += rb * share;
  }
  return {scale / nt, bias / nt};
}

Image dfg_table(const DfgDesc& d) {
  if (d.size < 4 || d.size > 1024) fail(ErrorKind::Value, "DFG table size {} outside 4..1024", d.size);
  if (d.n < 8 || d.n > 2048) fail(ErrorKind::Value, "DFG quadrature n {} outside 8..2048", d.n);
  Image out(d.size, d.size, 3);
  parallel_for(0, d.size, [&](int64_t j) {
    const double rho = (j + 0.5) / d.size;
    for (int i = 0; i < d.size; ++i) {
      Vec2 sb = dfg((i + 0.5) / d.size, rho, d.n);
      float* p = out.pixel(i, static_cast<int>(j));
      p[0] = float(sb.x), p[1] = float(sb.y), p[2] = 0;
    }
  });
  return out;
}

}  // namespace ibl::engine
