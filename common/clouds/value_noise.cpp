#include "common/clouds/value_noise.h"

#include <algorithm>

namespace skyfarm {

double value_noise_cell_max(std::uint64_t seed, std::int64_t cx, std::int64_t cy, std::int64_t cz, int n) {
  double m = 0.0;
  const std::int64_t x0 = cx * n, y0 = cy * n, z0 = cz * n;
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) m = std::max(m, lattice_value(seed, x0 + i, y0 + j, z0 + k));
  return m;
}

}  // namespace skyfarm
