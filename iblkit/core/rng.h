// iblkit's one random number generator (as pbrt-v4's util/rng.h is pbrt's): counter-based streams, so
// that every sample's numbers are keyed by what it is — (seed, probe, pixel, sample) — and a result
// never depends on thread scheduling or on the standard library ("same seed, same bytes").
//
// SplitMix64 (Steele, Lea & Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014): the
// state advances by the golden-ratio increment and each output is the state through mix64, a bijective
// 64-bit finaliser.
#pragma once
#include <cmath>
#include <cstdint>
#include <iterator>
#include <utility>

namespace ibl {

constexpr uint64_t kGoldenGamma = 0x9e3779b97f4a7c15ull;

// The SplitMix64 finaliser: a bijective 64-bit mix.
constexpr uint64_t mix64(uint64_t z) {
  z += kGoldenGamma;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// The key of a stream: mix64(… mix64(mix64(seed) ^ k₁) ^ k₂ …) over the keys given.
constexpr uint64_t stream_key(uint64_t seed) { return mix64(seed); }
template <typename... Keys>
constexpr uint64_t stream_key(uint64_t seed, uint64_t first, Keys... rest) {
  uint64_t z = mix64(mix64(seed) ^ first);
  ((z = mix64(z ^ static_cast<uint64_t>(rest))), ...);
  return z;
}

class Rng {
 public:
  explicit constexpr Rng(uint64_t key) : state_(key) {}
  // The next 64 random bits.
  constexpr uint64_t next() {
    state_ += kGoldenGamma;
    return mix64(state_);
  }
  // Uniform in [0, 1), 53 bits.
  constexpr double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  // Standard normal: Box–Muller, one of the pair (two uniforms per draw).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
  // Uniform in [0, n) for n ≥ 1, without modulo bias (Lemire's multiply-and-reject, 2019).
  uint64_t below(uint64_t n) {
    unsigned __int128 m = static_cast<unsigned __int128>(next()) * n;
    uint64_t low = static_cast<uint64_t>(m);
    if (low < n) {
      const uint64_t threshold = (0 - n) % n;
      while (low < threshold) {
        m = static_cast<unsigned __int128>(next()) * n;
        low = static_cast<uint64_t>(m);
      }
    }
    return static_cast<uint64_t>(m >> 64);
  }

 private:
  uint64_t state_;
};

// Fisher–Yates shuffle with iblkit's Rng: the same order on every standard library (std::shuffle's
// result is the library's choice).
template <typename RandomIt>
void shuffle(RandomIt first, RandomIt last, Rng& rng) {
  const auto n = static_cast<uint64_t>(std::distance(first, last));
  for (uint64_t i = n; i > 1; --i) {
    const uint64_t j = rng.below(i);
    using std::swap;
    swap(first[i - 1], first[j]);
  }
}

}  // namespace ibl
