// Counter-based random numbers for the sensor model: SplitMix64 (Steele, Lea & Flood 2014), the same
// generator as lab/rng.h. capture/ sits below lab/ (docs/architecture.md) and core/ has no rng.h yet,
// so the sensor keeps this small local copy; it moves to core/rng.h when that exists.
#pragma once
#include <cmath>
#include <cstdint>

namespace ibl::capture {

// SplitMix64 finaliser: a bijective 64-bit mix.
constexpr uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

class Rng {
 public:
  explicit Rng(uint64_t key) : state_(key) {}
  // Uniform in [0,1).
  double uniform() {
    state_ += 0x9e3779b97f4a7c15ull;
    return static_cast<double>(mix64(state_) >> 11) * 0x1.0p-53;
  }
  // Standard normal (Box–Muller; one of the pair).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }

 private:
  uint64_t state_;
};

}  // namespace ibl::capture
