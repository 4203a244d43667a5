#include "worker/volume_cache.h"

#include <algorithm>
#include <utility>

#include "common/assets/asset_id.h"

namespace skyfarm {

namespace {

std::size_t volume_bytes(const assets::VolumeGrid& grid) { return grid.values.size() * sizeof(float); }

}  // namespace

VolumeCache::VolumeCache(AssetDiskCache* disk, Fetch fetch, std::size_t memory_bytes, assets::VolumeLimits limits)
    : disk_(disk), fetch_(std::move(fetch)), memory_bytes_(memory_bytes), limits_(limits) {}

std::shared_ptr<const assets::VolumeGrid> VolumeCache::volume(std::string_view id_view) const {
  const std::string id(id_view);
  if (!assets::is_asset_id(id)) throw std::runtime_error("asset " + id + ": not an asset id (sha256:<64 hex>)");
  std::promise<Volume> promise;
  std::shared_future<Volume> pending;
  {
    std::lock_guard lock(mutex_);
    const auto it = std::find_if(lru_.begin(), lru_.end(), [&](const auto& e) { return e.first == id; });
    if (it != lru_.end()) {
      lru_.splice(lru_.begin(), lru_, it);
      ++memory_hits_;
      return lru_.front().second;
    }
    if (const auto l = loading_.find(id); l != loading_.end()) {
      pending = l->second;
    } else {
      loading_.emplace(id, promise.get_future().share());
    }
  }
  if (pending.valid()) return pending.get();  // another thread loads it; its error is ours
  try {
    Volume volume = load(id);
    remember(id, volume);
    promise.set_value(volume);
    std::lock_guard lock(mutex_);
    loading_.erase(id);
    return volume;
  } catch (...) {
    promise.set_exception(std::current_exception());
    std::lock_guard lock(mutex_);
    loading_.erase(id);
    throw;
  }
}

VolumeCache::Volume VolumeCache::load(const std::string& id) const {
  std::string why;
  if (disk_) {
    if (const std::optional<std::string> bytes = disk_->read(id)) {
      if (Volume volume = decode(id, *bytes, &why)) {
        ++disk_hits_;
        return volume;
      }
      disk_->remove(id);  // damaged or foreign: fetch it again
    }
  }
  if (!fetch_)
    throw std::runtime_error("asset " + id + " is not in the asset cache" +
                             (disk_ ? " (" + disk_->dir() + ")" : std::string()) +
                             ": upload it or give a file path");
  ++fetches_;
  const std::string bytes = fetch_(id);
  Volume volume = decode(id, bytes, &why);
  if (!volume) throw std::runtime_error("asset " + id + " from the server: " + why);
  if (disk_) {
    try {
      disk_->write(id, bytes);
    } catch (const std::exception&) {
      // A full or read-only cache costs a fetch next time, not this render.
    }
  }
  return volume;
}

VolumeCache::Volume VolumeCache::decode(const std::string& id, const std::string& bytes, std::string* why) const {
  if (assets::asset_id_of(bytes) != id) {
    ++rejected_;
    *why = "its bytes do not hash to the id";
    return nullptr;
  }
  auto volume = std::make_shared<assets::VolumeGrid>();
  if (!assets::decode_volume_file(bytes, limits_, volume.get(), why)) {
    ++rejected_;
    return nullptr;
  }
  return volume;
}

void VolumeCache::remember(const std::string& id, const Volume& volume) const {
  std::lock_guard lock(mutex_);
  lru_.emplace_front(id, volume);
  held_bytes_ += volume_bytes(*volume);
  while (held_bytes_ > memory_bytes_ && lru_.size() > 1) {
    held_bytes_ -= volume_bytes(*lru_.back().second);
    lru_.pop_back();
  }
}

MeshCacheStats VolumeCache::stats() const {
  return MeshCacheStats{memory_hits_.load(), disk_hits_.load(), fetches_.load(), rejected_.load()};
}

}  // namespace skyfarm
