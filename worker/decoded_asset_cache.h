// The machinery the worker's asset caches share (worker/mesh_cache.h,
// worker/volume_cache.h): a decoded asset by id from memory, else the disk
// cache (worker/asset_cache.h), else `fetch`.  Bytes from the disk or the
// server are used only if they hash to the id and `decode` accepts them;
// fetched bytes are then written to the disk cache.  One template, so that
// the mesh and the volume caches cannot drift apart in how they check,
// evict or share a load.
//
// Parameters
//   T             the decoded asset (assets::TriangleMesh, assets::VolumeGrid)
//   disk          the disk cache, or null (none)
//   fetch         the file's bytes by id; throws std::runtime_error (with a
//                 sentence) when it cannot have them.  Empty: an asset found
//                 neither in memory nor on disk is an error that says to
//                 upload it or give a file path
//   memory_bytes  the bound on the decoded assets kept in memory (least
//                 recently used go first; one a caller still holds lives on
//                 in it); the newest is kept even when it alone exceeds it
//   decode        fills a T from a file's bytes, or returns false with *why
//   bytes_of      the memory a decoded T holds, counted against memory_bytes
//
// Threads: get() may be called from every render thread; an asset wanted by
// several at once is loaded (and fetched) once, the others wait for it.
// Errors are not remembered: the next call tries again.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <future>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "common/assets/asset_id.h"
#include "worker/asset_cache.h"

namespace skyfarm {

struct AssetCacheStats {
  std::uint64_t memory_hits = 0;
  std::uint64_t disk_hits = 0;
  std::uint64_t fetches = 0;   // calls of fetch
  std::uint64_t rejected = 0;  // files that did not hash to their id or did not decode
};

template <typename T>
class DecodedAssetCache {
 public:
  using Asset = std::shared_ptr<const T>;
  using Fetch = std::function<std::string(const std::string& id)>;
  using Decode = std::function<bool(const std::string& bytes, T* asset, std::string* why)>;
  using BytesOf = std::function<std::size_t(const T& asset)>;

  DecodedAssetCache(AssetDiskCache* disk, Fetch fetch, std::size_t memory_bytes, Decode decode, BytesOf bytes_of)
      : disk_(disk),
        fetch_(std::move(fetch)),
        memory_bytes_(memory_bytes),
        decode_(std::move(decode)),
        bytes_of_(std::move(bytes_of)) {}

  Asset get(std::string_view id_view) const {
    const std::string id(id_view);
    if (!assets::is_asset_id(id)) throw std::runtime_error("asset " + id + ": not an asset id (sha256:<64 hex>)");
    std::promise<Asset> promise;
    std::shared_future<Asset> pending;
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
      Asset asset = load(id);
      remember(id, asset);
      promise.set_value(asset);
      std::lock_guard lock(mutex_);
      loading_.erase(id);
      return asset;
    } catch (...) {
      promise.set_exception(std::current_exception());
      std::lock_guard lock(mutex_);
      loading_.erase(id);
      throw;
    }
  }

  AssetCacheStats stats() const {
    return AssetCacheStats{memory_hits_.load(), disk_hits_.load(), fetches_.load(), rejected_.load()};
  }

 private:
  Asset load(const std::string& id) const {
    std::string why;
    if (disk_) {
      if (const std::optional<std::string> bytes = disk_->read(id)) {
        if (Asset asset = decode(id, *bytes, &why)) {
          ++disk_hits_;
          return asset;
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
    Asset asset = decode(id, bytes, &why);
    if (!asset) throw std::runtime_error("asset " + id + " from the server: " + why);
    if (disk_) {
      try {
        disk_->write(id, bytes);
      } catch (const std::exception&) {
        // A full or read-only cache costs a fetch next time, not this render.
      }
    }
    return asset;
  }

  // The asset in `bytes`, or null with *why set.
  Asset decode(const std::string& id, const std::string& bytes, std::string* why) const {
    if (assets::asset_id_of(bytes) != id) {
      ++rejected_;
      *why = "its bytes do not hash to the id";
      return nullptr;
    }
    auto asset = std::make_shared<T>();
    if (!decode_(bytes, asset.get(), why)) {
      ++rejected_;
      return nullptr;
    }
    return asset;
  }

  void remember(const std::string& id, const Asset& asset) const {
    std::lock_guard lock(mutex_);
    lru_.emplace_front(id, asset);
    held_bytes_ += bytes_of_(*asset);
    while (held_bytes_ > memory_bytes_ && lru_.size() > 1) {
      held_bytes_ -= bytes_of_(*lru_.back().second);
      lru_.pop_back();
    }
  }

  AssetDiskCache* disk_;
  Fetch fetch_;
  std::size_t memory_bytes_;
  Decode decode_;
  BytesOf bytes_of_;
  mutable std::mutex mutex_;
  mutable std::list<std::pair<std::string, Asset>> lru_;  // most recent first
  mutable std::size_t held_bytes_ = 0;
  mutable std::map<std::string, std::shared_future<Asset>> loading_;
  mutable std::atomic<std::uint64_t> memory_hits_{0}, disk_hits_{0}, fetches_{0}, rejected_{0};
};

}  // namespace skyfarm
