// The L1 distance between two binned lobes (the same bins), each normalised
// to unit energy: 0 for the same shape, 2 for lobes that share no bin.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

namespace skyfarm::material::testing {

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
