// Value noise on the integer lattice (Perlin 1985; Ebert et al., "Texturing
// and Modeling", ch. 2): a pseudo-random value in [0, 1) at each lattice
// point, blended inside each cell with Perlin's (2002) quintic fade
// 6t^5 - 15t^4 + 10t^3 (C2: no creases in the clouds).
//
// The blend is trilinear with faded weights in [0, 1], a convex combination
// of the cell's 8 corner values: the noise anywhere in a cell is at most the
// largest of its corners.  That is the cloud layer's majorant.
//
// Lattice points are 64-bit integers and the hash is pure integer
// arithmetic (MurmurHash3's finaliser over a mix of the coordinates and the
// seed): the same bits on every machine, for points up to 2^63 cells away
// (the wind's drift since J2000 reaches 1e10 m, ~1e7 cells).
#pragma once
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

// The largest lattice value over the cell [c, c + 1]^3 of a lattice that is
// `n` times coarser, i.e. over the points n c + (0..n) on each axis: the
// bound of the noise (at n times the frequency) over that coarse cell.
double value_noise_cell_max(std::uint64_t seed, std::int64_t cx, std::int64_t cy, std::int64_t cz, int n);

}  // namespace skyfarm
