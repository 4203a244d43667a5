#include "common/assets/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>

namespace skyfarm::assets {

namespace {

struct PositionKey {
  std::array<std::uint64_t, 3> bits;
  bool operator==(const PositionKey&) const = default;
};

struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint64_t b : k.bits) h = (h ^ b) * 1099511628211ull ^ (b >> 29);
    return static_cast<std::size_t>(h);
  }
};

PositionKey key_of(const double* p) {
  PositionKey k;
  for (int i = 0; i < 3; ++i) {
    // -0 and +0 are the same point: join them.
    const double v = p[i] == 0.0 ? 0.0 : p[i];
    std::memcpy(&k.bits[static_cast<std::size_t>(i)], &v, sizeof v);
  }
  return k;
}

bool zero_area(const double* a, const double* b, const double* c) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  return n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
}

}  // namespace

MeshBounds mesh_bounds(const TriangleMesh& mesh) {
  MeshBounds b;
  if (mesh.vertex_count() == 0) return b;
  for (int i = 0; i < 3; ++i) {
    b.min[static_cast<std::size_t>(i)] = std::numeric_limits<double>::infinity();
    b.max[static_cast<std::size_t>(i)] = -std::numeric_limits<double>::infinity();
  }
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    for (std::size_t i = 0; i < 3; ++i) {
      b.min[i] = std::min(b.min[i], mesh.positions[3 * v + i]);
      b.max[i] = std::max(b.max[i], mesh.positions[3 * v + i]);
    }
  return b;
}

TriangleMesh canonicalize_mesh(const TriangleMesh& mesh) {
  const std::size_t n = mesh.vertex_count();
  // Each input vertex -> its first vertex with the same position.
  std::vector<std::uint32_t> same(n);
  std::unordered_map<PositionKey, std::uint32_t, PositionHash> first;
  first.reserve(n);
  for (std::size_t v = 0; v < n; ++v)
    same[v] = first.try_emplace(key_of(&mesh.positions[3 * v]), static_cast<std::uint32_t>(v)).first->second;

  TriangleMesh out;
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> renumbered(n, kUnused);
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    std::uint32_t tri[3];
    bool valid = true;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t i = mesh.indices[3 * t + k];
      if (i >= n) valid = false;
      tri[k] = valid ? same[i] : 0;
    }
    if (!valid || tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;
    if (zero_area(&mesh.positions[3 * tri[0]], &mesh.positions[3 * tri[1]], &mesh.positions[3 * tri[2]])) continue;
    for (std::uint32_t i : tri) {
      if (renumbered[i] == kUnused) {
        renumbered[i] = static_cast<std::uint32_t>(out.vertex_count());
        const double* p = &mesh.positions[3 * i];
        for (int c = 0; c < 3; ++c) out.positions.push_back(p[c] == 0.0 ? 0.0 : p[c]);
      }
      out.indices.push_back(renumbered[i]);
    }
  }
  return out;
}

}  // namespace skyfarm::assets
