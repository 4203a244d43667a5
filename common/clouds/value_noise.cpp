#include "common/clouds/value_noise.h"

#include <algorithm>
#include <array>

#include <glm/common.hpp>

namespace skyfarm {

double value_noise_box_max(std::uint64_t seed, const glm::dvec3& lo, const glm::dvec3& hi) {
  const glm::dvec3 cell = glm::floor(0.5 * (lo + hi));
  const auto ix = static_cast<std::int64_t>(cell.x), iy = static_cast<std::int64_t>(cell.y),
             iz = static_cast<std::int64_t>(cell.z);
  const auto fade = [](double t) { return quintic_fade(std::clamp(t, 0.0, 1.0)); };
  const std::array<double, 2> u{fade(lo.x - cell.x), fade(hi.x - cell.x)};
  const std::array<double, 2> v{fade(lo.y - cell.y), fade(hi.y - cell.y)};
  const std::array<double, 2> w{fade(lo.z - cell.z), fade(hi.z - cell.z)};
  const auto lerp = [](double t, double a, double b) { return a + t * (b - a); };
  const double c000 = lattice_value(seed, ix, iy, iz), c100 = lattice_value(seed, ix + 1, iy, iz);
  const double c010 = lattice_value(seed, ix, iy + 1, iz), c110 = lattice_value(seed, ix + 1, iy + 1, iz);
  const double c001 = lattice_value(seed, ix, iy, iz + 1), c101 = lattice_value(seed, ix + 1, iy, iz + 1);
  const double c011 = lattice_value(seed, ix, iy + 1, iz + 1), c111 = lattice_value(seed, ix + 1, iy + 1, iz + 1);
  double m = 0.0;
  for (const double a : u) {
    // Blend along x first: four edges, then the corners of the box.
    const double e00 = lerp(a, c000, c100), e10 = lerp(a, c010, c110), e01 = lerp(a, c001, c101),
                 e11 = lerp(a, c011, c111);
    for (const double b : v) {
      const double f0 = lerp(b, e00, e10), f1 = lerp(b, e01, e11);
      for (const double c : w) m = std::max(m, lerp(c, f0, f1));
    }
  }
  return m;
}

}  // namespace skyfarm
