// The worker's VolumeSource (common/assets/volume_source.h): the cloud
// volumes a job's clouds name by asset id, from memory, else the disk cache
// (worker/asset_cache.h), else `fetch` (the farm worker asks the server the
// same way as for meshes, worker/asset_requests.h).  The mesh cache's twin
// (worker/mesh_cache.h): bytes from the disk or the server are used only if
// they hash to the id and decode as a SKYVOL1 file within the VolumeLimits;
// fetched bytes are then written to the disk cache.
//
// Parameters
//   disk          the disk cache, or null (none)
//   fetch         the file's bytes by id, as MeshCache's (AssetUnavailable
//                 when asking again later may work); empty: an asset found
//                 neither in memory nor on disk is an error
//   memory_bytes  the bound on the decoded volumes kept in memory (least
//                 recently used go first)
//
// Threads: volume() may be called from every render thread; an asset wanted
// by several at once is loaded (and fetched) once, the others wait for it.
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <future>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "common/assets/volume_file.h"
#include "common/assets/volume_source.h"
#include "worker/asset_cache.h"
#include "worker/mesh_cache.h"

namespace skyfarm {

class VolumeCache : public assets::VolumeSource {
 public:
  using Fetch = std::function<std::string(const std::string& id)>;

  VolumeCache(AssetDiskCache* disk, Fetch fetch, std::size_t memory_bytes = std::size_t{2} << 30,
              assets::VolumeLimits limits = {});

  std::shared_ptr<const assets::VolumeGrid> volume(std::string_view id) const override;

  MeshCacheStats stats() const;

 private:
  using Volume = std::shared_ptr<const assets::VolumeGrid>;
  Volume load(const std::string& id) const;
  Volume decode(const std::string& id, const std::string& bytes, std::string* why) const;
  void remember(const std::string& id, const Volume& volume) const;

  AssetDiskCache* disk_;
  Fetch fetch_;
  std::size_t memory_bytes_;
  assets::VolumeLimits limits_;
  mutable std::mutex mutex_;
  mutable std::list<std::pair<std::string, Volume>> lru_;  // most recent first
  mutable std::size_t held_bytes_ = 0;
  mutable std::map<std::string, std::shared_future<Volume>> loading_;
  mutable std::atomic<std::uint64_t> memory_hits_{0}, disk_hits_{0}, fetches_{0}, rejected_{0};
};

}  // namespace skyfarm
