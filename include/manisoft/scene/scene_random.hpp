// Portable random draws for scene sampling (the same (task, setting, index, seed) gives
// the identical scene from the g++ and the clang build): std::mt19937_64's raw output (specified
// by the standard) turned into numbers by our own code (the standard distributions are not
// portable), and the seed derivation that keeps training and evaluation scenes apart.
//
// Splits: engine_seed() hashes (task, setting, index, seed, attempt) with splitmix64 and then
// writes the split into the top bit (train 0, eval 1). A training scene's engine seed therefore
// never equals an evaluation scene's, whatever index and seed either was asked with: no
// evaluation scene can be drawn into a training dataset.
#pragma once

#include <cstdint>
#include <random>

#include "manisoft/core/error.hpp"
#include "manisoft/scene/scene_spec.hpp"

namespace manisoft::scene {

/// splitmix64's finalizer (Steele, Lea, Flood 2014): a bijective 64-bit mix.
inline std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

inline constexpr std::uint64_t split_bit = 1ull << 63;

/// The std::mt19937_64 seed of draw `attempt` of scene (split, task, setting, index, seed).
inline std::uint64_t engine_seed(Split split, Task task, Setting setting, std::uint64_t index, std::uint64_t seed, int attempt) {
  std::uint64_t h = mix64(0x4D616E69536F6674ull);  // "ManiSoft"
  h = mix64(h ^ static_cast<std::uint64_t>(task));
  h = mix64(h ^ (static_cast<std::uint64_t>(setting) + 16));
  h = mix64(h ^ index);
  h = mix64(h ^ seed);
  h = mix64(h ^ static_cast<std::uint64_t>(attempt));
  return (h & ~split_bit) | (split == Split::eval ? split_bit : 0);
}

/// Uniform draws from the raw engine.
class Draw {
 public:
  explicit Draw(std::uint64_t seed) : engine_(seed) {}
  /// [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// [lo, hi)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// An integer in [lo, hi] (inclusive).
  int integer(int lo, int hi) {
    if (hi < lo) manisoft::detail::fail("Draw::integer: empty range [", lo, ", ", hi, "]");
    const std::uint64_t n = static_cast<std::uint64_t>(hi - lo) + 1;
    return lo + static_cast<int>((engine_() >> 11) % n);
  }
  bool chance(double p) { return uniform() < p; }
  template <typename Vector>
  const auto& pick(const Vector& v) {
    if (v.empty()) manisoft::detail::fail("Draw::pick: nothing to pick from");
    return v[static_cast<std::size_t>(integer(0, static_cast<int>(v.size()) - 1))];
  }

 private:
  std::mt19937_64 engine_;
};

}  // namespace manisoft::scene
