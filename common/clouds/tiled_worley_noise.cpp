#include "common/clouds/tiled_worley_noise.h"

#include <algorithm>
#include <limits>

#include "common/sampling/sampler.h"

namespace skyfarm {

namespace {

// One feature point per cell of a lattice of `cells` per period, in cell
// units inside its cell, placed by hashing the seed and the cell.
std::vector<glm::dvec3> feature_points(std::uint64_t seed, int cells) {
  std::vector<glm::dvec3> points(static_cast<std::size_t>(cells * cells * cells));
  for (std::size_t cell = 0; cell < points.size(); ++cell) {
    const std::uint64_t h = hash_keys(seed, static_cast<std::uint64_t>(cells), cell, 0);
    points[cell] = {to_unit(fmix64(h ^ 1)), to_unit(fmix64(h ^ 2)), to_unit(fmix64(h ^ 3))};
  }
  return points;
}

// F1 at point p (in cell units): the distance to the nearest of the feature
// points of the 27 cells around p's, each wrapped around the period.
double worley_f1(const std::vector<glm::dvec3>& features, int cells, const glm::dvec3& p) {
  const int cx = static_cast<int>(std::floor(p.x)), cy = static_cast<int>(std::floor(p.y)),
            cz = static_cast<int>(std::floor(p.z));
  const auto wrap = [cells](int i) { return ((i % cells) + cells) % cells; };
  double best2 = std::numeric_limits<double>::infinity();
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = cx + dx, y = cy + dy, z = cz + dz;
        const auto cell = static_cast<std::size_t>((wrap(z) * cells + wrap(y)) * cells + wrap(x));
        const glm::dvec3 e = glm::dvec3(x, y, z) + features[cell] - p;
        best2 = std::min(best2, e.x * e.x + e.y * e.y + e.z * e.z);
      }
  return std::sqrt(best2);
}

}  // namespace

TiledWorleyNoise::TiledWorleyNoise(std::uint64_t seed) : table_(static_cast<std::size_t>(kSize * kSize * kSize)) {
  const std::vector<glm::dvec3> coarse_features = feature_points(seed, kCells);
  const std::vector<glm::dvec3> fine_features = feature_points(seed, 2 * kCells);
  for (int k = 0; k < kSize; ++k)
    for (int j = 0; j < kSize; ++j)
      for (int i = 0; i < kSize; ++i) {
        const glm::dvec3 unit{(i + 0.5) / kSize, (j + 0.5) / kSize, (k + 0.5) / kSize};  // in periods
        const double coarse = worley_f1(coarse_features, kCells, unit * static_cast<double>(kCells));
        const double fine = worley_f1(fine_features, 2 * kCells, unit * static_cast<double>(2 * kCells));
        table_[static_cast<std::size_t>((k * kSize + j) * kSize + i)] =
            static_cast<float>(std::clamp(0.625 * coarse + 0.375 * fine, 0.0, 1.0));
      }
}

}  // namespace skyfarm
