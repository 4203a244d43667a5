#include "common/geometry/icosphere.h"

#include <cmath>
#include <glm/geometric.hpp>
#include <stdexcept>
#include <unordered_map>

namespace skyfarm {

TriangleMesh icosphere(int subdivisions) {
  if (subdivisions < 0 || subdivisions > 8) throw std::invalid_argument("icosphere: subdivisions must be 0..8");
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<glm::dvec3> p = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0},
                               {0, -1, phi}, {0, 1, phi}, {0, -1, -phi}, {0, 1, -phi},
                               {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  for (auto& v : p) v = glm::normalize(v);
  std::vector<std::uint32_t> idx = {0, 11, 5, 0, 5,  1,  0,  1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                                    4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9,  4, 3,  4,  2, 3, 2, 6, 3,
                                    6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6, 2, 10, 8,  6, 7, 9, 8, 1};
  for (int s = 0; s < subdivisions; ++s) {
    std::unordered_map<std::uint64_t, std::uint32_t> midpoint;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      const auto i = static_cast<std::uint32_t>(p.size());
      p.push_back(glm::normalize(p[a] + p[b]));
      midpoint.emplace(key, i);
      return i;
    };
    std::vector<std::uint32_t> next;
    next.reserve(idx.size() * 4);
    for (std::size_t t = 0; t < idx.size(); t += 3) {
      const std::uint32_t a = idx[t], b = idx[t + 1], c = idx[t + 2];
      const std::uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    idx = std::move(next);
  }
  std::vector<glm::dvec3> normals = p;
  return TriangleMesh(std::move(p), std::move(idx), std::move(normals));
}

}  // namespace skyfarm
