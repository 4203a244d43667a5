#include "worker/mesh_cache.h"

#include <algorithm>
#include <utility>

#include "common/assets/asset_id.h"

namespace skyfarm {

std::size_t mesh_bytes(const assets::TriangleMesh& mesh) {
  return mesh.positions.size() * sizeof(double) + mesh.indices.size() * sizeof(std::uint32_t);
}

MeshCache::MeshCache(AssetDiskCache* disk, Fetch fetch, std::size_t memory_bytes, assets::MeshLimits limits)
    : disk_(disk), fetch_(std::move(fetch)), memory_bytes_(memory_bytes), limits_(limits) {}

std::shared_ptr<const assets::TriangleMesh> MeshCache::mesh(std::string_view id_view) const {
  const std::string id(id_view);
  if (!assets::is_asset_id(id)) throw std::runtime_error("asset " + id + ": not an asset id (sha256:<64 hex>)");
  std::promise<Mesh> promise;
  std::shared_future<Mesh> pending;
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
    Mesh mesh = load(id);
    remember(id, mesh);
    promise.set_value(mesh);
    std::lock_guard lock(mutex_);
    loading_.erase(id);
    return mesh;
  } catch (...) {
    promise.set_exception(std::current_exception());
    std::lock_guard lock(mutex_);
    loading_.erase(id);
    throw;
  }
}

MeshCache::Mesh MeshCache::load(const std::string& id) const {
  std::string why;
  if (disk_) {
    if (const std::optional<std::string> bytes = disk_->read(id)) {
      if (Mesh mesh = decode(id, *bytes, &why)) {
        ++disk_hits_;
        return mesh;
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
  Mesh mesh = decode(id, bytes, &why);
  if (!mesh) throw std::runtime_error("asset " + id + " from the server: " + why);
  if (disk_) {
    try {
      disk_->write(id, bytes);
    } catch (const std::exception&) {
      // A full or read-only cache costs a fetch next time, not this render.
    }
  }
  return mesh;
}

MeshCache::Mesh MeshCache::decode(const std::string& id, const std::string& bytes, std::string* why) const {
  if (assets::asset_id_of(bytes) != id) {
    ++rejected_;
    *why = "its bytes do not hash to the id";
    return nullptr;
  }
  auto mesh = std::make_shared<assets::TriangleMesh>();
  if (!assets::decode_mesh_file(bytes, limits_, mesh.get(), why)) {
    ++rejected_;
    return nullptr;
  }
  return mesh;
}

void MeshCache::remember(const std::string& id, const Mesh& mesh) const {
  std::lock_guard lock(mutex_);
  lru_.emplace_front(id, mesh);
  held_bytes_ += mesh_bytes(*mesh);
  while (held_bytes_ > memory_bytes_ && lru_.size() > 1) {
    held_bytes_ -= mesh_bytes(*lru_.back().second);
    lru_.pop_back();
  }
}

MeshCacheStats MeshCache::stats() const {
  return MeshCacheStats{memory_hits_.load(), disk_hits_.load(), fetches_.load(), rejected_.load()};
}

}  // namespace skyfarm
