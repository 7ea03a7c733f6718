// Counter-based random numbers: every pixel sample gets its own stream keyed by (seed, probe,
// pixel, sample), so results never depend on thread scheduling ("same seed, same bytes").
#pragma once
#include <cstdint>

namespace ibl::lab {

// SplitMix64 finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mix.
constexpr uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

constexpr uint64_t stream_key(uint64_t seed, uint64_t probe, uint64_t pixel, uint64_t sample) {
  return mix64(mix64(mix64(mix64(seed) ^ probe) ^ pixel) ^ sample);
}

class Rng {
 public:
  explicit Rng(uint64_t key) : state_(key) {}
  // Uniform in [0,1).
  double uniform() {
    state_ += 0x9e3779b97f4a7c15ull;
    return static_cast<double>(mix64(state_) >> 11) * 0x1.0p-53;
  }

 private:
  uint64_t state_;
};

}  // namespace ibl::lab
