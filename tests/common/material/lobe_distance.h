// Binned lobes of the walk comparisons: the bin of an exit direction
// (uniform in cos(theta) and phi over the upper hemisphere), and the L1
// distance between two binned lobes (the same bins), each normalised to
// unit energy: 0 for the same shape, 2 for lobes that share no bin.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

namespace skyfarm::material::testing {

inline constexpr int kThetaBins = 6;
inline constexpr int kPhiBins = 8;
inline constexpr int kBins = kThetaBins * kPhiBins;

// The bin of w, or -1 below the surface.
inline int bin_of(const glm::dvec3& w) {
  constexpr double kPi = 3.14159265358979323846;
  if (w.z <= 0.0) return -1;
  const int t = std::min(kThetaBins - 1, static_cast<int>(w.z * kThetaBins));
  const double phi = std::atan2(w.y, w.x) + kPi;
  const int p = std::min(kPhiBins - 1, static_cast<int>(phi / (2.0 * kPi) * kPhiBins));
  return t * kPhiBins + p;
}

inline double l1_distance(const std::vector<double>& a, const std::vector<double>& b) {
  double sa = 0.0;
  double sb = 0.0;
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) {
    sa += a[k];
    sb += b[k];
  }
  double d = 0.0;
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) d += std::abs(a[k] / sa - b[k] / sb);
  return d;
}

}  // namespace skyfarm::material::testing
