#include "worker/mesh_cache.h"

#include <cstdint>
#include <utility>

namespace skyfarm {

std::size_t mesh_bytes(const assets::TriangleMesh& mesh) {
  return mesh.positions.size() * sizeof(double) + mesh.indices.size() * sizeof(std::uint32_t);
}

MeshCache::MeshCache(AssetDiskCache* disk, Fetch fetch, std::size_t memory_bytes, assets::MeshLimits limits)
    : cache_(
          disk, std::move(fetch), memory_bytes,
          [limits](const std::string& bytes, assets::TriangleMesh* mesh, std::string* why) {
            return assets::decode_mesh_file(bytes, limits, mesh, why);
          },
          mesh_bytes) {}

std::shared_ptr<const assets::TriangleMesh> MeshCache::mesh(std::string_view id) const { return cache_.get(id); }

MeshCacheStats MeshCache::stats() const { return cache_.stats(); }

}  // namespace skyfarm
