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
//
// The machinery (memory, disk, fetch, the hash check) is worker/decoded_asset_cache.h.
#pragma once
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "common/assets/volume_file.h"
#include "common/assets/volume_source.h"
#include "worker/asset_cache.h"
#include "worker/decoded_asset_cache.h"
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
  DecodedAssetCache<assets::VolumeGrid> cache_;
};

}  // namespace skyfarm
