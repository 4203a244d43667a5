#include "common/clouds/value_noise.h"

#include <algorithm>
#include <array>

#include <glm/common.hpp>

namespace skyfarm {

void ValueNoiseCell::fetch(std::uint64_t seed, std::int64_t ix, std::int64_t iy, std::int64_t iz) {
  if (valid && ix == x && iy == y && iz == z) return;
  for (int i = 0; i < 8; ++i)
    c[static_cast<std::size_t>(i)] = lattice_value(seed, ix + (i & 1), iy + ((i >> 1) & 1), iz + (i >> 2));
  x = ix, y = iy, z = iz;
  valid = true;
}

double value_noise_box_max(std::uint64_t seed, const glm::dvec3& lo, const glm::dvec3& hi, ValueNoiseCell& cache) {
  const glm::dvec3 cell = glm::floor(0.5 * (lo + hi));
  cache.fetch(seed, static_cast<std::int64_t>(cell.x), static_cast<std::int64_t>(cell.y),
              static_cast<std::int64_t>(cell.z));
  const auto fade = [](double t) { return quintic_fade(std::clamp(t, 0.0, 1.0)); };
  const std::array<double, 2> u{fade(lo.x - cell.x), fade(hi.x - cell.x)};
  const std::array<double, 2> v{fade(lo.y - cell.y), fade(hi.y - cell.y)};
  const std::array<double, 2> w{fade(lo.z - cell.z), fade(hi.z - cell.z)};
  const auto lerp = [](double t, double a, double b) { return a + t * (b - a); };
  const std::array<double, 8>& c = cache.c;
  double m = 0.0;
  for (const double a : u) {
    // Blend along x first, as value_noise does: four edges, then the box's corners.
    const double e00 = lerp(a, c[0], c[1]), e10 = lerp(a, c[2], c[3]), e01 = lerp(a, c[4], c[5]),
                 e11 = lerp(a, c[6], c[7]);
    for (const double b : v) {
      const double f0 = lerp(b, e00, e10), f1 = lerp(b, e01, e11);
      for (const double g : w) m = std::max(m, lerp(g, f0, f1));
    }
  }
  return m;
}

double value_noise_box_max(std::uint64_t seed, const glm::dvec3& lo, const glm::dvec3& hi) {
  ValueNoiseCell cache;
  return value_noise_box_max(seed, lo, hi, cache);
}

}  // namespace skyfarm
