// Deterministic, evenly spread direction sets for the LUT integrals over the
// sphere and the hemisphere (no random numbers: a table built twice is
// bit-identical).
//
// Spherical Fibonacci points (Marques et al. 2013, "Spherical Fibonacci
// point sets for illumination integrals", eq. 2): for i < n,
//   z_i = 1 - (2 i + 1) / n,  phi_i = 2 pi i / Phi  (Phi the golden ratio),
// each representing the solid angle 4 pi / n.  The cosine-weighted
// hemisphere set lifts the Fibonacci spiral on the unit disk
// (r_i = sqrt((i + 1/2) / n), Vogel 1979) to the hemisphere (Malley's
// method), so each point stands for the same share of projected solid angle:
// int_H L cos dw ~ (pi / n) sum_i L(w_i).
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

inline std::vector<glm::dvec3> fibonacci_cosine_hemisphere(int n) {
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
  std::vector<glm::dvec3> w(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double r2 = (i + 0.5) / n, r = std::sqrt(r2), phi = golden_angle * i;
    w[static_cast<std::size_t>(i)] = {r * std::cos(phi), r * std::sin(phi), std::sqrt(1.0 - r2)};
  }
  return w;
}

}  // namespace skyfarm::lut
