// Checks of the points, directions, boxes and numbers that enter the library, made once where they
// enter (docs/conventions.md, "Range of values"): finite, and no larger than kMaxCoordinate metres.
// Beyond that range float32 geometry (Embree, GL) loses all precision, and Embree rejects rays whose
// components are not finite.
#pragma once
#include <cmath>
#include <string_view>

#include <unistd.h>

#include "iblkit/core/error.h"
#include "iblkit/core/vec.h"

namespace ibl {

// Every coordinate of a point or a box, in metres, lies in [−kMaxCoordinate, kMaxCoordinate].
inline constexpr double kMaxCoordinate = 1e6;

inline bool is_finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool in_range(Vec3 v, double bound = kMaxCoordinate) {
  return std::abs(v.x) <= bound && std::abs(v.y) <= bound && std::abs(v.z) <= bound;  // false for NaN
}

// Fails (ErrorKind::Value) unless p is finite and within ±kMaxCoordinate on every axis; `what` names
// the parameter ("capture position", "camera eye").
inline void require_point(std::string_view what, Vec3 p) {
  if (!is_finite(p)) fail(ErrorKind::Value, "{} ({}, {}, {}) is not finite", what, p.x, p.y, p.z);
  if (!in_range(p))
    fail(ErrorKind::Value, "{} ({}, {}, {}) lies outside ±{:g} m, the supported range of coordinates", what, p.x, p.y,
         p.z, kMaxCoordinate);
}

// Fails unless d is finite, within ±kMaxCoordinate and not (0, 0, 0); returns d normalised.
inline Vec3 require_direction(std::string_view what, Vec3 d) {
  if (!is_finite(d)) fail(ErrorKind::Value, "{} ({}, {}, {}) is not finite", what, d.x, d.y, d.z);
  if (!in_range(d))
    fail(ErrorKind::Value, "{} ({}, {}, {}) has components beyond ±{:g}", what, d.x, d.y, d.z, kMaxCoordinate);
  double l = length(d);
  if (!(l > 1e-12)) fail(ErrorKind::Value, "{} ({}, {}, {}) has no direction (zero length)", what, d.x, d.y, d.z);
  return d / l;
}

// Fails unless both corners are points (require_point) and lo ≤ hi on every axis (lo < hi with `strict`).
inline void require_box(std::string_view what, Vec3 lo, Vec3 hi, bool strict = false) {
  require_point(fmt::format("{} corner", what), lo);
  require_point(fmt::format("{} corner", what), hi);
  for (int a = 0; a < 3; ++a)
    if (strict ? !(hi[a] > lo[a]) : !(hi[a] >= lo[a]))
      fail(ErrorKind::Value, "{} ({}, {}, {})–({}, {}, {}): max must {} min on axis {}", what, lo.x, lo.y, lo.z, hi.x,
           hi.y, hi.z, strict ? "exceed" : "be at least", "xyz"[a]);
}

// Fails unless v is a finite number in [lo, hi].
inline double require_number(std::string_view what, double v, double lo, double hi) {
  if (!std::isfinite(v)) fail(ErrorKind::Value, "{} = {} is not a finite number", what, v);
  if (v < lo || v > hi) fail(ErrorKind::Value, "{} = {:g} outside [{:g}, {:g}]", what, v, lo, hi);
  return v;
}

// This machine's physical memory in bytes (16 GB when the system does not say).
inline double physical_memory() {
  static const double bytes = [] {
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? double(pages) * double(size) : 16e9;
  }();
  return bytes;
}

// Fails (ErrorKind::Value) before an allocation of `count` items of `bytes_each` bytes that exceeds
// `limit` bytes (default: the physical memory), saying how much and what to change:
// "{what} would allocate 12.3 GB (more than the 8 GB allowed); {hint}".
inline void require_allocation(std::string_view what, double count, double bytes_each, std::string_view hint,
                               double limit = physical_memory()) {
  double b = count * bytes_each;
  if (!(b <= limit))
    fail(ErrorKind::Value, "{} would allocate {:.3g} GB (more than the {:.3g} GB allowed); {}", what, b / 1e9,
         limit / 1e9, hint);
}

}  // namespace ibl
