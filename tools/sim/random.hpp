// SPDX-License-Identifier: MIT
// Deterministic random numbers: the same seed gives the same recording on every machine and
// standard library (std::normal_distribution is implementation-defined, so we roll our own).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace msgraphs::sim {

class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  /// An independent stream for (seed, a, b), e.g. robot and time chunk.
  static Random Stream(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0) {
    // Hash the three numbers (not just add them): neighbouring (a, b) must not give streams that
    // are shifted copies of each other, which additive seeding of splitmix64 would.
    return Random(Mix(seed ^ Mix(a ^ Mix(b + 0x632BE59BD9B4E019ull))));
  }
  static std::uint64_t Mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }

  std::uint64_t Next() {  // splitmix64
    return Mix(state_ += 0x9E3779B97F4A7C15ull);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }  ///< [0, 1)
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  int Index(int n) { return static_cast<int>(Uniform() * n); }
  double Normal() {  // Box-Muller
    const double u1 = 1.0 - Uniform(), u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }
  double Normal(double sigma) { return sigma * Normal(); }
  bool Chance(double p) { return Uniform() < p; }

 private:
  std::uint64_t state_;
};

}  // namespace msgraphs::sim
