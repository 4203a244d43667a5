// The random numbers a stochastic BSDF evaluation consumes: a seedable,
// deterministic stream of doubles in [0, 1) (SplitMix64; Steele, Lea and
// Flood 2014, "Fast splittable pseudorandom number generators").
//
// Parameters
//   seed  any 64-bit value; equal seeds give equal streams, so the path
//         tracer can make a stochastic evaluation repeatable (and the same
//         across the wavelengths of one path) by seeding from its sampler.
#pragma once

#include <cstdint>

namespace skyfarm::material {

class RandomSequence {
 public:
  explicit RandomSequence(std::uint64_t seed) : state_(seed) {}

  double next() {
    state_ += 0x9E3779B97F4A7C15ULL;
    std::uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    // The top 53 bits as a double in [0, 1).
    return static_cast<double>(z >> 11) * 0x1.0p-53;
  }

 private:
  std::uint64_t state_;
};

}  // namespace skyfarm::material
