#include "worker/volume_cache.h"

#include <utility>

namespace skyfarm {

namespace {

std::size_t volume_bytes(const assets::VolumeGrid& grid) { return grid.values.size() * sizeof(float); }

}  // namespace

VolumeCache::VolumeCache(AssetDiskCache* disk, Fetch fetch, std::size_t memory_bytes, assets::VolumeLimits limits)
    : cache_(
          disk, std::move(fetch), memory_bytes,
          [limits](const std::string& bytes, assets::VolumeGrid* volume, std::string* why) {
            return assets::decode_volume_file(bytes, limits, volume, why);
          },
          volume_bytes) {}

std::shared_ptr<const assets::VolumeGrid> VolumeCache::volume(std::string_view id) const { return cache_.get(id); }

MeshCacheStats VolumeCache::stats() const { return cache_.stats(); }

}  // namespace skyfarm
