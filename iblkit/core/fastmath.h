// Fast float approximations for hot loops, with their error bounds.
#pragma once
#include <cmath>

namespace ibl {

// atan(x) for |x| ≤ 1: Abramowitz & Stegun 4.4.49 (Hastings), |error| ≤ 1e−5 rad.
inline float atan_unit(float x) {
  float x2 = x * x;
  return x * (0.9998660f + x2 * (-0.3302995f + x2 * (0.1801410f + x2 * (-0.0851330f + x2 * 0.0208351f))));
}

// atan2(y, x) with |error| ≤ 1e−5 rad (a 10⁻³-pixel shift in a 1024-wide lat-long). Branch-free
// so that loops over arrays of directions vectorise; atan2(0, 0) = 0.
inline float fast_atan2(float y, float x) {
  constexpr float kPiF = 3.14159265358979f, kHalfPiF = 1.57079632679490f;
  float ax = std::abs(x), ay = std::abs(y);
  float mn = ax < ay ? ax : ay, mx = ax < ay ? ay : ax;
  float r = atan_unit(mn / (mx + 1e-30f));
  r = ay > ax ? kHalfPiF - r : r;
  r = x < 0 ? kPiF - r : r;
  return std::copysign(r, y);
}

}  // namespace ibl
