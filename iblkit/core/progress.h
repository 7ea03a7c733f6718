// Progress reporting: the library calls a user callback; the CLI draws a bar.
#pragma once
#include <functional>
#include <string_view>

namespace ibl {

// fraction in [0,1] of the named stage. Must be cheap and thread-safe.
using ProgressFn = std::function<void(std::string_view stage, double fraction)>;

inline void report(const ProgressFn& fn, std::string_view stage, double fraction) {
  if (fn) fn(stage, fraction);
}

}  // namespace ibl
