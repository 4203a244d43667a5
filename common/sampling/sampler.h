// Deterministic random numbers: every number a path uses is a pure function
// of (job seed, pixel, sample index, dimension), so a work unit rendered twice,
// on another worker, or split into passes in any order gives the same bits.
//
// Counter-based: u = to_unit(hash(seed, pixel, sample, dimension)), where the
// hash chains MurmurHash3's 64-bit finaliser (Appleby 2011) over the four
// keys, each step adding a distinct odd constant so that (a, b) and (b, a)
// differ.  No state is carried from one sample to the next.
#pragma once
#include <cstdint>

namespace skyfarm {

// MurmurHash3 fmix64: a bijective avalanche of 64 bits.
constexpr std::uint64_t fmix64(std::uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  k *= 0xc4ceb9fe1a85ec53ULL;
  k ^= k >> 33;
  return k;
}

constexpr std::uint64_t hash_keys(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample,
                                  std::uint64_t dimension) {
  std::uint64_t h = fmix64(seed + 0x9e3779b97f4a7c15ULL);
  h = fmix64(h ^ (pixel + 0xbf58476d1ce4e5b9ULL));
  h = fmix64(h ^ (sample + 0x94d049bb133111ebULL));
  h = fmix64(h ^ (dimension + 0x2545f4914f6cdd1dULL));
  return h;
}

// The top 53 bits as a double in [0, 1).
constexpr double to_unit(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

// The random numbers of one camera sample.  Dimensions are consumed in order
// by next(); a stream at a fixed dimension base gives an unbounded sequence
// for loops whose length is random (delta tracking).
class Sampler {
 public:
  Sampler(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample)
      : seed_(seed), pixel_(pixel), sample_(sample) {}

  double get(std::uint64_t dimension) const { return to_unit(hash_keys(seed_, pixel_, sample_, dimension)); }
  double next() { return get(dimension_++); }
  std::uint64_t dimension() const { return dimension_; }
  void set_dimension(std::uint64_t d) { dimension_ = d; }

 private:
  std::uint64_t seed_, pixel_, sample_;
  std::uint64_t dimension_ = 0;
};

}  // namespace skyfarm
