// The detail that erodes a cloud layer's edges: periodic Worley (1996)
// cellular noise, baked once per layer into a small tiled 3-D table and read
// back by trilinear interpolation (Schneider 2015 bakes his detail noise into
// 32^3 textures the same way).
//
// One period of the table spans kCells cells of the coarse octave (one
// feature point per cell, placed by hashing the seed and the cell) and twice
// as many of the fine one; the value at a point is the distance to the
// nearest feature point in cell units (F1, wrapped around the period),
// 0.625 F1_coarse + 0.375 F1_fine, clamped to [0, 1]: near 0 at the
// billows' centres, towards 1 in the gaps between them, which erosion eats.
//
// Parameters
//   seed   the layer's seed (the same table on every worker)
// lookup(x): x in table samples (kSize per period), any real value; the
// result is in [0, 1].
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace skyfarm {

class TiledWorleyNoise {
 public:
  static constexpr int kSize = 32;   // samples per period and axis (power of two)
  static constexpr int kCells = 4;   // coarse Worley cells per period and axis

  explicit TiledWorleyNoise(std::uint64_t seed);

  double lookup(const glm::dvec3& x) const {
    const double fx = std::floor(x.x), fy = std::floor(x.y), fz = std::floor(x.z);
    const double u = x.x - fx, v = x.y - fy, w = x.z - fz;
    // Wrapping in 64-bit integers: exact for any point the doubles hold.
    constexpr std::int64_t kMask = kSize - 1;
    const auto i0 = static_cast<std::int64_t>(fx) & kMask, j0 = static_cast<std::int64_t>(fy) & kMask,
               k0 = static_cast<std::int64_t>(fz) & kMask;
    const std::int64_t i1 = (i0 + 1) & kMask, j1 = (j0 + 1) & kMask, k1 = (k0 + 1) & kMask;
    const auto at = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      return static_cast<double>(table_[static_cast<std::size_t>((k * kSize + j) * kSize + i)]);
    };
    const auto lerp = [](double t, double a, double b) { return a + t * (b - a); };
    return lerp(w, lerp(v, lerp(u, at(i0, j0, k0), at(i1, j0, k0)), lerp(u, at(i0, j1, k0), at(i1, j1, k0))),
                lerp(v, lerp(u, at(i0, j0, k1), at(i1, j0, k1)), lerp(u, at(i0, j1, k1), at(i1, j1, k1))));
  }

 private:
  std::vector<float> table_;
};

}  // namespace skyfarm
