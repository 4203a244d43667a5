// Value noise on the integer lattice (Perlin 1985; Ebert et al., "Texturing
// and Modeling", ch. 2): a pseudo-random value in [0, 1) at each lattice
// point, blended inside each cell with Perlin's (2002) quintic fade
// 6t^5 - 15t^4 + 10t^3 (C2: no creases in the clouds).
//
// The blend is trilinear in the faded coordinates, each monotone in its
// coordinate: over any box inside one cell the noise is largest at one of
// the box's corners.  That is the cloud layer's majorant.
//
// Lattice points are 64-bit integers and the hash is pure integer
// arithmetic (MurmurHash3's finaliser over a mix of the coordinates and the
// seed): the same bits on every machine, for points up to 2^63 cells away
// (the wind's drift since J2000 reaches 1e10 m, ~1e7 cells).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>

#include <glm/vec3.hpp>

#include "common/sampling/sampler.h"

namespace skyfarm {

// The value in [0, 1) at a lattice point.
inline double lattice_value(std::uint64_t seed, std::int64_t x, std::int64_t y, std::int64_t z) {
  // Distinct odd multipliers and rotations keep (x, y, z) and its
  // permutations apart; fmix64 then avalanches every bit.
  const auto rotl = [](std::uint64_t v, int s) { return (v << s) | (v >> (64 - s)); };
  const std::uint64_t k = static_cast<std::uint64_t>(x) * 0x9e3779b97f4a7c15ULL +
                          rotl(static_cast<std::uint64_t>(y) * 0xbf58476d1ce4e5b9ULL, 21) +
                          rotl(static_cast<std::uint64_t>(z) * 0x94d049bb133111ebULL, 42);
  return to_unit(fmix64(k ^ seed));
}

inline double quintic_fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// The noise at x, in lattice units.
inline double value_noise(std::uint64_t seed, const glm::dvec3& x) {
  const double fx = std::floor(x.x), fy = std::floor(x.y), fz = std::floor(x.z);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy),
             iz = static_cast<std::int64_t>(fz);
  const double u = quintic_fade(x.x - fx), v = quintic_fade(x.y - fy), w = quintic_fade(x.z - fz);
  const auto lerp = [](double t, double a, double b) { return a + t * (b - a); };
  const double c000 = lattice_value(seed, ix, iy, iz), c100 = lattice_value(seed, ix + 1, iy, iz);
  const double c010 = lattice_value(seed, ix, iy + 1, iz), c110 = lattice_value(seed, ix + 1, iy + 1, iz);
  const double c001 = lattice_value(seed, ix, iy, iz + 1), c101 = lattice_value(seed, ix + 1, iy, iz + 1);
  const double c011 = lattice_value(seed, ix, iy + 1, iz + 1), c111 = lattice_value(seed, ix + 1, iy + 1, iz + 1);
  return lerp(w, lerp(v, lerp(u, c000, c100), lerp(u, c010, c110)), lerp(v, lerp(u, c001, c101), lerp(u, c011, c111)));
}

// The 8 lattice values of one cell, fetched once for the many boxes a
// majorant walk takes inside it.
struct ValueNoiseCell {
  std::int64_t x = 0, y = 0, z = 0;
  bool valid = false;
  std::array<double, 8> c{};  // index: dx + 2 dy + 4 dz
  // Holds the cell (ix, iy, iz) of `seed` afterwards (fetches when it did not).
  void fetch(std::uint64_t seed, std::int64_t ix, std::int64_t iy, std::int64_t iz);
};

// The largest value of the noise over the box [lo, hi] (lattice units),
// which must lie inside one lattice cell (faces included).  Inside a cell
// the noise is multilinear in (fade(x), fade(y), fade(z)) and the fade is
// monotone, so its maximum over the box is at one of the box's 8 corners:
// this is the exact maximum, not only a bound (up to rounding).  `cache`
// keeps the cell's lattice values between calls.
double value_noise_box_max(std::uint64_t seed, const glm::dvec3& lo, const glm::dvec3& hi, ValueNoiseCell& cache);
double value_noise_box_max(std::uint64_t seed, const glm::dvec3& lo, const glm::dvec3& hi);

}  // namespace skyfarm
