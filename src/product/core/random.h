#pragma once
// Deterministic random numbers, the one random stream of the project (the simulator's
// disturbances, the dataset design, the network's initialization, machines and days, ball-bar
// and surface noise, the check bar's noise): the std::mt19937_64 engine, whose output sequence the
// C++ standard fixes, with this project's own mapping to uniform and normal variates (the
// standard distributions are implementation-defined), so every shipped file and every result is
// identical across standard libraries.
//   Uniform()      (u64 >> 11) * 2^-53, uniform in [0, 1) with 53 random bits;
//   Uniform(a, b)  a + (b - a) Uniform();
//   Normal()       standard normal by the Box-Muller transform (G. E. P. Box and M. E. Muller,
//                  "A note on the generation of random normal deviates", Ann. Math. Statist. 29,
//                  1958): from u1 in (0, 1) and u2 in [0, 1), r = sqrt(-2 ln u1), the pair
//                  r cos(2 pi u2), r sin(2 pi u2), both used, in that order.
// Every draw of Uniform takes one engine output; Normal takes two at every second call.
#include <cmath>
#include <cstdint>
#include <random>

namespace whirl {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  /// Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  /// Standard normal by the Box-Muller transform (both values used, in order).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = Uniform();
    while (u1 <= 0.0) u1 = Uniform();
    const double u2 = Uniform();
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 6.283185307179586476925 * u2;
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

/// SplitMix64 mix of a seed and a stream index: independent seeds for rows of a dataset.
inline std::uint64_t MixSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace whirl
