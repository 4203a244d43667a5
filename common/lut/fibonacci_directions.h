// Deterministic, evenly spread directions over the sphere (no random
// numbers: a set built twice is bit-identical).
//
// Spherical Fibonacci points (Marques et al. 2013, "Spherical Fibonacci
// point sets for illumination integrals", eq. 2): for i < n,
//   z_i = 1 - (2 i + 1) / n,  phi_i = 2 pi i / Phi  (Phi the golden ratio),
// each representing the solid angle 4 pi / n.
#pragma once
#include <cmath>
#include <glm/vec3.hpp>
#include <vector>

#include "common/core/constants.h"

namespace skyfarm::lut {

inline std::vector<glm::dvec3> fibonacci_sphere(int n) {
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));  // 2 pi (1 - 1/Phi)
  std::vector<glm::dvec3> w(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, s = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * i;
    w[static_cast<std::size_t>(i)] = {s * std::cos(phi), s * std::sin(phi), z};
  }
  return w;
}

}  // namespace skyfarm::lut
